"""RK4's fast path: ``integrators.rk4`` and the renormalisation of ``integrators.integrate``, bit for
bit, when no force term depends on the state (gravity and the contact solver's constant forces, the
common case), worked on contiguous columns of a chunk of balls at a time."""

from __future__ import annotations

import numpy as np

from ..core.settings import RK4_CHUNK
from ..core.state import Q
from ..core.workspace import Workspace

# The fast path's layout of a chunk, one ball per column: x, v, then q with its y and z repeated in
# front (qy qz qx qy qz qw) and ω with its x and y repeated behind (ωx ωy ωz ωx ωy), so the rotated
# copies ``_dq`` needs for ω × q are plain row slices.
_X, _V, _Q6, _Q, _W5, _W = slice(0, 3), slice(3, 6), slice(6, 12), slice(8, 12), slice(12, 17), slice(12, 15)
_ROWS = 17
_W_ROWS = np.array([0, 1, 2, 0, 1])  # ω's components in its five-row layout


def rk4_constant(state: np.ndarray, lin: np.ndarray, ang: np.ndarray, h: float, ws: Workspace) -> None:
    """``rk4`` followed by the renormalisation of ``integrate``, bit for bit, when the accelerations
    ``lin`` and ``ang`` ((1, 3) or (N, 3), from ``forces.constant_acceleration``) do not depend on the
    state.

    Every stage then has k_v = lin and k_ω = ang, so k2 and k3 share their x part (v + ½h·lin) and only
    the orientations need four derivatives, none at all for balls that neither spin nor are spun up
    (``_keeps_orientation``). Each value is still formed by the same operations in the same order as in
    ``rk4`` (trial = k·(frac·h) + s, acc = k1 + k2 + k2 + k3 + k3 + k4, s += acc·(h/6)) and
    ``quaternion.normalize`` (whose sum of squares is taken by the same call on the same rows), so the
    results are identical. The work is done on contiguous columns of RK4_CHUNK balls at a time instead
    of on strided (N, 13) views, and nothing is computed twice.
    """
    n = len(state)
    half, sixth = 0.5 * h, h / 6.0
    if len(lin) != len(ang):  # one per ball, the other shared
        lin, ang = np.broadcast_to(lin, (n, 3)), np.broadcast_to(ang, (n, 3))
    per_ball = len(lin) > 1
    # the v and ω parts of acc·(h/6): the six k's added one by one, as ``rk4`` does (v and ω side by
    # side, the same sums for each)
    both = np.concatenate((lin, ang), axis=1)
    d = both + both
    for _ in range(4):
        d += both
    d *= sixth
    dv, dw = d[:, :3], d[:, 3:]
    lin_half, lin_h = lin * half, lin * h
    ang_half = ang_h = None  # ω's trial increments, made when some ball spins
    cols = ws.get("rk4 columns", (_ROWS, RK4_CHUNK))
    scratch = ws.get("rk4 scratch", (5, 3, RK4_CHUNK))  # acc_x, k2_x (then k4_x), three for _dq
    omegas = ws.get("rk4 omega", (2, 5, RK4_CHUNK))  # trial ω for stages 2–3 and for stage 4
    quats = ws.get("rk4 q", (2, 6, RK4_CHUNK))  # k and trial state for the orientation
    q_acc = ws.get("rk4 q acc", (4, RK4_CHUNK))
    for start in range(0, n, RK4_CHUNK):
        rows = state[start : start + RK4_CHUNK]
        m = len(rows)
        part = slice(start, start + m) if per_ball else slice(None)
        t = cols[:, :m]
        np.copyto(t[0:6], rows[:, 0:6].T)
        np.copyto(t[8:15], rows[:, 6:13].T)
        x, v, q6, q, w5, w = t[_X], t[_V], t[_Q6], t[_Q], t[_W5], t[_W]
        acc, k2, *tmp = scratch[:, :, :m]
        # x: acc = k1 + k2 + k2 + k3 + k3 + k4 with k1 = v, k2 = k3 = lin·½h + v, k4 = lin·h + v
        np.add(lin_half[part].T, v, out=k2)
        np.add(v, k2, out=acc)
        for _ in range(3):
            acc += k2
        np.add(lin_h[part].T, v, out=k2)
        acc += k2
        acc *= sixth
        x += acc
        if np.count_nonzero(ang[part]) or np.count_nonzero(w) or not _keeps_orientation(q):
            t[6:8] = t[9:11]  # the repeated rows of the layout
            t[15:17] = t[12:14]
            if ang_half is None:
                ang5 = ang.take(_W_ROWS, axis=1)  # in ω's five-row layout
                ang_half, ang_h = ang5 * half, ang5 * h
            # ω at the trial states: ang·½h + ω (stages 2 and 3) and ang·h + ω (stage 4)
            w_mid, w_end = omegas[:, :, :m]
            np.add(ang_half[part].T, w5, out=w_mid)
            np.add(ang_h[part].T, w5, out=w_end)
            # q: four derivatives, each at the trial state built from the one before
            k, trial = quats[:, :, :m]
            qacc = q_acc[:, :m]
            _dq(q6, w5, k, tmp)
            np.copyto(qacc, k[2:6])
            for frac_h, weight, omega in ((half, 2, w_mid), (half, 2, w_mid), (h, 1, w_end)):
                np.multiply(k, frac_h, out=trial)
                trial += q6
                _dq(trial, omega, k, tmp)
                for _ in range(weight):
                    qacc += k[2:6]
            qacc *= sixth
            q += qacc
        v += dv[part].T
        w += dw[part].T
        # back into the state, then q / |q| with |q|² summed by the very call ``normalize`` makes
        np.copyto(rows[:, 0:6], t[0:6].T)
        np.copyto(rows[:, 6:13], t[8:15].T)
        q_rows = rows[:, Q]
        q /= np.sqrt(np.einsum("...i,...i->...", q_rows, q_rows))
        np.copyto(q_rows, q.T)


