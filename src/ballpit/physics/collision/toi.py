"""Time of impact by conservative advancement, vectorised over the kept pairs.

For each pair, φ(t) is the gap (distance minus radii) along the path the integrator will take. The
gap cannot shrink faster than the bound L on the pair's relative speed over the interval, so stepping
t ← t + φ(t)/L never jumps past the first contact (Mirtich's conservative advancement). For a
head-on approach at constant velocity one step lands exactly on the contact; gravity adds a few more.
This is what stops fast balls tunnelling: a ball at 500 m/s that would cross a plane inside one step
is stopped where it first touches.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..core import exact
from ..core.contacts import SPHERE_PLANE, ContactPoints
from ..core.settings import IMPACT_OVERLAP, LEAP_AFTER, MAX_ADVANCE_STEPS
from ..core.state import State, V, X, with_static
from ..dynamics import moving_planes
from ..dynamics.model import Model
from . import geometry


def first_contact(
    gap_at: Callable[[np.ndarray, np.ndarray], np.ndarray],
    speed_bound: np.ndarray,
    t_max: float,
    tolerance: float | np.ndarray,
    max_iterations: int = MAX_ADVANCE_STEPS,
    start: np.ndarray | None = None,
    overlap: float | None = None,
) -> np.ndarray:
    """Earliest time in [0, t_max] at which each pair's gap falls to ``tolerance`` (one for all, or
    one per pair; inf if none).

    ``gap_at(k, t)`` gives the gaps of pairs ``k`` at times ``t``. ``start``, when given, is a time
    before which each pair cannot get there (inf: not within t_max at all): such pairs are left out,
    and a pair still advancing after LEAP_AFTER steps leaps ahead to its start. A pair still converging
    after ``max_iterations`` reports the time it reached, a safe lower bound: the caller advances to it
    and asks again. With ``overlap`` (``merged``'s bound) a pair stops advancing, inf, once its
    meeting can no longer change ``merged``'s answer (``past_merging``).
    """
    count = len(speed_bound)
    t = np.zeros(count)
    when = np.full(count, np.inf)
    active = np.arange(count) if start is None else (start <= t_max).nonzero()[0]
    if active.size == 0:
        return when
    gap = gap_at(active, t[active])
    per_pair = np.ndim(tolerance) > 0
    for iteration in range(max_iterations):
        touching = gap <= (tolerance[active] if per_pair else tolerance)
        when[active[touching]] = t[active[touching]]
        moving = ~touching & (speed_bound[active] > 0.0)
        active, gap = active[moving], gap[moving]
        t_next = t[active] + gap / speed_bound[active]
        if start is not None and iteration + 1 == LEAP_AFTER:
            t_next = np.maximum(t_next, start[active])
        within = t_next <= t_max
        if overlap is not None:  # (t only grows: a pair meets at t_next or later)
            within &= ~past_merging(when, speed_bound, t_next, overlap)
        active, t_next = active[within], t_next[within]
        if active.size == 0:
            return when
        t[active] = t_next
        gap = gap_at(active, t_next)
    when[active] = t[active]
    return when


def next_impact(model: Model, state: State, c: ContactPoints, accel: np.ndarray, h: float) -> float:
    """Time until the first pair not yet touching comes into contact (inf if none within ``h``).

    Each ball follows the integrator's path under ``accel`` (its free acceleration plus the resting
    forces), and each plane its own motion (moving_planes.py). Impacts close in time are taken
    together: the result is the latest impact that leaves every earlier pair overlapping by less than
    IMPACT_OVERLAP of the smallest radius (removed next interval by moving positions). A lone impact is
    always met exactly.
    """
    # (inf with no balls: then no pair meets)
    allowed = IMPACT_OVERLAP * float(model.spheres.radius.min(initial=np.inf))
    slop = model.contact_slop()
    when, bound, _ = meetings(model, state, c, accel, h, lambda ra, rb: 0.5 * slop, allowed)
    return merged(when, bound, allowed)


def merged(when: np.ndarray, bound: np.ndarray, allowed: float) -> float:
    """The latest of the meeting times ``when`` (inf: none) that leaves every pair met before it
    overlapping by at most ``allowed`` (m), each closing at its speed ``bound`` since it met, counted
    from the first meeting; inf if none."""
    hit = np.isfinite(when)
    if not np.count_nonzero(hit):
        return np.inf
    order = np.argsort(when[hit], kind="stable")
    t, speed = when[hit][order], bound[hit][order]
    overlap = (t - t[0]) * np.maximum.accumulate(speed)
    return float(t[np.searchsorted(overlap, allowed, side="right") - 1])


def past_merging(when: np.ndarray, bound: np.ndarray, t: np.ndarray, allowed: float) -> np.ndarray:
    """Which pairs that cannot meet before ``t`` are met too late to change ``merged(when, bound,
    allowed)``, whenever they meet (a mask over ``t``; ``when``: the pairs met so far, inf the others).

    With t₁ the earliest meeting so far and s₁ the least speed of the pairs met then, a pair meeting at
    t′ ≥ t > t₁ is sorted after them and overlaps by (t′ − t₀)·(a running maximum ≥ s₁) ≥ (t − t₁)·s₁
    in ``merged`` (t₀ ≤ t₁ the first meeting of all). Beyond ``allowed`` neither it nor any meeting
    sorted after it is taken, and the meetings before it never see its speed: the answer is the same
    without it (rounded products grow with their factors, so this holds in floating point too)."""
    met = np.isfinite(when)
    if not np.count_nonzero(met):
        return np.zeros(t.shape, bool)
    first = float(np.minimum.reduce(when[met]))
    speed = float(np.minimum.reduce(bound[met & (when == first)]))
    return (t - first) * speed > allowed


def meetings(
    model: Model,
    state: State,
    c: ContactPoints,
    accel: np.ndarray,
    h: float,
    target,
    overlap: float | None = None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """When each pair of ``c`` not yet touching first has its gap down to ``target(r_a, r_b)`` within
    ``h`` (inf if never), with the closing-speed bound used, for the pairs that could get there at
    all (their indices into ``c``); with ``overlap``, inf too for the pairs met too late to change
    ``merged`` (``first_contact``)."""
    apart = (c.gap >= model.contact_slop()).nonzero()[0]
    none = np.zeros(0)
    if apart.size == 0:
        return none, none, apart
    body, path = state.body, model.integrator
    x, v, accel = with_static(body[:, X]), with_static(body[:, V]), with_static(accel)
    acc = path.path_acceleration(accel)
    a, b = c.a[apart], c.b[apart]
    bound = path.closing_speed_bound(v[a] - v[b], accel[a] - accel[b], h)
    if model.moving_planes():  # a plane's surface moves too: bound its approach as well
        on = c.kind[apart] == SPHERE_PLANE
        bound[on] = moving_planes.closing_speed_bound(
            model, state, a[on], c.other[apart[on]], v[a[on]], acc[a[on]], h
        )
    radius = np.append(model.spheres.radius, 0.0)
    goal = np.broadcast_to(target(radius[a], radius[b]), a.shape)
    # (a gap that need only fall to a small positive target counts as reachable when it could close
    # altogether, as it always has)
    reachable = c.gap[apart] - np.minimum(goal, 0.0) <= bound * h
    apart, a, b, bound, goal = apart[reachable], a[reachable], b[reachable], bound[reachable], goal[reachable]
    if apart.size == 0:
        return none, none, apart
    on_plane = c.kind[apart] == SPHERE_PLANE
    reach = radius[a] + radius[b]
    pose, half = state.planes, model.planes.half_size
    moving = model.moving_planes()

    def gap_at(k: np.ndarray, t: np.ndarray) -> np.ndarray:
        tt = t[:, None]
        pa = path.position_at(x[a[k]], v[a[k]], accel[a[k]], tt)
        pb = path.position_at(x[b[k]], v[b[k]], accel[b[k]], tt)
        plane_k = on_plane[k]
        if np.count_nonzero(plane_k):
            pk = c.other[apart[k[plane_k]]]
            if moving:  # each plane where it will be after t
                centre, u, w = moving_planes.frames_at(model, state, pk, t[plane_k])
                rows = np.arange(len(pk))
                pb[plane_k] = geometry.closest_point_on_planes(pa[plane_k], rows, centre, u, w, half[pk])
            else:
                pb[plane_k] = geometry.closest_point_on_planes(
                    pa[plane_k], pk, pose.center, pose.axis_u, pose.axis_v, half
                )
        return exact.norm_rows(pa - pb) - reach[k]

    start = earliest(model, state, c, apart, x, v, acc, h, goal)
    return first_contact(gap_at, bound, h, goal, start=start, overlap=overlap), bound, apart


def earliest(
    model: Model,
    state: State,
    c: ContactPoints,
    apart: np.ndarray,
    x: np.ndarray,
    v: np.ndarray,
    acc: np.ndarray,
    h: float,
    goal: np.ndarray,
) -> np.ndarray:
    """A time before which no pair ``apart`` of ``c`` can have its gap down to ``goal`` (inf: not
    within ``h``), so conservative advancement need not crawl up to it.

    The gap is never less than the gap along the contact normal e of now: the distance from a ball's
    centre to a convex body is at least e·(x − p₀), p₀ its closest point now (e·(y − p₀) ≤ 0 for every
    point y of the body). Along e the gap is a parabola in t, gap₀ + (e·Δv)·t + ½·(e·Δa)·t², on the
    integrator's path and a still plane or another ball. On a plane moving at v_p and turning at ω
    about its centre c, e and p₀ turn with it: the slope is e·w with w = v − v_p − ω × (x − c), the
    ball's velocity relative to the plane's frame, and the curvature is at least
    e·a − |ω|·(|a|·h + |w|_max + |v − v_p|_max). The first root of that parabola at ``goal`` (found as
    2·D / (−b + √(b² − 2·c·D)), D = gap₀ − goal, which never cancels) is the time returned.

    Conservative advancement alone steps by gap / (bound on the closing speed), and the bound counts
    the speed along the surface: a ball hopping a tenth of a millimetre as it rolls at 3 m/s took 48
    steps and more to land.
    """
    a, b = c.a[apart], c.b[apart]
    e = c.normal[apart]
    dv, da = v[a] - v[b], acc[a] - acc[b]
    slope, curve = exact.dot_rows(e, dv), exact.dot_rows(e, da)
    if model.moving_planes():
        on = (c.kind[apart] == SPHERE_PLANE).nonzero()[0]
        pl, k = model.planes, c.other[apart[on]]
        spin, rel = model.plane_spin()[k], dv[on] - pl.velocity[k]  # v − v_p
        w = rel - exact.cross_rows(spin, x[a[on]] - state.planes.center[k])
        norm = exact.norm_rows
        rate, accel = norm(spin), norm(da[on])
        speed = norm(rel) + accel * h  # |v − v_p| over the interval
        turn = norm(w) + h * (accel + rate * speed)  # |w| over the interval
        slope[on] = exact.dot_rows(e[on], w)
        curve[on] -= rate * (accel * h + turn + speed)
    depth = c.gap[apart] - goal
    root = slope * slope - 2.0 * curve * depth
    below = -slope + np.sqrt(np.maximum(root, 0.0))
    meets = (root >= 0.0) & (below > 0.0)
    return np.where(meets, 2.0 * depth / np.where(meets, below, 1.0), np.inf)


def threatened(model: Model, state: State, c: ContactPoints, accel: np.ndarray, h: float) -> np.ndarray:
    """Balls that could reach a pair not yet touching within ``h``, whether the other body keeps
    moving or stops: the bound |v_a| + |v_b| + (|a_a| + |a_b|)·h covers both (a plane's motion is
    bounded as in ``next_impact``). A (N,) mask."""
    n = model.spheres.count
    hit = np.zeros(n + 1, bool)
    apart = (c.gap >= model.contact_slop()).nonzero()[0]
    if apart.size:
        body, path = state.body, model.integrator
        speed = np.append(exact.norm_rows(body[:, V]), 0.0)
        acc = np.append(exact.norm_rows(path.path_acceleration(accel)), 0.0)
        a, b = c.a[apart], c.b[apart]
        bound = speed[a] + speed[b] + (acc[a] + acc[b]) * h
        if model.moving_planes():
            on = c.kind[apart] == SPHERE_PLANE
            v, aa = with_static(body[:, V]), with_static(path.path_acceleration(accel))
            bound[on] = moving_planes.closing_speed_bound(
                model, state, a[on], c.other[apart[on]], v[a[on]], aa[a[on]], h
            )
        reach = c.gap[apart] <= bound * h
        hit[a[reach]] = True
        hit[b[reach]] = True
    return hit[:n]
