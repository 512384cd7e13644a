"""A sleeping ball struck inside a step: is it woken, and is momentum kept?

Three 5 cm balls on an elastic frictionless floor, in a row along x: C (1 kg) at x = 0.6, B (10 g)
26 cm to its left, and A (10 kg) touching B on the other side. All three fall asleep; then A is set
moving at 10 m/s towards B (which wakes A's and B's islands, not C's: C is out of every pair's reach at
the step's start). A strikes B at once, and B (at about 20 m/s) reaches C 13 ms into the same 1/60 s
step. No force acts along x, so the total x momentum must stay m_A·10 = 100 kg·m/s.

    .venv/bin/python benchmarks/struck_sleeper.py

prints each step's momentum and whether C is asleep. A sleeping ball is solved as infinite mass, and only
the paths at a step's start wake islands, so B bounced off C as off a wall and C stayed asleep. Now a
step whose impulses reach a sleeping ball is undone and taken again with its island awake
(``step.struck``): the momentum stays 100 kg·m/s and C leaves at 0.40 m/s (2·m_B/(m_B + m_C) of B's
speed).
"""

import numpy as np

import ballpit


def main() -> None:
    world = ballpit.World(sleep=True, integrator="rk4")
    world.add_plane(restitution=1.0, friction=0.0)
    r, dt = 0.05, 1 / 60
    b_x = 0.6 - 2 * r - 0.26
    balls = dict(radius=r, restitution=1.0, friction=0.0)
    world.add_sphere(position=(0.6, r, 0), mass=1.0, **balls)  # C
    world.add_sphere(position=(b_x, r, 0), mass=0.01, **balls)  # B
    world.add_sphere(position=(b_x - 2 * r - 0.001, r, 0), mass=10.0, **balls)  # A
    while not world.asleep.all():
        world.step(dt)
    world.spheres[2].velocity = (10.0, 0.0, 0.0)
    for k in range(3):
        p = float((world.spheres.masses * world.spheres.velocities[:, 0]).sum())
        world.step(dt)
        q = float((world.spheres.masses * world.spheres.velocities[:, 0]).sum())
        v = np.round(world.spheres.velocities[:, 0], 4).tolist()
        asleep = bool(world.asleep[0])
        print(f"step {k}: x momentum {p:.4f} -> {q:.4f} kg·m/s; C asleep: {asleep}; vx (C, B, A) {v}")


if __name__ == "__main__":
    main()
