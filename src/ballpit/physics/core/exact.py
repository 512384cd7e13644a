"""Arithmetic whose bits do not depend on the CPU, for everything a step computes: the one module of
vectors and sums.

Vectors come in two layouts, named apart: rows, (..., 3) arrays with one vector a row (ball states,
contact points; ``dot_rows``, ``norm_rows``, ``cross_rows`` work over the last axis), and columns,
(3, K) arrays with one vector a column (the solves' contacts, contact_model.py; ``dot_cols``,
``norm_cols``, ``cross_cols``). Either way a dot product sums x, y, z from first to last. A sum of many
numbers is ``total`` (first to last, one addition at a time), or ``correctly_rounded_total`` where the
sign of a tiny sum decides something.

A scene gives the same bits on any x86-64 machine only if every operation in the step does. These do:
elementwise +, −, ×, ÷ and sqrt are correctly rounded (IEEE 754) on every CPU and SIMD width, and a
sum taken in an order fixed by the code is too. These do not, so the step avoids them:

- matrix products (``@``, ``np.dot``, ``np.matmul``, ``np.linalg.norm`` of a 1-D vector, which is a
  dot product): OpenBLAS picks its kernel by CPU (``OPENBLAS_CORETYPE``), and the kernels sum in
  different orders, some with fused multiply-adds;
- NumPy's transcendental functions (``np.sin``, ``np.cos``, ``np.exp``, ...): some have SIMD variants
  chosen by CPU (``NPY_DISABLE_CPU_FEATURES``), and the rest call the C library, whose ``sin`` and
  ``cos`` also pick an FMA variant by CPU (glibc's ``GLIBC_TUNABLES=glibc.cpu.hwcaps``). Python's
  ``math.sin`` is that same C function, so it is no way out either.

NumPy's ``einsum`` without ``optimize`` and ``np.add.reduce`` over a short axis are compiled once for
the baseline CPU (they have no CPU-dispatched variants), so the per-row dot products written with
them elsewhere give the same bits everywhere too; ``tests/test_determinism.py`` checks the bundled
scenes under each switch.
"""

from __future__ import annotations

import math

import numpy as np

# π/2 in three pieces for Cody–Waite reduction (fdlibm's e_rem_pio2.c): the first two have 33
# significant bits, so n·piece is exact for |n| < 2**20; _PIO2_2T is what the first two lack.
_INV_PIO2 = 6.36619772367581382433e-01
_PIO2_1 = 1.57079632673412561417e00
_PIO2_2 = 6.07710050630396597660e-11
_PIO2_2T = 2.02226624879595063154e-21
# Minimax polynomials for sin and cos on [−π/4, π/4] (FreeBSD msun k_sin.c and k_cos.c, < 1 ulp).
_S1, _S2, _S3 = -1.66666666666666324348e-01, 8.33333333332248946124e-03, -1.98412698298579493134e-04
_S4, _S5, _S6 = 2.75573137070700676789e-06, -2.50507602534068634195e-08, 1.58969099521155010221e-10
_C1, _C2, _C3 = 4.16666666666666019037e-02, -1.38888888888741095749e-03, 2.48015872894767294178e-05
_C4, _C5, _C6 = -2.75573143513906633035e-07, 2.08757232129817482790e-09, -1.13596475577881948265e-11
# Beyond this the reduction's n·piece products are no longer exact: larger angles are first taken
# modulo the double nearest 2π (np.fmod is exact), which is off by under 1e-9 rad there, less than
# the spacing of the angles themselves (2e-10 rad at 2¹⁹·π).
_MAX_ANGLE = 2.0**19 * np.pi


