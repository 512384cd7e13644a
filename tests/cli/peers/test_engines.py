"""Every engine runs the same material: a dropped ball bounces with e = 0.25, a sliding one slows at
μg with μ = 0.25 and rolls on at 5/7 of its speed (test_report.py lands a grid in each).

A peer whose package is not installed (the optional ``bench`` extra) is skipped, by name."""

import importlib.util
import re

import numpy as np
import pytest

from ballpit.cli.peers.engines import ENGINES
from ballpit.cli.peers.landing import DT, FRICTION, GRAVITY, RADIUS, RESTITUTION, Landing
from ballpit.cli.peers.measure import bounce

# MuJoCo's contact is a damped spring; at 240 Hz it bounces livelier on fast impacts (mujoco_engine.py)
BOUNCE_TOLERANCE = {"ballpit": 0.01, "mujoco": 0.1, "pybullet": 0.03}


def engine_param(name: str):
    package = ENGINES[name].package
    missing = package is not None and importlib.util.find_spec(package) is None
    reason = f"{package} is not installed (pip install 'ballpit[bench]')"
    return pytest.param(name, marks=pytest.mark.skipif(missing, reason=reason))


ALL = [engine_param(name) for name in ENGINES]


@pytest.mark.parametrize("engine", ALL)
def test_a_ball_dropped_on_the_floor_bounces_with_e_a_quarter(engine):
    spec = ENGINES[engine]
    assert bounce(engine, spec.configure({})) == pytest.approx(RESTITUTION, abs=BOUNCE_TOLERANCE[engine])


@pytest.mark.parametrize("engine", ALL)
def test_a_ball_sliding_on_the_floor_slows_at_mu_g_then_rolls_at_five_sevenths(engine):
    """Launched at v0 without spin, it slides with deceleration μg until v = 5/7·v0 at t = 2v0/(7μg)."""
    spec = ENGINES[engine]
    v0 = 1.0
    run = spec.start(
        Landing(np.array([[0.0, RADIUS, 0.0]]), 1.0, np.array([[v0, 0.0, 0.0]])), spec.configure({})
    )
    t_roll = 2 * v0 / (7 * FRICTION * GRAVITY)  # 0.117 s
    frame = DT * run.steps_per_advance
    for k in range(1, 31):  # half a second
        run.advance()
        t, v = k * frame, run.velocities()[0, 0]
        if t < t_roll - 2 * frame:  # sliding (MuJoCo's soft contact takes a step or two to carry the ball)
            assert v == pytest.approx(v0 - FRICTION * GRAVITY * t, abs=0.03), f"t = {t:.3f} s"
    assert v == pytest.approx(5 / 7 * v0, abs=0.005)


def test_pybullet_balls_are_rigid_bodies_in_the_peers_and_the_bench_pile():
    """Both ``--peers`` and ``bench --workload pile --pybullet`` build their balls with ``build_world``."""
    pytest.importorskip("pybullet", reason="pybullet is not installed (pip install 'ballpit[bench]')")
    import pybullet as p

    from ballpit.cli.peers.pybullet_engine import PybulletRun, PybulletSettings, build_world

    client = p.connect(p.DIRECT)
    try:
        balls = build_world(client, Landing.of(8).centres, 1.0, restitution=0.5, friction=0.5, gravity=9.81)
        types = {p.getDynamicsInfo(b, -1, physicsClientId=client)[10] for b in balls}
        assert types == {1}  # btRigidBody, PyBullet's maximal coordinates; a multibody is 2
    finally:
        p.disconnect(physicsClientId=client)
    run = PybulletRun(Landing.of(8), PybulletSettings())
    assert {p.getDynamicsInfo(b, -1, physicsClientId=run.client)[10] for b in run.balls} == {1}
    p.disconnect(physicsClientId=run.client)


def test_settings_are_overridden_by_name_with_their_own_types():
    mujoco = ENGINES["mujoco"].configure({"iterations": "20", "solver": "PGS", "tolerance": "1e-6"})
    assert (mujoco.iterations, mujoco.solver, mujoco.tolerance) == (20, "PGS", 1e-6)
    assert ENGINES["pybullet"].configure({"maximal_coordinates": "false"}).maximal_coordinates is False


@pytest.mark.parametrize(
    ("engine", "overrides", "message"),
    [
        ("mujoco", {"iterations": "many"}, "mujoco setting iterations='many': expected a whole number"),
        ("pybullet", {"maximal_coordinates": "yes"}, "expected true or false"),
        ("ballpit", {"solver": "CG"}, "ballpit has no setting 'solver' (it has integrator, substeps)"),
    ],
)
def test_a_bad_setting_is_refused_by_name(engine, overrides, message):
    with pytest.raises(ValueError, match=re.escape(message)):
        ENGINES[engine].configure(overrides)
