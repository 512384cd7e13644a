"""The all-contacts-at-once solve (Jacobi with mass splitting) reaches the same answers the
colour-by-colour solve does: checked against the closed forms of a resting column and of balls that
slide or stick on the floor."""

import numpy as np
import pytest

from ballpit.physics.contact import jacobi, solver
from ballpit.physics.contact.contact_model import Impulses
from ballpit.physics.contact.rows import ContactRows
from ballpit.physics.core.settings import JACOBI_FROM, JACOBI_SWEEPS

G, DT, R, M = 9.81, 1 / 240, 0.5, 2.0


def equal_balls(a: np.ndarray, b: np.ndarray, normal: np.ndarray, friction: float,
                rolling: float) -> ContactRows:  # fmt: skip
    """Contacts between balls of mass M and radius R; b = len(a) is the floor (the static row)."""
    n = len(a)
    on_floor = b == n
    inv_mass, inv_inertia = 1 / M, 1 / (0.4 * M * R * R)
    return ContactRows(
        a=a,
        b=b,
        normal=normal,
        radius_a=np.full(n, R),
        radius_b=np.where(on_floor, 0.0, R),
        inv_mass_a=np.full(n, inv_mass),
        inv_mass_b=np.where(on_floor, 0.0, inv_mass),
        inv_inertia_a=np.full(n, inv_inertia),
        inv_inertia_b=np.where(on_floor, 0.0, inv_inertia),
        restitution=np.zeros(n),
        friction=np.full(n, friction),
        rolling=np.full(n, rolling),
        surface=np.zeros((n, 3)),
        spin=np.zeros((n, 3)),
        moving=False,
        static=n,
    )


def column(n: int) -> ContactRows:
    """n balls stacked on the floor: contact i holds ball i on ball i − 1 (ball 0 on the floor, the
    static row n)."""
    normal = np.tile([0.0, 1.0, 0.0], (n, 1))
    return equal_balls(np.arange(n), np.r_[n, np.arange(n - 1)], normal, friction=0.5, rolling=0.01)


def test_a_resting_column_carries_the_weight_above_each_contact():
    n = 20  # a column converges in about n² sweeps
    rows = column(n)
    v = np.zeros((n + 1, 3))
    v[:n, 1] = -G * DT  # every ball after a step of free fall
    w = np.zeros((n + 1, 3))
    imp = jacobi.solve(rows, v, w, np.zeros(n), Impulses.zeros(n), 20_000)
    # contact i holds the n − i balls from i up: P = (n − i)·m·g·dt
    assert imp.normal == pytest.approx((n - np.arange(n)) * M * G * DT, rel=1e-6)
    assert np.abs(v).max() < 1e-7  # every ball stopped (from g·dt = 0.04 m/s)
    assert np.abs(w).max() == 0.0 and np.abs(imp.friction).max() == 0.0  # nothing to turn or slip


def test_the_dispatch_gives_a_column_the_jacobi_solve_from_its_threshold_on():
    n = JACOBI_FROM
    rows = column(n)
    results = []
    for solve in (solver.solve, jacobi.solve):
        v = np.zeros((n + 1, 3))
        v[:n, 1] = -G * DT
        imp = solve(rows, v, np.zeros((n + 1, 3)), np.zeros(n), Impulses.zeros(n), 7)
        results.append(imp.normal)
    # solver.solve asks for JACOBI_SWEEPS sweeps per iteration
    v = np.zeros((n + 1, 3))
    v[:n, 1] = -G * DT
    direct = jacobi.solve(rows, v, np.zeros((n + 1, 3)), np.zeros(n), Impulses.zeros(n),
                          7 * JACOBI_SWEEPS)  # fmt: skip
    assert np.array_equal(results[0], direct.normal)


def test_a_falling_column_is_never_pushed_upwards_while_it_is_stopped():
    """Sweep by sweep the column's balls only slow down: none is pushed past rest."""
    n = 80
    rows = column(n)
    v = np.zeros((n + 1, 3))
    v[:n, 1] = -G * DT
    w = np.zeros((n + 1, 3))
    imp = Impulses.zeros(n)
    for _ in range(200):
        jacobi.solve(rows, v, w, np.zeros(n), imp, 1)
        assert v[:n, 1].max() <= 1e-15