def dot_rows(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a · b of vectors laid out as rows (over the last axis), summed from first to last:
    (a₀b₀ + a₁b₁) + a₂b₂ for 3-vectors."""
    if not (type(a) is np.ndarray and a.dtype == np.float64):
        a = np.asarray(a, float)
    if not (type(b) is np.ndarray and b.dtype == np.float64):
        b = np.asarray(b, float)
    if a.shape[-1] == 3 == b.shape[-1]:  # the common case, the same sums written out
        return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]
    out = a[..., 0] * b[..., 0]
    for k in range(1, max(a.shape[-1], b.shape[-1])):
        out = out + a[..., k] * b[..., k]
    return out


def norm_rows(a: np.ndarray) -> np.ndarray:
    """|a| of rows (over the last axis), its squares summed from first to last (as ``np.linalg.norm(a,
    axis=-1)`` sums them for rows of a matrix, but without its dot product for a single vector)."""
    return np.sqrt(dot_rows(a, a))


def total(x: np.ndarray) -> float:
    """Σx from first to last, one addition at a time (an accumulation is sequential by definition,
    unlike a matrix product's kernel): the step's sum of many numbers."""
    x = np.ravel(x)
    return float(np.cumsum(x)[-1]) if x.size else 0.0


def correctly_rounded_total(x: np.ndarray) -> float:
    """Σx correctly rounded (``math.fsum``): independent of the order, for the impulses' energy check,
    whose sign decides whether impulses are scaled (energy_guard.keep_impulses)."""
    return math.fsum(x)


def sin_cos(angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """sin and cos of ``angle`` (radians) from +, −, × only, within 1 ulp for |angle| < 2¹⁹·π.

    The angle is reduced to r + r_lo in [−π/4, π/4] by n quarter turns (Cody–Waite, π/2 in three
    pieces), then fdlibm's polynomials give sin r and cos r, and n mod 4 picks the signs and order.
    """
    x = np.asarray(angle, float)
    x = np.where(np.abs(x) > _MAX_ANGLE, np.fmod(x, 2.0 * np.pi), x)
    n = np.rint(x * _INV_PIO2)
    # fdlibm's two-step medium reduction: r = x − n·π/2 with the rounding of each step carried in r_lo
    t = x - n * _PIO2_1
    w = n * _PIO2_2
    r = t - w
    w = n * _PIO2_2T - ((t - r) - w)
    hi = r - w
    lo = (r - hi) - w
    z = hi * hi
    zz = z * z
    # k_sin: r + r³·S(r²), with the reduction's tail lo added to first order
    v = z * hi
    s_poly = _S2 + z * (_S3 + z * _S4) + z * zz * (_S5 + z * _S6)
    s = hi - ((z * (0.5 * lo - v * s_poly) - lo) - v * _S1)
    # k_cos: 1 − r²/2 + r⁴·C(r²), the 1 − r²/2 split so its rounding error is kept
    c_poly = z * (_C1 + z * (_C2 + z * _C3)) + zz * zz * (_C4 + z * (_C5 + z * _C6))
    half = 0.5 * z
    one = 1.0 - half
    c = one + (((1.0 - one) - half) + (z * c_poly - hi * lo))
    quarter = np.mod(n, 4.0)
    sin = np.where(quarter == 0.0, s, np.where(quarter == 1.0, c, np.where(quarter == 2.0, -s, -c)))
    sin = np.where(x == 0.0, x, sin)  # sin(−0) = −0, which the reduction's subtractions lose
    cos = np.where(quarter == 0.0, c, np.where(quarter == 1.0, -s, np.where(quarter == 2.0, -c, s)))
    return sin, cos


def cross_rows(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """p × q of rows (over the last axis of (..., 3) arrays), as ``np.cross`` forms each component
    (p₁q₂ − p₂q₁, p₂q₀ − p₀q₂, p₀q₁ − p₁q₀), so the bits are the same, without its axis shuffling,
    which costs several times the arithmetic on a few rows."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    out = np.empty(p.shape if p.shape == q.shape else np.broadcast_shapes(p.shape, q.shape))
    p0, p1, p2 = p[..., 0], p[..., 1], p[..., 2]
    q0, q1, q2 = q[..., 0], q[..., 1], q[..., 2]
    np.subtract(p1 * q2, p2 * q1, out=out[..., 0])
    np.subtract(p2 * q0, p0 * q2, out=out[..., 1])
    np.subtract(p0 * q1, p1 * q0, out=out[..., 2])
    return out


def norm_floats(x: float, y: float, z: float) -> float:
    """|(x, y, z)| of one vector in Python floats, its squares summed first to last (a plane's speed or
    spin: a few a step, where NumPy's calls would cost more than the arithmetic)."""
    return math.sqrt((x * x + y * y) + z * z)


def dot_cols(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a · b of vectors laid out as columns ((3, K) arrays, over the first axis), summed x, y, z in that
    order: the same sums as ``dot_rows`` of the rows."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def dot_cols_in_place(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``dot_cols`` formed in ``a``'s own rows (its values are used up): the same products, summed x,
    y, z in the same order; returns ``a[0]``, which holds the sums."""
    a *= b
    a[0] += a[1]
    a[0] += a[2]
    return a[0]


def norm_cols(a: np.ndarray, scratch: np.ndarray | None = None, out: np.ndarray | None = None) -> np.ndarray:
    """|a| of columns ((3, K)), its squares summed x, y, z in that order (``dot_cols``); into ``out``
    through ``scratch`` ((3, K)) when given, so a caller looping over chunks makes no temporaries."""
    if scratch is None:
        return np.sqrt(dot_cols(a, a))
    np.multiply(a, a, out=scratch)
    np.add(scratch[0], scratch[1], out=out)
    out += scratch[2]
    return np.sqrt(out, out=out)


def cross_cols(a: np.ndarray, b: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """a × b of columns ((3, K) arrays), each component as ``np.cross`` forms it, into ``out`` if given
    (it must not overlap ``a`` or ``b``)."""
    if out is None:  # (np.broadcast_shapes costs more than a few columns' arithmetic)
        out = np.empty(a.shape if a.shape == b.shape else np.broadcast_shapes(a.shape, b.shape))
    if a.ndim == b.ndim == 2 and out.shape[1] <= CROSS_GATHER_UP_TO:
        # a few columns: the rows a_j, b_k, a_k, b_j gathered for all three components at once, then
        # a_j·b_k − a_k·b_j in one pass (the same products and difference as component by component)
        return np.subtract(
            a.take(_CYCLE_J, axis=0) * b.take(_CYCLE_K, axis=0),
            a.take(_CYCLE_K, axis=0) * b.take(_CYCLE_J, axis=0),
            out=out,
        )
    for i in range(3):
        cross_col(a, b, i, out=out[i])
    return out


# (j, k) of each component i in cyclic order, and up to how many columns ``cross_cols`` gathers them
# (beyond, the copies cost more than the calls they save)
_CYCLE_J, _CYCLE_K = np.array([1, 2, 0]), np.array([2, 0, 1])
CROSS_GATHER_UP_TO = 64


def cross_col(a: np.ndarray, b: np.ndarray, i: int, out: np.ndarray | None = None) -> np.ndarray:
    """Component ``i`` of the column-wise a × b: a_j·b_k − a_k·b_j with (i, j, k) in cyclic order."""
    j, k = (i + 1) % 3, (i + 2) % 3
    return np.subtract(a[j] * b[k], a[k] * b[j], out=out)
