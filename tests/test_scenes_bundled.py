"""The bundled scenes: each one checks and simulates, and the demos do what their comments promise.

The slopes demo is judged only from what the real command line writes (trajectory and events CSV),
the way a user would check it.
"""

from __future__ import annotations

import math
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from ballpit.physics.dynamics.integrators import INTEGRATORS
from ballpit.scene import bundled_scenes, load_scene, read_scene
from ballpit.viewer.camera import Camera

from .cli.runner import run_in_process

SHARED = ("slopes_run",)  # 10 s of the slopes through the CLI, made once (tests/conftest.py: on one worker)
ROOT = Path(__file__).resolve().parents[1]
SCENES = ROOT / "scenes"
REQUIRED = {
    "slopes",
    "cradle",
    "cradle_touching",
    "cannon",
    "billiards",
    "incline",
    "pile",
    "pile10k",
    "seesaw",
    "integrators",
}
# Enough simulated time to exercise each scene while keeping the suite fast (big piles: a few steps).
SHORT_RUN = {"pile": 3, "pile10k": 2, "gas": 3, "billiards": 20}  # steps
DEFAULT_STEPS = 24


def ballpit(*args: str | Path, timeout: float = 300) -> subprocess.CompletedProcess:
    return run_in_process(*args, cwd=ROOT)


