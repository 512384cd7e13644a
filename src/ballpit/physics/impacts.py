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
down until it adds none (``_keep_energy``); scaling impulses keeps momentum.

What it gives: a touching cradle struck by one ball passes the impulse down the line and only the
last ball leaves; struck by two, two leave; the Galilean cannon's top ball leaves at
(3M − m)/(M + m)·v. A ball struck from two sides at once (two contacts in one wave) gets the
simultaneous answer: equal balls at ±v on a ball at rest go back at ∓v and it stays; at 2 and −1
m/s they leave at −4/3 and 5/3 and the middle one at 2/3 (energy and momentum kept).

At the bound: what still closes after MAX_WAVES waves is stopped, e = 0, by ``stop_approaches``
(an inelastic impact never adds energy). So are the slower approaches, after the waves.
"""

from __future__ import annotations

import math

import numpy as np

from . import contact_model, solver
from .contact_model import Impulses
from .contacts import ContactPoints, EventLog
from .model import Model
from .rows import ContactRows
from .settings import (
    APPROACH_SPEED,
    BOUNCE_HOPS,
    BOUNCE_JACOBI_SWEEPS,
    JACOBI_FROM,
    MAX_WAVES,
    WAVE_ITERATIONS,
)
from .state import State, V, W, with_static


def normal_speeds(rows: ContactRows, v: np.ndarray) -> np.ndarray:
    """Each contact's normal speed v_n (negative: closing), from the (N+1, 3) velocities ``v`` (row N the
    static world), relative to a moving plane's surface (``contact_model.normal_speed``)."""
    v_a, v_b = np.take(v, rows.a, axis=0).T, np.take(v, rows.b, axis=0).T
    return contact_model.normal_speed(v_a, v_b, rows.normal.T, rows.surface.T if rows.moving else None)


def in_waves(model: Model, state: State, c: ContactPoints, rows: ContactRows, restitution_threshold: float,
             min_normal_speed: np.ndarray, events: EventLog, now: float, *,
             jacobi_from: int = JACOBI_FROM) -> int:  # fmt: skip
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
        vn = normal_speeds(rows, v)
        arriving = (vn < min_normal_speed - APPROACH_SPEED) & (-vn > restitution_threshold)
        if not arriving.any():
            break
        idx = np.flatnonzero(arriving)
        wave = rows.subset(idx)
        before = _velocities(wave, v, w)
        imp = solver.solve(wave, v, w, -wave.restitution * vn[idx], Impulses.zeros(len(idx)), iterations,
                           jacobi_sweeps=BOUNCE_JACOBI_SWEEPS, jacobi_from=jacobi_from)  # fmt: skip
        scale = _keep_energy(model, wave, before, v, w)
        keys = c.keys() if keys is None else keys
        events.add(now, c.subset(idx), keys[idx], imp.normal * scale)
        waves += 1
    if waves:
        state.body[:, V] = v[:-1]
        state.body[:, W] = w[:-1]
    return waves


def stop_approaches(model: Model, state: State, c: ContactPoints, rows: ContactRows,
                    min_normal_speed: np.ndarray, events: EventLog, now: float, *,
                    jacobi_from: int = JACOBI_FROM) -> None:  # fmt: skip
    """Stop every contact still closing faster than its ``min_normal_speed`` allows (e = 0), solved over
    the island of touching contacts around it (BOUNCE_HOPS balls); velocities change in place.

    After ``in_waves`` these are the approaches slower than the restitution threshold, and whatever
    still arrives after MAX_WAVES waves. Inelastic impacts never add energy (checked as for a wave).
    """
    if len(c) == 0:
        return
    v, w = with_static(state.body[:, V]), with_static(state.body[:, W])
    vn = normal_speeds(rows, v)
    seeds = vn < min_normal_speed - APPROACH_SPEED
    if not seeds.any():
        return
    near = _island(model, c, seeds)
    island = rows.subset(near)
    before = _velocities(island, v, w)
    imp = solver.solve(island, v, w, min_normal_speed[near], Impulses.zeros(len(island)),
                       model.solver_iterations, jacobi_sweeps=BOUNCE_JACOBI_SWEEPS,
                       jacobi_from=jacobi_from)  # fmt: skip
    scale = _keep_energy(model, island, before, v, w)
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


def _keep_energy(model: Model, rows: ContactRows, before: tuple[np.ndarray, ...], v: np.ndarray,
                 w: np.ndarray) -> float:  # fmt: skip
    """Make sure the impulses just applied to the balls of ``rows`` added no kinetic energy, and return
    the factor they were scaled by (1 when they added none).

    With Δ the velocity change, K(s) = K₀ + s·B + ½·s²·A (B = Σ m·v₀·Δv + I·ω₀·Δω, A = Σ m·Δv² + I·Δω²).
    If K(1) > K₀, the impulses are scaled by s = −2B/A (0 if B ≥ 0), where K(s) = K₀: equal and opposite
    impulses stay so, and momentum is kept. A moving plane may give energy (a paddle): not checked then.
    """
    balls, v0, w0 = before
    if rows.moving or len(balls) == 0:
        return 1.0
    dv, dw = v[balls] - v0, w[balls] - w0
    mass = model.spheres.mass[balls]
    inertia = 1.0 / model.spheres.inv_inertia[balls]

    def dot(x: np.ndarray, y: np.ndarray) -> np.ndarray:
        return x[:, 0] * y[:, 0] + x[:, 1] * y[:, 1] + x[:, 2] * y[:, 2]

    # exact sums (math.fsum): the same bits on every CPU
    b = math.fsum(mass * dot(v0, dv)) + math.fsum(inertia * dot(w0, dw))
    a = math.fsum(mass * dot(dv, dv)) + math.fsum(inertia * dot(dw, dw))
    if b + 0.5 * a <= 0.0 or a == 0.0:
        return 1.0
    s = max(0.0, -2.0 * b / a)
    v[balls] = v0 + s * dv
    w[balls] = w0 + s * dw
    return s
