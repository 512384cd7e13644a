"""Impacts: contacts arriving faster than the restitution threshold leave at e times their approach
speed (Newton's impact law, v_n' = −e·v_n).

The rule is **impacts in waves** (``in_waves``): simultaneous within a wave, sequential between waves.

- A wave is the set of contacts arriving now: closing faster than the restitution threshold. Only they
  take part. A contact that touches but does not close is no part of the wave, so it cannot share
  the impulse: that is what makes a touching Newton's cradle move on as one block in every engine
  that solves the touching contacts together (an LCP over the whole island; Smith, Kaufman, Vouga,
  Tamstorf and Grinspun, "Reflections on simultaneous impact", SIGGRAPH 2012, compare the rules).
- The wave's contacts are solved together, each to v_n' ≥ −e·v_n, with P_n ≥ 0 and P_n = 0 wherever
  v_n' ends above its target (an LCP over the wave alone). A ball struck from two sides in the same
  wave is struck by both at once.
- Then the contacts are measured again: those the wave set closing (the next ball in the chain, the
  small ball on top of a big one that has just bounced off the floor) form the next wave, from their
  new approach speeds. This repeats until nothing arrives, at most MAX_WAVES times.

What it keeps: momentum, in every wave (impulses are equal and opposite). Energy: with every contact
of a wave arriving (v_n < 0), the wave's LCP changes the kinetic energy by
½·Σ P_i·(1 − e_i)·v_n,i ≤ 0 (frictionless; zero when e = 1), so no wave adds energy. An iterative solve
that has not quite converged could still add a little, so each wave's impulses are checked and scaled
down until it adds none (``energy_guard.keep_impulses``); scaling impulses keeps momentum.

What it gives: a touching cradle struck by one ball passes the impulse down the line and only the
last ball leaves; struck by two, two leave; the Galilean cannon's top ball leaves at
(3M − m)/(M + m)·v. A ball struck from two sides at once (two contacts in one wave) gets the
simultaneous answer: equal balls at ±v on a ball at rest go back at ∓v and it stays; at 2 and −1
m/s they leave at −4/3 and 5/3 and the middle one at 2/3 (energy and momentum kept).

At the bound: what still closes after MAX_WAVES waves is stopped, e = 0, by ``stop_approaches``
(an inelastic impact never adds energy). So are the slower approaches, after the waves.
"""

from __future__ import annotations

import dataclasses

import numpy as np

from ..core.contacts import ContactPoints, EventLog
from ..core.settings import (
    APPROACH_SPEED,
    BOUNCE_HOPS,
    BOUNCE_JACOBI_SWEEPS,
    CONVERGED,
    JACOBI_FROM,
    MAX_WAVES,
    RESTITUTION_SWEEPS,
    WAVE_ITERATIONS,
    WAVE_SWEEPS,
)
from ..core.state import State, V, W, with_static
from ..dynamics.model import Model
from . import contact_model, energy_guard, jacobi, resting, solver
from .contact_model import Impulses
from .rows import ContactRows


def in_waves(
    model: Model,
    state: State,
    c: ContactPoints,
    rows: ContactRows,
    restitution_threshold: float,
    min_normal_speed: np.ndarray,
    events: EventLog,
    now: float,
    *,
    jacobi_from: int = JACOBI_FROM,
) -> int:
    """Bounce the contacts of ``c`` that arrive, wave after wave (the module's rule); velocities
    change in place. Returns the number of waves.

    ``min_normal_speed`` (m/s, ≤ 0) is the least normal speed each contact may have without being
    stopped: zero for a touching contact, −gap/dt for a speculative one, which therefore arrives only
    when it closes faster than gap/dt (and faster than ``restitution_threshold``). Slower approaches
    are left alone (``stop_approaches``).
    """
    if len(c) == 0:
        return 0
    v, w = with_static(state.body[:, V]), with_static(state.body[:, W])
    keys = None
    waves = 0
    iterations = max(model.solver_iterations, WAVE_ITERATIONS)
    while waves < MAX_WAVES:
        vn = rows.normal_speeds(v)
        arriving = (vn < min_normal_speed - APPROACH_SPEED) & (-vn > restitution_threshold)
        if not np.count_nonzero(arriving):
            break
        idx = arriving.nonzero()[0]
        wave = rows.subset(idx)
        before = _velocities(wave, v, w)
        imp = solver.solve(
            wave,
            v,
            w,
            -wave.restitution * vn[idx],
            Impulses.zeros(len(idx)),
            iterations,
            jacobi_sweeps=BOUNCE_JACOBI_SWEEPS,
            jacobi_from=jacobi_from,
        )
        scale = energy_guard.keep_impulses(model, wave, before, v, w)
        keys = c.keys() if keys is None else keys
        events.add(now, c.subset(idx), keys[idx], imp.normal * scale)
        waves += 1
    if waves:
        state.body[:, V] = v[:-1]
        state.body[:, W] = w[:-1]
    return waves