def simulate_csv(tmp_path: Path, scene: str, *args: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Run ``ballpit simulate`` and read back (trajectory rows, event rows, event kinds)."""
    out, ev = tmp_path / f"{scene}.csv", tmp_path / f"{scene}-events.csv"
    r = ballpit("simulate", SCENES / f"{scene}.toml", "--out", out, "--events", ev, *args)
    assert r.returncode == 0, r.stderr
    traj = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    kinds = np.loadtxt(ev, delimiter=",", skiprows=1, usecols=1, dtype=str, ndmin=1)
    events = np.loadtxt(ev, delimiter=",", skiprows=1, usecols=[0, 2, 3, 4, 5, 6, 7, 8, 9, 10], ndmin=2)
    return traj, events, kinds


def test_the_required_scenes_are_bundled():
    names = {p.stem for p in bundled_scenes()}
    assert names >= REQUIRED, REQUIRED - names
    assert (SCENES / "slopes.toml") in bundled_scenes() or any(
        p.name == "slopes.toml" for p in bundled_scenes()
    )


@pytest.mark.parametrize("path", sorted(SCENES.glob("*.toml")), ids=lambda p: p.stem)
def test_every_bundled_scene_checks_and_simulates(tmp_path, path):
    r = ballpit("check", path)
    assert r.returncode == 0 and ": ok:" in r.stdout, r.stderr
    scene = read_scene(path)
    world = scene.world
    steps = SHORT_RUN.get(path.stem, DEFAULT_STEPS)
    dt = scene.timestep
    out = tmp_path / "t.csv"
    r = ballpit("simulate", path, "--duration", repr(steps * dt), "--out", out)
    assert r.returncode == 0, r.stderr
    assert f"{steps} steps" in r.stdout
    rows = np.loadtxt(out, delimiter=",", skiprows=1, ndmin=2)
    assert rows.shape == ((steps + 1) * len(world.spheres), 15)
    assert np.isfinite(rows).all()
    first = path.read_text().splitlines()[0]
    assert first.startswith("# "), "each scene opens with a one-line description"


@pytest.mark.parametrize(("name", "at_least"), [("pile", 1000), ("pile10k", 10_000)])
def test_piles_pour_into_a_box(name, at_least):
    world = load_scene(SCENES / f"{name}.toml")
    assert len(world.spheres) >= at_least
    planes = list(world.planes)
    assert len(planes) == 5 and all(not p.infinite for p in planes)
    floor, walls = planes[0], planes[1:]
    assert np.allclose(floor.normal, [0, 1, 0])
    assert all(abs(w.normal[1]) < 1e-12 for w in walls)
    # every ball starts above the floor and inside the walls' footprint
    pos = world.spheres.positions
    half = floor.size[0] / 2
    assert (np.abs(pos[:, [0, 2]]) < half).all() and (pos[:, 1] > 0).all()


MULTIPLES = {"twice": 2, "three times": 3, "four times": 4, "five times": 5, "six times": 6,
             "seven times": 7, "eight times": 8, "nine times": 9, "ten times": 10}  # fmt: skip


def test_ballpit_scenes_states_true_ball_counts():
    """Every count ``ballpit scenes`` gives ("1,200 balls", "the 1,200-ball pile.toml", "eight times
    over" another scene) is what the scenes hold."""
    r = ballpit("scenes")
    assert r.returncode == 0, r.stderr
    counts = {p.stem: len(load_scene(p).spheres) for p in bundled_scenes()}
    checked = 0
    for line in r.stdout.splitlines():
        name, text = line.split(None, 1)
        number = r"(\d{1,3}(?:,\d{3})+|\d+)"
        for n in re.findall(number + r"(?=(?: [a-z]+,?){0,3} balls\b)", text):
            assert int(n.replace(",", "")) == counts[name], line
            checked += 1
        for n, other in re.findall(number + r"-ball (\w+)\.toml", text):
            assert int(n.replace(",", "")) == counts[other], line
            checked += 1
        for other in re.findall(r"(\w+)\.toml", text):
            for words, k in MULTIPLES.items():
                if words in text:
                    assert k * counts[other] == counts[name], line
    assert checked >= 3  # gas, pile and pile10k at least


def test_incline_balls_accelerate_as_the_textbook_says(tmp_path):
    traj, _, _ = simulate_csv(tmp_path, "incline", "--duration", "1.0")
    vx = traj[-4:, 5]  # the four balls at t = 1 s
    speed_along_slope = -vx / math.cos(math.radians(30))
    g = 9.81
    s, c = math.sin(math.radians(30)), math.cos(math.radians(30))
    expected = [g * s, g * (s - 0.1 * c), 5 / 7 * g * s, 3 / 5 * g * s]
    assert np.allclose(speed_along_slope, expected, rtol=0.01)


def test_cradle_passes_momentum_down_the_line(tmp_path):
    traj, _, kinds = simulate_csv(tmp_path, "cradle", "--duration", "0.5")
    last = traj[-6:]
    assert np.allclose(last[:5, 5], 0, atol=0.02), "the striker and the middle balls stop"
    assert last[5, 5] == pytest.approx(2.0, rel=0.01), "the far ball leaves at the striker's speed"
    assert (kinds == "sphere-sphere").sum() >= 5


@pytest.mark.slow
def test_integrators_agree_at_first_then_part_ways(tmp_path):
    """The integrators demo, judged from ``ballpit simulate --integrator`` output: drag is the only force
    that changes within a step, so the runs agree to millimetres for the first second; the balls'
    meetings then multiply the difference until every other integrator's balls are far from RK4's. Its
    first line names every registered integrator and promises the others' ghosts (G shows all but the
    one running)."""
    first = (SCENES / "integrators.toml").read_text().splitlines()[0].lower()
    assert all(i.label.lower() in first for i in INTEGRATORS.values()), first
    assert "the other integrators' ghosts" in first
    world = load_scene(SCENES / "integrators.toml")
    assert np.allclose(world.gravity, 0.0) and world.linear_drag > 0.0
    n, radius = len(world.spheres), float(np.median(world.spheres.radii))
    runs = {}
    for name in INTEGRATORS:
        traj, _, _ = simulate_csv(tmp_path, "integrators", "--integrator", name, "--duration", "5")
        runs[name] = traj.reshape(-1, n, 15)
    times = runs["rk4"][:, 0, 0]
    one, five = np.argmin(np.abs(times - 1.0)), len(times) - 1
    assert times[five] == pytest.approx(5.0, abs=0.04)
    for name in set(INTEGRATORS) - {"rk4"}:
        apart = np.linalg.norm(runs[name][:, :, 2:5] - runs["rk4"][:, :, 2:5], axis=2)
        assert apart[one].max() < 0.05, name
        assert np.median(apart[five]) > 2 * radius, (name, apart[five])
    # all of them lose energy to the drag only: the walls and balls are perfectly elastic and smooth
    speeds = {k: np.linalg.norm(r[:, :, 5:8], axis=2) for k, r in runs.items()}
    assert all((s[five] ** 2).sum() < (s[0] ** 2).sum() for s in speeds.values())


def test_touching_cradle_sends_off_two_balls_when_two_strike(tmp_path):
    """Two touching strikers at 2 m/s hit five touching balls: the strikers and the three first balls
    stop, the last two leave at 2 m/s (impacts in waves), and energy is kept."""
    traj, _, _ = simulate_csv(tmp_path, "cradle_touching", "--duration", "0.6")
    last = traj[-7:]  # balls in scene order: the two strikers, then the row left to right
    assert np.allclose(last[:5, 5], 0, atol=0.04), "the strikers and the first three balls stop"
    assert last[5:, 5] == pytest.approx([2.0, 2.0], rel=0.02), "the last two leave at the strikers' speed"
    world = load_scene(SCENES / "cradle_touching.toml")
    energy = 0.5 * float(np.sum(world.spheres.masses * np.sum(world.spheres.velocities**2, axis=1)))
    assert 0.5 * float(np.sum(world.spheres.masses * np.sum(last[:, 5:8] ** 2, axis=1))) == pytest.approx(
        energy, rel=1e-3
    )


def test_cannon_throws_its_top_ball_far_above_where_it_was_dropped_from(tmp_path):
    """The three stacked balls land together; the top one rises to the closed-form height of two
    elastic impacts in turn (floor, big on middle, middle on top), more than four times its start."""
    traj, _, _ = simulate_csv(tmp_path, "cannon", "--duration", "2.5")
    world = load_scene(SCENES / "cannon.toml")
    (m1, m2, m3), (r1, r2, r3) = world.spheres.masses, world.spheres.radii
    start = float(world.spheres.positions[2, 1])
    v = math.sqrt(2 * 9.81 * (float(world.spheres.positions[0, 1]) - r1))  # landing speed
    v2 = (3 * m1 - m2) / (m1 + m2) * v  # the middle ball off the bounced big one
    v3 = ((m3 - m2) * -v + 2 * m2 * v2) / (m2 + m3)  # the top ball off the middle one
    apex = 2 * r1 + 2 * r2 + r3 + v3 * v3 / (2 * 9.81)
    top = traj[2::3, 3].max()
    assert top == pytest.approx(apex, rel=0.01)
    assert top > 4 * start


@pytest.mark.slow  # seconds of subprocesses or real-time steps: make test, not make check
def test_seesaw_rolls_the_balls_down_then_tips_them_off_its_far_end(tmp_path):
    """The see-saw demo, judged from ``ballpit simulate`` output: the balls land on the plank, roll
    left (downhill), turn back as it tips over, and leave its right end for the floor."""
    traj, events, kinds = simulate_csv(tmp_path, "seesaw", "--duration", "5.5")
    world = load_scene(SCENES / "seesaw.toml")
    n = len(world.spheres)
    assert n == 5
    plank = world.planes[1]
    assert np.any(plank.angular_velocity != 0) and plank.size == (5.0, 2.2)
    t, x, y = (traj[:, k].reshape(-1, n) for k in (0, 2, 3))
    radius = np.asarray(world.spheres.radii)
    riding = (t[:, 0] > 0.7) & (t[:, 0] < 3.5)
    assert (y[riding] > 2.0).all(), "no ball leaves the plank early"
    leftmost = x.min(axis=0)
    assert (leftmost < x[0] - 0.5).all(), "each ball first rolls left, downhill"
    assert (leftmost > -2.3).all(), "and turns back before the plank's left end"
    assert np.allclose(y[-1], radius, atol=0.01), "all on the floor at the end"
    assert (x[-1] > 4.0).all(), "right of the plank's reach (2.5 m from its centre)"
    plane_hits = events[kinds == "sphere-plane"]
    on_plank, on_floor = plane_hits[plane_hits[:, 2] == 1], plane_hits[plane_hits[:, 2] == 0]
    for ball in range(n):
        assert on_plank[on_plank[:, 1] == ball, 0].min() < on_floor[on_floor[:, 1] == ball, 0].min()
    assert on_floor[:, 0].min() > 4.0, "nothing reaches the floor before the plank has tipped"


# --------------------------------------------------------------------------- the slopes demo

GROUND, SLOPES = 0, {1, 2, 3, 4}
RADIUS = 0.25


def project(points: np.ndarray, camera: np.ndarray, look_at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A plain look-at pinhole camera: (tan of horizontal angle, tan of vertical angle), and depth."""
    forward = look_at - camera
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 1.0, 0.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    rel = points - camera
    depth = rel @ forward
    return np.column_stack([rel @ right / depth, rel @ up / depth]), depth


@dataclass
class SlopesRun:
    world: object
    times: np.ndarray  # (T,) recorded times
    frames: np.ndarray  # (T, balls, 15) trajectory rows
    events: np.ndarray  # (K, 10) events without the kind column
    kinds: np.ndarray  # (K,) "sphere-plane" / "sphere-sphere"


@pytest.fixture(scope="module")
def slopes_run(tmp_path_factory):
    """The demo simulated headless for 10 s through the real CLI, every step recorded."""
    tmp = tmp_path_factory.mktemp("slopes")
    traj, events, kinds = simulate_csv(tmp, "slopes", "--duration", "10")
    world = load_scene(SCENES / "slopes.toml")
    n = len(world.spheres)
    times = traj[::n, 0]
    return SlopesRun(world, times, traj.reshape(len(times), n, 15), events, kinds)


def test_slopes_scene_layout():
    world = load_scene(SCENES / "slopes.toml")
    planes = list(world.planes)
    assert len(planes) == 5 and planes[GROUND].infinite and np.allclose(planes[GROUND].normal, [0, 1, 0])
    slopes = planes[1:]
    assert all(p.size is not None and p.size[0] == p.size[1] for p in slopes), "four squares"
    tilts = {round(math.degrees(math.acos(p.normal[1])), 3) for p in slopes}
    normals = {tuple(np.round(p.normal, 6)) for p in slopes}
    assert len(tilts) == 4 and len(normals) == 4, "each tilted differently"
    bounciness = {p.restitution for p in slopes}
    assert len(bounciness) == 4, "each as bouncy as no other, so their colours differ"
    assert all(p.position[1] - 0.5 * p.size[0] > 0 for p in slopes), "slopes are above the ground"
    heights = world.spheres.positions[:, 1]
    assert len(heights) == 5 and heights.argmax() == 4, "the fifth ball starts highest"


def test_slopes_every_slope_and_the_ground_is_hit(slopes_run):
    events, kinds = slopes_run.events, slopes_run.kinds
    plane_hits = events[kinds == "sphere-plane"]
    hit_by = {int(b): set(plane_hits[plane_hits[:, 2] == b, 1].astype(int)) for b in SLOPES | {GROUND}}
    assert all(hit_by[s] for s in SLOPES), hit_by
    assert hit_by[GROUND] == set(range(5)), "every ball ends up on the ground"
    first_plane = {a: int(plane_hits[plane_hits[:, 1] == a][0, 2]) for a in range(5)}
    assert {first_plane[a] for a in range(4)} == SLOPES, "balls 0-3 each land on their own slope first"


def _next_plane(plane_hits: np.ndarray, ball: int, t: float) -> int | None:
    later = plane_hits[(plane_hits[:, 1] == ball) & (plane_hits[:, 0] > t)]
    return int(later[0, 2]) if len(later) else None


def test_slopes_balls_collide_in_mid_air_then_drop_to_the_ground(slopes_run):
    run = slopes_run
    world, times, frames, events, kinds = run.world, run.times, run.frames, run.events, run.kinds
    plane_hits = events[kinds == "sphere-plane"]
    midair = []
    for t, a, b in events[kinds == "sphere-sphere"][:, :3]:
        a, b = int(a), int(b)
        k = min(np.searchsorted(times, t), len(times) - 1)
        centres = frames[k, [a, b], 2:5]
        clearance = min(float(np.min(p.distance(centres))) for p in world.planes) - RADIUS
        bounced = all(
            set(plane_hits[(plane_hits[:, 1] == ball) & (plane_hits[:, 0] < t), 2].astype(int)) & SLOPES
            for ball in (a, b)
        )
        if clearance > 0.5 and bounced:
            midair.append((round(t, 3), a, b, round(clearance, 2)))
            assert _next_plane(plane_hits, a, t) == GROUND and _next_plane(plane_hits, b, t) == GROUND, (
                t,
                a,
                b,
            )
    pairs = {(min(a, b), max(a, b)) for _, a, b, _ in midair}
    assert len(pairs) >= 2, f"mid-air collisions after slope bounces: {midair}"
    involved = {ball for pair in pairs for ball in pair}
    assert 4 not in involved, "the fifth ball flies free"


def test_slopes_fifth_ball_flies_far_with_the_highest_spin(slopes_run):
    times, frames, events, kinds = slopes_run.times, slopes_run.frames, slopes_run.events, slopes_run.kinds
    plane_hits = events[kinds == "sphere-plane"]
    mine = plane_hits[plane_hits[:, 1] == 4]
    (t_slope, _, slope, *_), (t_land, _, landed, *_) = mine[0], mine[mine[:, 2] != mine[0, 2]][0]
    assert int(slope) in SLOPES and int(landed) == GROUND
    touches = events[(kinds == "sphere-sphere") & ((events[:, 1] == 4) | (events[:, 2] == 4))]
    assert not (touches[:, 0] < t_land).any(), "nothing touches it in flight"
    i0, i1 = np.searchsorted(times, [t_slope, t_land])
    flight = np.linalg.norm(frames[i1, 4, [2, 4]] - frames[i0, 4, [2, 4]])
    assert flight > 8.0, f"it flies far: {flight:.2f} m"
    spin = np.linalg.norm(frames[:, :, 8:11], axis=2)
    in_flight = spin[i0 + 2 : i1 - 1, 4].min()
    assert in_flight > spin[:, :4].max(), "in flight it spins faster than any other ball ever does"
    assert spin[:, 4].max() == spin.max()


def test_slopes_everything_stays_on_screen(slopes_run):
    world, frames = slopes_run.world, slopes_run.frames
    look = read_scene(SCENES / "slopes.toml").appearance
    camera, look_at = look.camera_position, look.camera_look_at
    centres = frames[:, :, 2:5].reshape(-1, 3)
    tangents, depth = project(centres, camera, look_at)
    half_v = math.tan(math.radians(Camera().fov_y_degrees / 2))  # the viewer's vertical field of view
    half_h = half_v * 16 / 9
    assert (depth > 1.0).all()
    assert (np.abs(tangents[:, 0]) + RADIUS / depth < half_h).all()
    assert (np.abs(tangents[:, 1]) + RADIUS / depth < half_v).all()
    corners = []
    for plane in list(world.planes)[1:]:
        u, v = plane.axes
        w, d = plane.size
        corners += [plane.position + 0.5 * (su * w * u + sv * d * v) for su in (-1, 1) for sv in (-1, 1)]
    tangents, _ = project(np.array(corners), camera, look_at)
    assert (np.abs(tangents[:, 0]) < half_h).all() and (np.abs(tangents[:, 1]) < half_v).all()
