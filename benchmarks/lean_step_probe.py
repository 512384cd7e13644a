"""A ceiling probe for a lean crowded step: how fast could a pile land with ONE solve per step?

Not the engine's step. It is the leanest step that keeps the whole contact model (Coulomb friction,
rolling resistance, restitution from the start-of-step approach speed), built from the engine's own
stages, so its cost is a floor for any crowded step made of them:

- kept pairs from boxes grown by ``--margin`` radii, found again only when some ball has moved half
  that far (``broadphase.sphere_pairs``, ``pairs.plane_pairs``);
- the narrow phase and contact rows of the engine (``narrowphase``, ``rows``);
- one warm-started Jacobi solve (``jacobi.solve``) per step on the velocities after gravity, with
  targets: a pair arriving faster than the restitution threshold leaves at e times its approach speed; a
  pair with a gap closes by at most that gap, v_n ≥ −gap/dt; an overlap is pushed out at a fifth of
  its depth per step (Baumgarte), never faster than 1 m/s;
- symplectic Euler: x += v·dt with the solved velocities (orientation is left alone: a sphere's
  contacts do not depend on it).

What it leaves out, and the engine needs: time of impact and the guard that stops a ball passing
through a wall when a bounce turns it towards a pair left out, the exact textbook answers of the split
step, removing overlaps by positions only, the energy bookkeeping of a separation, sleeping. So it is a
ceiling on speed, not a design to copy as it is.

    PYTHONPATH=src python benchmarks/lean_step_probe.py [scenes/pile.toml] [--sweeps 16] [--steps 960]

Prints steps/s over the landing (after the first 0.5 s of free fall), the worst overlap while it lands
and at the end (fraction of a radius), and the fastest ball at the end.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np

from ballpit.physics.collision import broadphase, narrowphase
from ballpit.physics.collision.pairs import KeptPairs, plane_pairs, plane_sides
from ballpit.physics.contact import jacobi, rows, solver
from ballpit.physics.contact.resting import WarmStart
from ballpit.physics.core.contacts import ContactPoints
from ballpit.physics.core.settings import CONTACT_SLOP
from ballpit.physics.core.state import V, W, X, with_static
from ballpit.scene import read_scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", nargs="?", default=str(ROOT / "scenes" / "pile.toml"))
    ap.add_argument("--sweeps", type=int, default=16, help="Jacobi sweeps per step")
    ap.add_argument("--friction-every", type=int, default=4, help="friction in every k-th sweep")
    ap.add_argument("--steps", type=int, default=960)
    ap.add_argument("--margin", type=float, default=0.5, help="box growth, in radii")
    ap.add_argument("--dt", type=float, default=1 / 240)
    args = ap.parse_args()

    world = read_scene(args.scene).world
    model, state, dt = world.model, world.state, args.dt
    body, radius = state.body, model.spheres.radius
    gravity = np.asarray(model.gravity, float)
    restitution_threshold = model.restitution_threshold_for(dt)
    warm = WarmStart()
    kept, anchor = None, None
    free_fall = round(0.5 / dt)
    spent, worst_landing = 0.0, 0.0

    for step in range(args.steps):
        began = time.perf_counter()
        x = body[:, X]
        # kept pairs: boxes grown by the margin, found again once some ball has moved half of it
        if kept is None or np.max(np.abs(x - anchor)) > 0.5 * args.margin * radius.min():
            grow = ((1.0 + args.margin) * radius)[:, None]
            lo, hi = x - grow, x + grow
            i, j = broadphase.sphere_pairs(lo, hi)
            s, p = plane_pairs(model, state, lo, hi, dt)
            kept = KeptPairs(lo, hi, x.copy(), grow[:, 0], i, j, s, p, plane_sides(model, state, s, p),
                             (model.spheres.count, model.planes.count))  # fmt: skip
            anchor = x.copy()
        c = narrowphase.contact_points(model, state, kept)
        v, w = with_static(body[:, V]), with_static(body[:, W])
        # the speculative contacts: pairs that could close their gap within the step
        rel0 = v[c.a] - v[c.b]
        vn0 = np.einsum("ij,ij->i", rel0, c.normal)
        reach = 2.0 * dt * (np.maximum(-vn0, 0.0) + np.linalg.norm(gravity) * dt)
        near = c.gap < CONTACT_SLOP + reach
        c, vn0 = c.subset(near), vn0[near]
        batch = rows.contact_rows(model, state, c)
        target = np.where(c.gap > 0.0, -c.gap / dt, np.minimum(-0.2 * c.gap / dt, 1.0))
        arriving = (vn0 < -restitution_threshold) & (vn0 * dt < -c.gap)
        target = np.where(arriving, np.maximum(target, -batch.restitution * vn0), target)
        v[:-1] += gravity * dt
        keys = c.keys()
        imp = warm.impulses(keys, c.normal, dt)
        solver.warm_start(batch, v, w, imp)
        jacobi.solve(batch, v, w, target, imp, args.sweeps, args.friction_every)
        warm.keep(keys, imp, dt)
        body[:, V] = v[:-1]
        body[:, W] = w[:-1]
        body[:, X] += v[:-1] * dt
        state.time += dt
        if step >= free_fall:
            spent += time.perf_counter() - began
            if step % 8 == 0:
                worst_landing = max(worst_landing, _deepest(model, state, kept))
    landing = args.steps - free_fall
    speed = np.linalg.norm(body[:, V], axis=1).max()
    print(f"{Path(args.scene).name}: {len(radius)} balls, {args.sweeps} sweeps (friction every "
          f"{args.friction_every}), margin {args.margin} r: {landing / spent:.0f} steps/s while landing "
          f"({1e3 * spent / landing:.2f} ms a step); worst overlap landing {100 * worst_landing:.1f} % r, "
          f"at {state.time:.1f} s {100 * _deepest(model, state, kept):.2f} % r; fastest ball then "
          f"{speed:.3f} m/s")  # fmt: skip


def _deepest(model, state, kept: KeptPairs) -> float:
    """The deepest overlap among the kept pairs, as a fraction of the ball's radius."""
    c: ContactPoints = narrowphase.contact_points(model, state, kept)
    if len(c) == 0:
        return 0.0
    return float(np.max(-c.gap / model.spheres.radius[c.a], initial=0.0))


if __name__ == "__main__":
    main()