def stop_approaches(
    model: Model,
    state: State,
    c: ContactPoints,
    rows: ContactRows,
    min_normal_speed: np.ndarray,
    events: EventLog,
    now: float,
    *,
    jacobi_from: int = JACOBI_FROM,
    interval: float | None = None,
) -> None:
    """Stop every contact still closing faster than its ``min_normal_speed`` allows (e = 0), solved over
    the island of touching contacts around it (BOUNCE_HOPS balls); velocities change in place.

    After ``in_waves`` these are the approaches slower than the restitution threshold, and whatever
    still arrives after MAX_WAVES waves. Inelastic impacts never add energy (checked as for a wave).

    The sweeps may leave a ball pressed between heavier ones and a plane still closing on the plane
    (Gauss–Seidel hands momentum through a light ball at about m_light/m_heavy a sweep). Those speeds
    start the ``interval`` that follows, and explicit Euler moves a ball by its start velocity alone, so
    no force over the interval can keep the ball out of the plane: planes win here too
    (``resting.hold_by_planes``, over the interval's length).
    """
    if len(c) == 0:
        return
    v, w = with_static(state.body[:, V]), with_static(state.body[:, W])
    vn = rows.normal_speeds(v)
    seeds = vn < min_normal_speed - APPROACH_SPEED
    if not np.count_nonzero(seeds):
        return
    near = _island(model, c, seeds)
    island = rows.subset(near)
    before = _velocities(island, v, w)
    imp = solver.solve(
        island,
        v,
        w,
        min_normal_speed[near],
        Impulses.zeros(len(island)),
        model.solver_iterations,
        jacobi_sweeps=BOUNCE_JACOBI_SWEEPS,
        jacobi_from=jacobi_from,
    )
    if interval is not None:
        resting.hold_by_planes(
            island,
            c.gap[near],
            model.spheres.radius,
            v.copy(),
            v,
            min_normal_speed[near],
            imp.normal,
            interval,
        )
    scale = energy_guard.keep_impulses(model, island, before, v, w)
    state.body[:, V] = v[:-1]
    state.body[:, W] = w[:-1]
    hit = c.subset(near)
    events.add(now, hit, hit.keys(), imp.normal * scale)


def _island(model: Model, c: ContactPoints, seeds: np.ndarray) -> np.ndarray:
    """The contacts within BOUNCE_HOPS balls of the ``seeds`` (a mask over ``c``)."""
    n = model.spheres.count
    involved = np.zeros(n + 1, bool)
    near = seeds
    for _ in range(BOUNCE_HOPS):
        involved[c.a[near]] = True
        involved[c.b[near]] = True
        involved[n] = False
        near = involved[c.a] | involved[c.b]
    return near


def _velocities(rows: ContactRows, v: np.ndarray, w: np.ndarray) -> tuple[np.ndarray, ...]:
    """The balls the contacts ``rows`` touch (the static row left out) and their velocities now."""
    balls = np.unique(np.concatenate((rows.a, rows.b)))
    balls = balls[balls != rows.static]
    return balls, v[balls], w[balls]


