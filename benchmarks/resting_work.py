"""Energy an elastic, frictionless closed box gains in split steps: two scenes the long fuzz search found.

Both run in a cube of six infinite elastic frictionless walls (|x|, |y|, |z| ≤ 1), gravity −9.81 along
y, RK2 at 1/60 s, so the total energy may only stay as it is (up to rounding):

- ``coincident``: ten 1 kg balls created at the cube's centre (nine of radius 6.25 cm, one 7.8 mm);
- ``shell``: a 25 cm, 1 kg ball in a corner, touching three walls, and a 0.5 mm, 10 g ball inside its
  shell at rest.

    .venv/bin/python benchmarks/resting_work.py

prints the first step whose total energy rose above the start's. The rise comes in an interval integrated
with the resting solve's constant forces: a touching contact that is separating slowly at the
interval's start while gravity closes it is held at v_n = 0 at the end, and the constant push does
work J·(v_n0 + v_n1)/2 > 0 on the way. Since the resting solve lets such a contact end closing at v_n0
(``resting.workless_targets``) it prints nothing: the energy never rises (+0.017 J and +2.6e-7 J
before; tests/physics/test_resting.py holds both scenes).
"""

import numpy as np

import ballpit


def cube(**balls) -> ballpit.World:
    world = ballpit.World(integrator="rk2")
    for face in (*np.eye(3), *-np.eye(3)):
        world.add_plane(position=face, normal=-face, restitution=1.0, friction=0.0)
    world.add_spheres(restitution=1.0, friction=0.0, **balls)
    return world


def main() -> None:
    scenes = {
        "coincident": cube(positions=np.zeros((10, 3)), radius=[0.0625] * 8 + [0.0078125, 0.0625]),
        "shell": cube(
            positions=[(-0.75, -0.75, -0.75), (-0.75, -0.5949668382248494, -0.5949668382248494)],
            radius=[0.25, 0.0005],
            mass=[1.0, 0.01],
        ),
    }
    for name, world in scenes.items():
        start = world.kinetic_energy() + world.potential_energy()
        for k in range(40):
            world.step(1 / 60)
            gain = world.kinetic_energy() + world.potential_energy() - start
            if gain > 1e-12 * abs(start) + 1e-12:
                print(f"{name}: from step {k + 1} the total energy is {gain:+.3e} J above the start's")
                break


if __name__ == "__main__":
    main()