def landing_on_one_ball(k: int) -> ContactRows:
    """k balls (0 … k−1) landing at once on ball k, which sits on the floor (static row k + 1); the
    last contact holds ball k on the floor."""
    angles = 2 * np.pi * np.arange(k) / k
    tilt = np.radians(30.0)
    up = np.stack((np.sin(tilt) * np.cos(angles), np.full(k, np.cos(tilt)), np.sin(tilt) * np.sin(angles)), 1)
    normal = np.vstack((up, [0.0, 1.0, 0.0]))
    return equal_balls(np.r_[np.arange(k), k], np.r_[np.full(k, k), k + 1], normal, friction=0.0, rolling=0.0)


def test_mass_splitting_never_pushes_a_ball_faster_than_anything_arrived():
    """Six balls land at 1 m/s on one ball on the floor. Plain Jacobi gives each contact the whole
    ball underneath, so the six pushes add up and drive it into the floor at several m/s; split
    masses keep every sweep's velocities within the arrival speed."""
    k, u = 6, 1.0
    rows = landing_on_one_ball(k)
    v = np.zeros((k + 2, 3))
    v[:k, 1] = -u
    w = np.zeros((k + 2, 3))
    imp = Impulses.zeros(k + 1)
    for _ in range(50):
        jacobi.solve(rows, v, w, np.zeros(k + 1), imp, 1)
        assert np.linalg.norm(v, axis=1).max() <= u + 1e-12
    assert imp.normal.min() > 0.0  # every contact took part


@pytest.mark.parametrize("friction_every", [1, 4])
def test_friction_in_some_sweeps_only_gives_sliding_and_sticking_balls_their_closed_forms(friction_every):
    """Balls on the floor after a step of free fall, moving sideways at u. Fast ones slide: friction
    takes μ·g·dt off u and the floor holds m·g·dt. Slow ones stick: they leave rolling, at 5/7·u with
    ω = −v/R. Friction updated in only every fourth sweep must reach the same answers."""
    n, mu = 70, 0.5
    u = np.where(np.arange(n) % 2 == 0, 1.0, 0.01)  # 2/7·u against μ·g·dt = 0.0204: slide, then stick
    rows = equal_balls(
        np.arange(n), np.full(n, n), np.tile([0.0, 1.0, 0.0], (n, 1)), friction=mu, rolling=0.0
    )
    v = np.zeros((n + 1, 3))
    v[:n, 0], v[:n, 1] = u, -G * DT
    w = np.zeros((n + 1, 3))
    imp = jacobi.solve(rows, v, w, np.zeros(n), Impulses.zeros(n), 8, friction_every)
    slides = u > 0.5
    assert imp.normal == pytest.approx(np.full(n, M * G * DT), rel=1e-12)
    assert np.abs(v[:n, 1]).max() < 1e-12
    assert v[:n, 0][slides] == pytest.approx(u[slides] - mu * G * DT, rel=1e-12)
    assert v[:n, 0][~slides] == pytest.approx(5 / 7 * u[~slides], rel=1e-12)
    assert w[:n, 2][~slides] == pytest.approx(-5 / 7 * u[~slides] / R, rel=1e-12)


@pytest.mark.slow
def test_adding_up_one_row_at_a_time_gives_the_same_bits_as_the_kept_bins(monkeypatch):
    # Big solves (beyond ADD_UP_BINS_UP_TO entries) add up their pushes one np.bincount a row instead
    # of one over every row; the bundled scenes are too small to take that path. Forced everywhere, the
    # landing pile must come out bit for bit as with the bins: the same sums in the same order.
    from ballpit.scene import read_scene, resolve_scene_path

    def landed(bins: int) -> np.ndarray:
        monkeypatch.setattr(jacobi, "ADD_UP_BINS_UP_TO", bins)
        scene = read_scene(resolve_scene_path("pile"))
        for _ in range(75):  # into the landing: every frame crowded, the overlaps moved apart
            scene.world.step(scene.timestep)
        return scene.world.state.body.copy()

    kept, by_row = landed(1 << 40), landed(0)
    assert kept.tobytes() == by_row.tobytes()