def waves_from(
    model: Model,
    rows: ContactRows,
    k: jacobi.ContactColumns,
    v: np.ndarray,
    vn_start: np.ndarray,
    restitution_threshold: float,
    pressed: np.ndarray,
) -> tuple[np.ndarray, ...]:
    """The module's rule for a frame solved as a whole (the soft step's restitution, softstep.py): the
    waves are run on the normal speeds the contacts had at the frame's start, ``vn_start``, over the
    contacts that pushed during it (``pressed``), and give what each contact's normal speed should be
    after the impact. Returns those speeds and which contacts took part in a wave.

    The frame's velocities ``v`` ((≥3, M) columns of ``k.balls``) are not changed: the waves run on a
    copy, measured as v_n(start) + (v_n(copy) − v_n(end)). A wave's impulses change the speeds the same
    way whatever velocities they start from, so this is the rule applied to the frame's start, without
    its start velocities: its arriving contacts (closing faster than the threshold) are solved together
    to v_n' ≥ −e·v_n, then those the wave set closing, at most MAX_WAVES times; no wave adds energy
    (ΔK = Σ P·(v_n + ½·Δv_n) ≤ 0, checked and scaled by ``energy_guard.wave_scale``).
    """
    copy = np.array(v[:3])
    after = np.array(vn_start)
    struck = np.zeros(k.k, bool)
    # the contacts that can take part, with what the waves need of them
    cand = (pressed & (k.ima + k.imb > 0.0)).nonzero()[0]
    kk, m = k.k, k.m
    ea, eb = k.ends[:kk][cand], k.ends[kk:][cand]
    n = k.n[:, cand]
    surface = k.surface[:, cand] if k.surface is not None else None
    ima, imb, e = k.ima[cand], k.imb[cand], rows.restitution[cand]

    def speeds(v: np.ndarray, at: np.ndarray | slice = slice(None)) -> np.ndarray:
        s = None if surface is None else surface[:, at]
        return contact_model.normal_speed(v.take(ea[at], axis=1), v.take(eb[at], axis=1), n[:, at], s)

    offset = vn_start[cand] - speeds(copy)
    vn = vn_start[cand]
    inv3 = np.tile(k.inverse[0], 3)  # each column's own 1/m, for x, y and z
    closing = -max(restitution_threshold, APPROACH_SPEED)
    for _ in range(MAX_WAVES):
        idx = (vn < closing).nonzero()[0]  # the contacts arriving now
        if idx.size == 0:
            break
        struck[cand[idx]] = True
        before = copy.copy()
        target = -e[idx] * vn[idx] - offset[idx]  # v_n' ≥ −e·v_n, as the copy measures it
        wave = (ea[idx], eb[idx], n[:, idx], None if surface is None else surface[:, idx], ima[idx], imb[idx])
        impulse, after_vn = _wave_sweeps(wave, m, inv3, copy, target)
        after_vn += offset[idx]
        # ΔK of the wave's normal impulses: Σ P·v_n + ½·Σ P·Δv_n (spheres: they do not turn the balls)
        scale = energy_guard.wave_scale(model, rows.moving, impulse, vn[idx], after_vn)
        if scale is not None:
            copy = before + scale * (copy - before)
        # only the contacts of the balls the wave moved change speed
        moved = np.zeros(m, bool)
        moved[wave[0]] = True
        moved[wave[1]] = True
        near = (moved[ea] | moved[eb]).nonzero()[0]
        vn[near] = speeds(copy, near) + offset[near]
    after[cand] = vn
    return after, struck