_NEGATIVE_ZERO = np.array(-0.0).view(np.int64)


def _keeps_orientation(q: np.ndarray) -> bool:
    """Whether RK4 leaves the orientations ``q`` (4, m) exactly as they are, given that no ball spins
    or is spun up (ω = 0 and α = 0, either sign of zero).

    Then every product in dq/dt is a zero, so every k and the sum of them are zeros, each trial state
    is q + (±0) = q, and so is the end q + acc·(h/6): adding a zero changes no finite value, except
    that −0 + +0 is +0. So q is kept when it is finite and holds no −0 (the identity holds +0s).
    """
    return bool(np.isfinite(q).all()) and not np.count_nonzero(q.view(np.int64) == _NEGATIVE_ZERO)


def _dq(q6: np.ndarray, w5: np.ndarray, out: np.ndarray, tmp: list[np.ndarray]) -> None:
    """``quaternion.derivative`` in the fast path's layout: q6 = (qy qz qx qy qz qw) and w5 =
    (ωx ωy ωz ωx ωy) by columns, into ``out`` in q6's layout. Each component is formed as there:
    (qw·ω_i + ω_j·q_k) − ω_k·q_j for (i, j, k) = (x, y, z), (y, z, x), (z, x, y), and −((ωx·qx +
    ωy·qy) + ωz·qz), then halved."""
    vec, a, b = out[2:5], tmp[0], tmp[1]
    np.multiply(q6[5], w5[0:3], out=vec)  # qw·ω_i
    np.multiply(w5[1:4], q6[1:4], out=a)  # ω_j·q_k
    vec += a
    np.multiply(w5[2:5], q6[0:3], out=a)  # ω_k·q_j
    vec -= a
    np.multiply(w5[0:3], q6[2:5], out=b)  # ω_i·q_i
    s = out[5]
    np.add(b[0], b[1], out=s)
    s += b[2]
    np.negative(s, out=s)
    out[2:6] *= 0.5
    out[0:2] = out[3:5]