def _wave_sweeps(
    wave: tuple,
    m: int,
    inv3: np.ndarray,
    v: np.ndarray,
    target: np.ndarray,
    start: np.ndarray | None = None,
    sweeps: int = WAVE_SWEEPS,
) -> tuple:
    """One wave of ``waves_from``: normal impulses alone on its contacts (``wave``: their columns a and
    b, normals, moving surfaces, inverse masses), each ball's mass split among the wave's contacts that
    touch it (jacobi.py), driving v_n to ≥ ``target`` from the accumulated ``start`` (zero: None), at
    most ``sweeps`` sweeps and until none changes a contact's speed by more than CONVERGED (a wave of
    contacts that share no ball takes one). ``v`` ((3, M) columns; ``inv3`` their 1/m, three times
    over) changes in place. Returns the impulses and the wave's normal speeds after them."""
    ea, eb, n, surface, ima, imb = wave
    ends = np.concatenate((ea, eb))
    share = np.bincount(ends, minlength=m).astype(float)  # each ball's mass split among the wave
    m_n = (
        1.0 / contact_model.inverse_effective_masses(share[ea] * ima, share[eb] * imb, 0.0, 0.0, 0.0, 0.0)[0]
    )
    bound = float((ima + imb).max())  # 1/m_n unsplit: the most a unit impulse changes a contact's v_n
    # each contact end's row in one (3·M) bincount: x, y, z of column c at c, M + c, 2M + c
    rows3 = np.concatenate((ends, ends + m, ends + 2 * m))
    impulse = np.zeros(len(ea)) if start is None else start
    for _ in range(sweeps):
        vn = contact_model.normal_speed(v.take(ea, axis=1), v.take(eb, axis=1), n, surface)
        new = contact_model.normal_impulse(impulse, m_n, target, vn)
        d = new - impulse
        impulse = new
        change = float(np.abs(d).max()) * bound
        if change == 0.0:
            return impulse, vn
        push = d * n
        v += (
            np.bincount(rows3, np.concatenate((push, -push), axis=1).ravel(), minlength=3 * m) * inv3
        ).reshape(3, m)
        if change < CONVERGED:
            break
    return impulse, contact_model.normal_speed(v.take(ea, axis=1), v.take(eb, axis=1), n, surface)


def normal_solve(
    rows: ContactRows,
    k: jacobi.ContactColumns,
    vw: np.ndarray,
    idx: np.ndarray,
    start: np.ndarray,
    target: np.ndarray,
) -> np.ndarray:
    """Normal impulses alone (friction and rolling resistance left out) driving the contacts ``idx`` of
    a soft frame (``rows``, ``k``) to v_n ≥ ``target``, from the accumulated ``start`` (which may be
    taken back, never below zero). Fewer than JACOBI_FROM contacts are solved colour by colour
    (``solver.solve``) to convergence, at most WAVE_ITERATIONS sweeps: a struck chain's answer is then
    exact. More (a pile landing) take RESTITUTION_SWEEPS Jacobi sweeps with mass splitting, as Box2D's
    restitution pass. ``vw`` ((≥3, M) columns of ``k.balls``) changes in place; returns the
    accumulated impulses."""
    if len(idx) >= JACOBI_FROM:
        kk = k.k
        surface = k.surface[:, idx] if k.surface is not None else None
        wave = (k.ends[:kk][idx], k.ends[kk:][idx], k.n[:, idx], surface, k.ima[idx], k.imb[idx])
        v = np.array(vw[:3])
        normal, _ = _wave_sweeps(
            wave, k.m, np.tile(k.inverse[0], 3), v, target, start.copy(), RESTITUTION_SWEEPS
        )
        vw[:3] = v
        return normal
    sub = rows.subset(idx)
    balls = np.unique(np.concatenate((sub.a, sub.b)))
    cols = np.searchsorted(k.balls, balls)  # among the frame's columns
    none = np.zeros(len(sub))
    smooth = dataclasses.replace(sub, friction=none, rolling=none)
    full, spin = np.zeros((sub.static + 1, 3)), np.zeros((sub.static + 1, 3))
    full[balls] = vw[:3, cols].T
    imp = Impulses.zeros(len(sub))
    imp.normal[:] = start
    imp = solver.solve(smooth, full, spin, target, imp, WAVE_ITERATIONS)
    vw[:3, cols] = full[balls].T
    return imp.normal
