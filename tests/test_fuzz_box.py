"""Generated closed boxes: no ball ever leaves one, a restored snapshot repeats the run bit for bit, and a
scene saved mid-run loads back with the same balls.

Each example is a small closed box (six infinite walls) with one tilted square slope inside, which may
turn about its centre; balls of radius 3 mm to 16 cm and mass 0.01 to 2 kg anywhere inside it (they may
overlap each other and the slope), at up to 52 m/s; gravity with up to 24 m/s² sideways; any integrator
at 1/60, 1/120 or 1/240 s. Whatever the engine does inside a step, a ball's centre that ends a step
outside the box has passed through a wall.

The wider search (``Turned``, below) turns the box (six infinite walls, or six squares meeting at their
edges) and draws the scenes that broke the engine before: explicit Euler at 0.05–0.2 s a step, balls
pressed by gravity into an edge or a corner, 10–40 balls at up to 1,000 m/s, small balls starting
inside a big one beside a wall (overlaps up to a scene's ``overlap_tolerance`` of 6 cm), a sleeping
row or heap struck by a ball thrown at up to 1,000 m/s, and chains of balls 2–100 times heavier each
against a wall. After every step: no state is non-finite, no ball's centre is beyond a wall, and an
elastic frictionless box integrated exactly (RK2, RK4, or no gravity) gains no energy beyond rounding.

The suite runs a fixed, derandomised set of examples (6 for each property of the first box, 3 for each
of the wider search, BALLPIT_FUZZ_EXAMPLES) plus the failures longer searches found, kept as
``@example`` cases. A longer search, for instance:

    BALLPIT_FUZZ_EXAMPLES=3000 BALLPIT_FUZZ_RANDOM=1 python -m pytest tests/test_fuzz_box.py -x

(``BALLPIT_FUZZ_RANDOM=1`` draws new examples each run instead of the suite's fixed ones;
``BALLPIT_FUZZ_SPLIT=1`` splits every step at impacts, ``crowd_limit`` inf, to search that path alone;
``BALLPIT_FUZZ_LONG=1`` is the long search: 500 new examples a property unless BALLPIT_FUZZ_EXAMPLES
says otherwise, shrunk when they fail; give each run its own ``--hypothesis-seed``.)
"""

from __future__ import annotations

import math
import os
import tempfile
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
import pytest
import tomlkit
from hypothesis import HealthCheck, Phase, example, given, settings
from hypothesis import strategies as st

import ballpit
from ballpit.physics.dynamics.integrators import INTEGRATOR_NAMES
from ballpit.scene import read_scene

pytestmark = pytest.mark.slow  # a hypothesis search over whole runs: `make test`, not `make check`

LONG = os.environ.get("BALLPIT_FUZZ_LONG") == "1"  # the long search: many new examples, shrunk
EXAMPLES = int(os.environ.get("BALLPIT_FUZZ_EXAMPLES", "500" if LONG else "6"))
FIXED = os.environ.get("BALLPIT_FUZZ_RANDOM") != "1" and not LONG
SPLIT = os.environ.get("BALLPIT_FUZZ_SPLIT") == "1"  # every step split at impacts (crowd_limit inf)
FUZZ = settings(
    max_examples=EXAMPLES,
    deadline=None,
    derandomize=FIXED,
    # the suite reports a failure as drawn (shrinking one costs minutes); searches shrink them
    phases=(Phase.explicit, Phase.generate) if FIXED else tuple(Phase),
    database=None if FIXED else settings.default.database,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    print_blob=True,
)
# the wider search's properties run fewer fixed examples in the suite (each runs 20–40 steps of a scene)
WIDE = settings(FUZZ, max_examples=EXAMPLES if LONG or "BALLPIT_FUZZ_EXAMPLES" in os.environ else 3)
# the thousand-m/s property's second and third fixed examples take 10-25 s each (up to 40 balls, 0.1 s
# steps split at many impacts): the suite runs its first and the kept failures, the long search hundreds
ONE = settings(WIDE, max_examples=EXAMPLES if LONG or "BALLPIT_FUZZ_EXAMPLES" in os.environ else 1)
STEPS = 60  # the split-at-impacts escape this search first found came at step 37


@dataclass(frozen=True)
class Balls:
    """What every generated scene has: gravity, the integrator and its step, and the balls."""

    gravity: tuple[float, float, float]
    integrator: str
    dt: float
    positions: tuple[tuple[float, float, float], ...]
    velocities: tuple[tuple[float, float, float], ...]
    radii: tuple[float, ...]
    masses: tuple[float, ...]
    restitution: float


@dataclass(frozen=True)
class Box(Balls):
    """One generated scene: a cube of side 2·half centred on the origin, its slope and its balls."""

    half: float
    wall_restitution: float
    wall_friction: float
    slope_rotation: tuple[float, float, float]
    slope_size: float
    slope_spin: tuple[float, float, float]
    crowd_limit: float | None = None  # inf: every step split at impacts (None: the world's default)

    def world(self) -> ballpit.World:
        world = ballpit.World(gravity=self.gravity, integrator=self.integrator)
        if self.crowd_limit is not None:
            world.crowd_limit = self.crowd_limit
        h = self.half
        for axis in range(3):
            for sign in (-1.0, 1.0):
                normal = np.zeros(3)
                normal[axis] = -sign  # facing in
                position = np.zeros(3)
                position[axis] = sign * h
                world.add_plane(position=position, normal=normal, restitution=self.wall_restitution,
                                friction=self.wall_friction)  # fmt: skip
        world.add_plane(rotation=self.slope_rotation, size=self.slope_size, angular_velocity=self.slope_spin)
        if self.positions:
            world.add_spheres(
                np.array(self.positions), radius=np.array(self.radii), mass=np.array(self.masses),
                velocity=np.array(self.velocities), restitution=self.restitution,
            )  # fmt: skip
        return world

    def apart(self) -> Box:
        """This box without the balls that overlap the slope or a ball kept before them, as a scene
        file must be (it refuses overlaps)."""
        world, keep = self.world(), []
        x, r = np.array(self.positions), np.array(self.radii)
        clear = world.planes[6].distance(x) > 1.001 * r
        for i in np.flatnonzero(clear):
            if all(np.linalg.norm(x[i] - x[j]) > 1.001 * (r[i] + r[j]) for j in keep):
                keep.append(i)
        pick = lambda values: tuple(values[i] for i in keep)  # noqa: E731
        return replace(self, positions=pick(self.positions), velocities=pick(self.velocities),
                       radii=pick(self.radii), masses=pick(self.masses))  # fmt: skip

    def outside(self, world: ballpit.World) -> np.ndarray:
        """Indices of balls whose centre is not strictly inside the box (or is not finite)."""
        x = np.asarray(world.spheres.positions)
        return np.flatnonzero(~np.all(np.abs(x) < self.half, axis=1))


def _vector(limit: float) -> st.SearchStrategy[tuple[float, float, float]]:
    part = st.floats(-limit, limit, allow_nan=False, allow_infinity=False)
    return st.tuples(part, part, part)


@st.composite
def boxes(draw, integrators=("rk2", "rk4", "euler"), timesteps=(1 / 60, 1 / 120, 1 / 240),
          counts=(1, 20)) -> Box:  # fmt: skip
    half = draw(st.floats(0.3, 1.0))
    n = draw(st.integers(*counts))
    radius = st.floats(0.003, min(0.16, 0.4 * half))
    radii = tuple(draw(st.lists(radius, min_size=n, max_size=n)))
    positions = tuple(
        tuple(draw(st.floats(-(half - r), half - r)) for _ in range(3)) for r in radii
    )  # fmt: skip
    speed = draw(st.sampled_from([0.0, 3.0, 15.0, 52.0]))
    velocities = tuple(draw(_vector(speed)) for _ in range(n)) if speed else ((0.0, 0.0, 0.0),) * n
    # The slope's corners stay a ball's diameter from the walls however it turns: it cannot wedge a
    # ball against a wall (a kinematic plane would crush it through).
    slope = draw(st.floats(0.2, 1.0)) * (half - 2.0 * max(radii)) * math.sqrt(2.0)
    spin = draw(st.sampled_from([None, 1.0, 4.0]))
    return Box(
        half=half,
        wall_restitution=draw(st.sampled_from([0.0, 0.5, 0.8, 1.0])),
        wall_friction=draw(st.sampled_from([0.0, 0.5, 1.0])),
        slope_rotation=draw(_vector(80.0)),
        slope_size=max(slope, 0.01),
        slope_spin=draw(_vector(spin)) if spin else (0.0, 0.0, 0.0),
        gravity=(draw(st.floats(-24, 24)), -9.81, draw(st.floats(-24, 24))),
        integrator=draw(st.sampled_from(integrators)),
        dt=draw(st.sampled_from(timesteps)),
        positions=positions,
        velocities=velocities,
        radii=radii,
        masses=tuple(draw(st.lists(st.floats(0.01, 2.0), min_size=n, max_size=n))),
        restitution=draw(st.sampled_from([0.0, 0.5, 1.0])),
        crowd_limit=math.inf if SPLIT else None,
    )


# Failures found by longer searches (2026-12-02, RK2 at 1/60 s), kept as regression cases.
_Z = (0.0, 0.0, 0.0)
# 20 balls (3 mm to 13 cm) at the centre of a 72 cm box, all but one at one point and one of them
# thrown down at 12.6 m/s, over a small flat slope: in step 3, split at impacts, a 16 mm ball passes
# through the floor.
COINCIDENT_TWENTY = Box(
    half=0.36221806494511516, wall_restitution=0.0, wall_friction=0.0, slope_rotation=_Z,
    slope_size=0.07579839155788569, slope_spin=_Z, gravity=(0.0, -9.81, 0.0), integrator="rk2", dt=1 / 60,
    positions=(_Z, (-0.12921182900353728, 0.0, 0.0), *[_Z] * 18),
    velocities=(*[_Z] * 11, (0.0, -12.572179274993843, 0.0), *[_Z] * 8),
    radii=(0.09969348081123287, 0.0416666666666666, 0.05971324610186519, 0.12751147579894345,
           0.12733823994272045, 0.11343583427358678, 0.07694347406030605, 0.1224263524062222,
           0.11543191845808974, 0.05842847779869554, 0.020842070970734553, 0.016523666726343096,
           0.02555293970992056, 0.08648793644568675, 0.04651092020313627, 0.04902591488750961,
           0.01166431432535088, 0.003, 0.0765148326207335, 0.01625938684705956),
    masses=(1.5, 1.875, 1.625, 1.71875, 1.125, 1.5, 2.0, 1.0, 1.8671875, 1.53125, 0.5, 0.9375, 0.75, 1.0,
            0.96875, 0.46875, 0.25, 0.3046875, 0.390625, 0.3333333333333333),
    restitution=0.0,
)  # fmt: skip

# 17 balls (8 mm to 16 cm), 15 of them at the centre of an 81 cm box, one 8 mm ball among them thrown
# sideways at 52 m/s: in the first step, taken whole (crowded), the 8 mm ball leaves through a wall.
CROWDED_SEVENTEEN = Box(
    half=0.40261038753223904, wall_restitution=0.0, wall_friction=0.0, slope_rotation=_Z,
    slope_size=0.12891706606196074, slope_spin=_Z, gravity=(0.0, -9.81, 0.0), integrator="rk2", dt=1 / 60,
    positions=(*[_Z] * 9, (0.0, 0.0, 0.27919199995142824), *[_Z] * 4, (0.0, 0.3243346498637686, 0.0), _Z, _Z),
    velocities=(*[_Z] * 8, (52.0, 0.0, 0.0), (0.0, 0.0, -14.384744437198236), *[_Z] * 4, (0.0, -15.0, 0.0),
                _Z, _Z),
    radii=(0.15572612795457624, 0.1331577862085064, 0.10467323710196619, 0.09382568303811017,
           0.031468315032122496, 0.05243490285369637, 0.05053417718474767, 0.0211505995011891,
           0.00833333333332249, 0.1209658730494455, 0.06270845715369124, 0.03395084722614494,
           0.034255406076298865, 0.022907074746832054, 0.07827573766847043, 0.032599652411756,
           0.048029467743620706),
    masses=(1.0,) * 17,
    restitution=0.0,
)  # fmt: skip

# Three balls apart at the start, thrown at up to 52 m/s under sideways gravity of 23 m/s²: saved
# after 17 steps, two of them touch with 0.57 mm of overlap, and the saved file is refused for it.
SAVED_TOUCHING = Box(
    half=0.57, wall_restitution=0.5, wall_friction=1.0,
    slope_rotation=(12.998747517779051, -2.230908350974318e-255, 1.8177501570693746e-216),
    slope_size=0.27138913199148823, slope_spin=_Z, gravity=(-3.8788376737301675, -9.81, 23.0),
    integrator="rk2", dt=1 / 60,
    positions=((1.762442843784343e-271, 0.29865980011128, 0.04935513036814021),
               (-0.39792199070079837, -2.3462682983645785e-259, 0.25),
               (0.270698773319989, 0.23120760171663396, 0.08250815395842576)),
    velocities=((22.336535431460405, -7.521239548409618, 2.087572321298175e-09),
                (3.552103652150187, -24.681427925266334, 51.99999999999999),
                (-1.899844895076174e-227, 39.1926539865383, -30.466123834424483)),
    radii=(0.059759506488614826, 0.03141654850452379, 0.10131532553479922),
    masses=(0.4163255912496776, 0.95, 1.5),
    restitution=0.0,
)  # fmt: skip


# Found by a search with every step split at impacts (2026-12-04, RK2 at 1/60 s, BALLPIT_FUZZ_SPLIT=1;
# not shrunk): 17 balls at up to 52 m/s, some overlapping. In step 1 the push-apart moved a 12.5 cm ball
# from 13 cm off a wall to 1 mm off it (its centre did not cross it, so keep_sides_of_planes let it be);
# that wall was not among the interval's touching contacts, and the ball flew on into it at 22 m/s and
# out of the box (18 cm beyond the wall by the step's end).
SPLIT_SEVENTEEN = replace(
    Box(
        half=0.4256625025206699,
        wall_restitution=0.8,
        wall_friction=0.0,
        slope_rotation=(-11.144704915732873, 27.15857092172088, -3.538253180340348),
        slope_size=0.1349713295132408,
        slope_spin=(0.2589652542371612, 0.8327320826154136, 0.8142239541892184),
        gravity=(20.522320731250915, -9.81, 1.9207937727261362e-138),
        integrator="rk2",
        dt=0.016666666666666666,
        positions=(
            (-9.215204402139305e-206, -2.749795967626517e-301, -0.24561885561113875),
            (0.16201043664600778, -2.225073858507e-311, 0.0),
            (0.08088588645342237, 0.3362098246514944, 0.19017362849499553),
            (0.07758236033628657, -0.15521314553780108, -1.5572200076189704e-11),
            (0.0, -0.10408566495764865, -0.3326197330691812),
            (0.4226625025206699, 0.05, -2.943060195771112e-17),
            (-0.07720460336104507, -0.2749612001587566, -0.054829574075639986),
            (0.3816896264664386, 0.10505869131978862, 0.25044049002966623),
            (0.3438783216638098, -0.009202372691711258, -0.1723997316187861),
            (-9.689518610632891e-106, 0.16542826521363085, 0.10824008546768638),
            (-4.3801444920111184e-72, 0.2981684655893625, 0.3256625025206698),
            (0.00833333333332249, -0.3490335488818415, 0.27950292812816113),
            (0.2415068374912479, 0.029783511972377885, 2.797298367111268e-260),
            (-2.3432153928868945e-272, 0.32140516681906295, -0.2182524481884043),
            (0.16548988585914787, 0.008836895376752807, 0.24729090325239617),
            (0.29420349063648105, 1.4790443043908204e-74, 0.0702749395317287),
            (1.0875790582637673e-175, 0.13147942503207977, 1e-05),
        ),
        velocities=(
            (-38.715450484081636, 29.71929685958291, -1.4658993700610865e-08),
            (16.597468996509335, -37.819712662714835, -39.8673928738999),
            (51.0, -31.2799585803086, -20.283816487393157),
            (-2.762658798361699e-252, 29.596917063694306, -37.457133556841086),
            (-15.278518268721555, 35.62359556700456, -9.652037838216089),
            (-2.8916071035002204, 23.519735823987887, -40.08868939040845),
            (-51.64949087516482, -0.7664439715176172, 12.003858612525718),
            (49.46786696102271, 12.428207725712412, -51.45774533480988),
            (2.2616025008857303e-197, -3.9942337487406476, 44.95058932503747),
            (18.453276371344714, 6.642061165352765e-203, 27.01742900294856),
            (0.005, -33.3307954930307, 5.284233549806821e-209),
            (50.682440379990354, 27.706140764715713, -51.0),
            (40.10711300603438, 42.712127695528224, 41.34630793414094),
            (9.544339486672526e-86, 1.1527078278904214e-247, 2.225073858507203e-309),
            (0.93, 1.9, 26.708580088599405),
            (21.972703823207254, 0.02, 43.27186840281442),
            (-1.1925949603119319e-124, -32.00364356015198, 0.007339417222368638),
        ),
        radii=(
            0.02,
            0.13404559027025295,
            0.0764107793982299,
            0.1458687809983229,
            0.009592530078802858,
            0.003,
            0.014835775760785867,
            0.04397287605423128,
            0.039137557229648005,
            0.1543020493190412,
            0.1,
            0.05,
            0.15887437304042798,
            0.1042573357016069,
            0.01652064753459405,
            0.12548234062880226,
            0.010068259803838353,
        ),
        masses=(
            0.5310799841986182,
            0.3211084566678591,
            1.1,
            0.2,
            1.0102535360049412,
            0.5354781661702198,
            1.9,
            0.9932946573814562,
            1.8192814222887146,
            0.35582091892381995,
            1.9584431560644575,
            1.7340014619376138,
            1.396911561595661,
            0.1,
            0.01952695943457687,
            0.3947534111675473,
            1.5576436084106122,
        ),
        restitution=0.5,
    ),
    crowd_limit=math.inf,
)


@FUZZ
@example(SPLIT_SEVENTEEN)
@example(CROWDED_SEVENTEEN)
@example(COINCIDENT_TWENTY)
@given(boxes())
def test_no_ball_ever_leaves_a_closed_box(box):
    world = box.world()
    for k in range(STEPS):
        crowded = world.crowded_steps
        world.step(box.dt)
        out = box.outside(world)
        where = (
            f"step {k + 1}: balls {out.tolist()} (r = {np.asarray(world.spheres.radii)[out].tolist()}) "
            f"left the box at {np.asarray(world.spheres.positions)[out].tolist()}"
        )
        # two asserts, so that a search reports an escape from each strategy as a failure of its own
        if world.crowded_steps > crowded:
            assert out.size == 0, f"whole (crowded) {where}"
        else:
            assert out.size == 0, f"split at impacts, {where}"


@FUZZ
@given(boxes(), st.integers(0, STEPS // 2))
def test_a_restored_snapshot_repeats_the_run_bit_for_bit(box, at):
    world = box.world()
    for _ in range(at):
        world.step(box.dt)
    snap = world.snapshot()
    first = [_digest(world.step(box.dt), world) for _ in range(STEPS // 4)]
    world.restore(snap)
    again = [_digest(world.step(box.dt), world) for _ in range(STEPS // 4)]
    assert first == again


@FUZZ
@example(SAVED_TOUCHING, 17)
@given(boxes(), st.integers(0, STEPS // 2))
def test_a_scene_saved_mid_run_loads_back_with_the_same_balls(box, at):
    """Saved from a start a scene file could hold (no overlaps), at any later step (Ctrl+S)."""
    from ballpit.viewer.camera import Camera
    from ballpit.viewer.save import Scales, clean, scene_document
    from ballpit.viewer.simulation import Simulation

    box = box.apart()
    world = box.world()
    sim = Simulation(world)
    for _ in range(at):
        world.step(box.dt)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "box.toml"
        path.write_text(tomlkit.dumps(scene_document(sim, Camera())))
        back = read_scene(path).world
    # Ctrl+S writes round-off (below ROUND_OFF of its quantity's scale in the scene) as 0, the rest exactly
    scales = Scales.of(world, Camera())
    for column, scale in (
        ("positions", scales.length),
        ("velocities", scales.speed),
        ("angular_velocities", scales.spin),
        ("radii", scales.length),
        ("masses", 0.0),
    ):
        saved, now = getattr(back.spheres, column), getattr(world.spheres, column)
        assert np.array_equal(saved, clean(now, scale)), column


def _digest(contacts, world) -> bytes:
    parts = (contacts.time, contacts.a, contacts.b, contacts.point, contacts.impulse, world.state.body)
    return b"".join(np.ascontiguousarray(p).tobytes() for p in parts)


# ---------------------------------------------------------------------------------------------------
# The wider search: turned boxes of six walls (infinite, or squares meeting at their edges) and the
# scenes that broke the engine in 2026-12-04's attack. Each example says where its balls are in the
# box's own frame; the box is turned about its centre (the origin) by ``turn``.


@dataclass(frozen=True)
class Turned(Balls):
    """A closed cube of side 2·half, turned by ``turn`` (extrinsic x, y, z degrees), and its balls,
    placed in the cube's frame (gravity too). ``strike`` (radius, mass, position, velocity in the cube's
    frame) is a ball thrown once the others have fallen asleep (``sleep``)."""

    half: float
    turn: tuple[float, float, float]
    squares: bool
    wall_restitution: float
    wall_friction: float
    friction: float = 0.0
    substeps: int = 1
    sleep: bool = False
    strike: tuple[float, float, tuple[float, float, float], tuple[float, float, float]] | None = None
    steps: int = 40

    def rotation(self) -> np.ndarray:
        ax, ay, az = np.radians(self.turn)
        rx = np.array([[1, 0, 0], [0, math.cos(ax), -math.sin(ax)], [0, math.sin(ax), math.cos(ax)]])
        ry = np.array([[math.cos(ay), 0, math.sin(ay)], [0, 1, 0], [-math.sin(ay), 0, math.cos(ay)]])
        rz = np.array([[math.cos(az), -math.sin(az), 0], [math.sin(az), math.cos(az), 0], [0, 0, 1]])
        return rz @ ry @ rx

    def world(self) -> ballpit.World:
        turn = self.rotation()
        world = ballpit.World(
            gravity=turn @ np.array(self.gravity),
            integrator=self.integrator,
            sleep=self.sleep,
            substeps=self.substeps,
        )
        for axis in range(3):
            for sign in (-1.0, 1.0):
                face = np.eye(3)[axis] * sign  # the wall's outward direction in the cube's frame
                if self.squares:
                    # the +y square turned so that its normal faces in (−face), then with the cube
                    rotation = _euler_xyz(turn @ _facing(-face))
                    plane = world.add_plane(
                        position=turn @ (face * self.half),
                        rotation=rotation,
                        size=2.0 * self.half,
                        restitution=self.wall_restitution,
                        friction=self.wall_friction,
                    )
                    assert np.allclose(plane.normal, -(turn @ face), atol=1e-9)
                else:
                    world.add_plane(
                        position=turn @ (face * self.half),
                        normal=-(turn @ face),
                        restitution=self.wall_restitution,
                        friction=self.wall_friction,
                    )
        if self.positions:
            world.add_spheres(
                np.array(self.positions) @ turn.T,
                radius=np.array(self.radii),
                mass=np.array(self.masses),
                velocity=np.array(self.velocities) @ turn.T,
                restitution=self.restitution,
                friction=self.friction,
            )
        return world

    def throw(self, world: ballpit.World) -> None:
        """Add the striking ball (``strike``) to ``world``."""
        radius, mass, at, velocity = self.strike
        turn = self.rotation()
        world.add_sphere(
            position=turn @ np.array(at),
            radius=radius,
            mass=mass,
            velocity=turn @ np.array(velocity),
            restitution=self.restitution,
            friction=self.friction,
        )

    def beyond(self, world: ballpit.World) -> np.ndarray:
        """How far each ball's centre is beyond the nearest wall, in the cube's frame (m; ≤ 0 inside,
        NaN for a ball that is not finite)."""
        local = np.asarray(world.spheres.positions) @ self.rotation()
        return np.abs(local).max(axis=1) - self.half

    def elastic(self) -> bool:
        """Whether no energy may be lost or gained: elastic, frictionless, and integrated exactly under
        gravity (RK2 and RK4) or with no gravity at all."""
        exact_path = self.integrator in ("rk2", "rk4") or not any(self.gravity)
        smooth = self.wall_friction == 0.0 and self.friction == 0.0
        return exact_path and smooth and self.wall_restitution == 1.0 and self.restitution == 1.0


def _facing(normal: np.ndarray) -> np.ndarray:
    """A rotation taking +y to ``normal`` (one of ±x, ±y, ±z), by quarter and half turns."""
    x, y, z = normal
    if y:
        return np.diag([1.0, y, y])  # +y: identity; −y: a half turn about x
    if x:  # a quarter turn about z: +y -> ∓x
        return np.array([[0.0, x, 0.0], [-x, 0.0, 0.0], [0.0, 0.0, 1.0]])
    return np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -z], [0.0, z, 0.0]])  # about x: +y -> ±z


def _euler_xyz(m: np.ndarray) -> tuple[float, float, float]:
    """Extrinsic x, y, z angles (degrees) of the rotation matrix ``m`` = Rz·Ry·Rx."""
    sy = -m[2, 0]
    if abs(sy) < 1.0 - 1e-12:
        ay = math.asin(sy)
        ax = math.atan2(m[2, 1], m[2, 2])
        az = math.atan2(m[1, 0], m[0, 0])
    else:  # gimbal lock: fold z into x
        ay = math.copysign(math.pi / 2, sy)
        ax = math.atan2(-m[1, 2], m[1, 1])
        az = 0.0
    return tuple(math.degrees(a) for a in (ax, ay, az))


def _turn(draw) -> tuple[float, float, float]:
    return draw(st.sampled_from([(0.0, 0.0, 0.0), None])) or draw(_vector(45.0))


def _corner_gravity(draw, into: np.ndarray) -> tuple[float, float, float]:
    """Gravity pressing into the corner or edge ``into`` (a vector of 0 and ±1 in the cube's frame)."""
    g = np.array([draw(st.floats(2.0, 30.0)) for _ in range(3)]) * into
    return tuple(float(c) for c in g)


def _pressed(draw, half: float, into: np.ndarray, radii: list[float], heaps: bool) -> list:
    """Positions of balls pressed into the corner or edge ``into``: each touches the walls it points
    into, stacked along the edge or heaped against the corner (``heaps``: the next ball sits on the
    last one, along −gravity, a little apart)."""
    positions, last = [], None
    for r in radii:
        # touching the walls of ``into``, anywhere along the other axes
        p = np.array([draw(st.floats(-(half - r), half - r)) for _ in range(3)])
        p = np.where(into != 0, into * (half - r), p)
        if heaps and last is not None:
            lp, lr = last
            up = -into / np.linalg.norm(into)
            p = lp + up * (lr + r) * draw(st.sampled_from([1.0, 1.001, 1.1]))
            p = np.clip(p, -(half - r), half - r)
        positions.append(tuple(float(c) for c in p))
        last = (p, r)
    return positions


def _into(draw) -> np.ndarray:
    """A corner (three walls) or an edge (two) of the cube, as signs per axis."""
    signs = np.array([draw(st.sampled_from([-1.0, 1.0])) for _ in range(3)])
    if draw(st.booleans()):  # an edge: one axis free
        signs[draw(st.integers(0, 2))] = 0.0
    return signs


def _corner_box(draw, half: float, into: np.ndarray, integrators, timesteps, elastic: bool) -> dict:
    """A turned cube with gravity pressing into its corner or edge ``into``, one of ``integrators`` at
    one of ``timesteps``; walls and balls elastic and frictionless, or each drawn dead to half so."""
    dead = st.sampled_from([0.0, 0.5])
    return dict(
        half=half,
        turn=_turn(draw),
        squares=draw(st.booleans()),
        wall_restitution=1.0 if elastic else draw(dead),
        wall_friction=0.0 if elastic else draw(dead),
        gravity=_corner_gravity(draw, into),
        integrator=draw(st.sampled_from(integrators)),
        dt=draw(st.sampled_from(timesteps)),
        restitution=1.0 if elastic else draw(dead),
        friction=0.0 if elastic else draw(dead),
    )


@st.composite
def pressed_into_corners(
    draw, integrators=("euler", "rk2", "rk4", "symplectic"), timesteps=(1 / 60, 0.05, 0.1)
) -> Turned:
    """1–6 balls of 0.1 mm to 5 cm pressed by gravity into an edge or a corner of a turned box, some
    moving at up to 10 m/s, heavy or light, elastic and frictionless or not, at large steps."""
    half = draw(st.sampled_from([1.0, 0.3]))
    n = draw(st.integers(1, 6))
    radii = draw(st.lists(st.sampled_from([1e-4, 1e-3, 5e-3, 0.02, 0.05]), min_size=n, max_size=n))
    into = _into(draw)
    positions = _pressed(draw, half, into, radii, draw(st.booleans()))
    speed = draw(st.sampled_from([0.0, 1.0, 10.0]))
    elastic = draw(st.booleans())
    return Turned(
        **_corner_box(draw, half, into, integrators, timesteps, elastic),
        positions=tuple(positions),
        velocities=tuple(draw(_vector(speed)) for _ in range(n)) if speed else ((0.0, 0.0, 0.0),) * n,
        radii=tuple(radii),
        masses=tuple(draw(st.lists(st.sampled_from([0.001, 0.1, 1.0, 10.0]), min_size=n, max_size=n))),
    )


@st.composite
def fast_in_turned_squares(draw) -> Turned:
    """10–40 balls at up to 1,000 m/s in a turned box of six squares (or walls), RK2, RK4 or Euler at
    up to 0.1 s a step, elastic and frictionless."""
    half = 1.0
    n = draw(st.integers(10, 40))
    radii = draw(st.lists(st.floats(0.005, 0.08), min_size=n, max_size=n))
    positions = tuple(tuple(draw(st.floats(-(half - r), half - r)) for _ in range(3)) for r in radii)
    speed = draw(st.sampled_from([100.0, 1000.0]))
    return Turned(
        half=half,
        turn=_turn(draw),
        squares=draw(st.booleans()),
        wall_restitution=1.0,
        wall_friction=0.0,
        gravity=(0.0, -9.81, 0.0),
        integrator=draw(st.sampled_from(["rk2", "rk4", "euler"])),
        dt=draw(st.sampled_from([1 / 60, 0.05, 0.1])),
        positions=positions,
        velocities=tuple(draw(_vector(speed)) for _ in range(n)),
        radii=tuple(radii),
        masses=tuple(draw(st.lists(st.floats(0.01, 2.0), min_size=n, max_size=n))),
        restitution=1.0,
        steps=20,
    )


def _floor_box(draw, elastic: bool) -> dict:
    """A turned 2 m cube under plain gravity, any integrator at 1/240 or 1/60 s, its walls and balls
    elastic and frictionless or half so."""
    return dict(
        half=1.0,
        turn=_turn(draw),
        squares=draw(st.booleans()),
        wall_restitution=1.0 if elastic else 0.5,
        wall_friction=0.0 if elastic else 0.5,
        gravity=(0.0, -9.81, 0.0),
        integrator=draw(st.sampled_from(INTEGRATOR_NAMES)),
        dt=draw(st.sampled_from([1 / 240, 1 / 60])),
        restitution=1.0 if elastic else 0.5,
        friction=0.0 if elastic else 0.5,
    )


@st.composite
def overlapping_starts(draw) -> Turned:
    """A big ball (up to 100 kg) touching or near a wall of a turned box, and 1–4 small balls starting
    inside its shell, overlapping it by up to 6 cm (a scene's ``overlap_tolerance``), moving at up to
    20 m/s; any integrator."""
    half = 1.0
    big = draw(st.floats(0.1, 0.4))
    into = _into(draw)
    centre = np.where(into != 0, into * (half - big - draw(st.sampled_from([0.0, 0.0, 0.01]))), 0.0)
    radii, positions = [big], [tuple(float(c) for c in centre)]
    for _ in range(draw(st.integers(1, 4))):
        r = draw(st.sampled_from([5e-4, 1e-3, 5e-3]))
        direction = np.array(draw(_vector(1.0)))
        length = float(np.linalg.norm(direction))
        direction = direction / length if length > 1e-3 else into / np.linalg.norm(into)
        overlap = draw(st.floats(1e-4, 0.06))
        p = centre + direction * (big + r - overlap)
        p = np.clip(p, -(half - r), half - r)
        radii.append(r)
        positions.append(tuple(float(c) for c in p))
    n = len(radii)
    speed = draw(st.sampled_from([0.0, 1.0, 10.0, 20.0]))
    elastic = draw(st.booleans())
    return Turned(
        **_floor_box(draw, elastic),
        positions=tuple(positions),
        velocities=((0.0, 0.0, 0.0),) + tuple(draw(_vector(speed)) for _ in range(n - 1)),
        radii=tuple(radii),
        masses=(draw(st.sampled_from([1.0, 100.0])),) + (0.01,) * (n - 1),
    )


@st.composite
def struck_sleepers(draw) -> Turned:
    """A row or heap of 2–8 balls asleep on the floor of a turned box, struck by a ball thrown at 2 to
    1,000 m/s from across the box once they sleep, so that it arrives inside a step."""
    half = 1.0
    n = draw(st.integers(2, 8))
    r = draw(st.sampled_from([0.02, 0.05, 0.1]))
    heap = draw(st.booleans())
    positions = []
    for i in range(n):
        if heap and i >= 3:  # on top of the first three
            positions.append((0.0, -half + r + (i - 2) * 2.0 * r * 1.2, 0.0))
        else:
            positions.append(((i - n / 2) * 2.0 * r * draw(st.sampled_from([1.0, 1.01])), -half + r, 0.0))
    target = np.array(positions[draw(st.integers(0, n - 1))])
    start = np.array(
        [draw(st.sampled_from([-0.8, 0.8])), draw(st.floats(-0.8, 0.8)), draw(st.floats(-0.8, 0.8))]
    )
    speed = draw(st.sampled_from([2.0, 20.0, 200.0, 1000.0]))
    aim = target - start
    elastic = draw(st.booleans())
    return Turned(
        **_floor_box(draw, elastic),
        positions=tuple(positions),
        velocities=((0.0, 0.0, 0.0),) * n,
        radii=(r,) * n,
        masses=tuple(draw(st.lists(st.sampled_from([0.1, 1.0, 10.0]), min_size=n, max_size=n))),
        sleep=True,
        strike=(
            draw(st.sampled_from([r, r / 4])),
            draw(st.sampled_from([0.1, 1.0, 10.0])),
            tuple(float(c) for c in start),
            tuple(float(c) for c in aim / np.linalg.norm(aim) * speed),
        ),
    )


@st.composite
def mass_chains(draw) -> Turned:
    """A chain of 2–5 balls against a wall, an edge or a corner of a turned box, along gravity, each
    ball 2 to 100 times heavier than the one below it (or lighter), the top one maybe thrown in."""
    half = 1.0
    n = draw(st.integers(2, 5))
    radii = draw(st.lists(st.sampled_from([0.001, 0.005, 0.01, 0.05]), min_size=n, max_size=n))
    into = _into(draw)
    if draw(st.booleans()):  # a single wall
        keep = draw(st.sampled_from(np.flatnonzero(into).tolist()))  # one of the walls it pressed
        into = np.where(np.arange(3) == keep, into, 0.0)
    positions = _pressed(draw, half, into, radii, heaps=True)
    ratio = draw(st.sampled_from([2.0, 7.0, 47.0, 100.0, 0.1]))
    masses = tuple(float(0.01 * ratio**i) for i in range(n))
    top = draw(st.sampled_from([0.0, 1.0, 10.0]))
    velocities = [(0.0, 0.0, 0.0)] * (n - 1) + [tuple(float(c) for c in into / np.linalg.norm(into) * top)]
    elastic = draw(st.booleans())
    timesteps = (1 / 240, 1 / 60, 0.05)
    return Turned(
        **_corner_box(draw, half, into, INTEGRATOR_NAMES, timesteps, elastic),
        positions=tuple(positions),
        velocities=tuple(velocities),
        radii=tuple(radii),
        masses=masses,
    )


def _energy(world: ballpit.World) -> float:
    return world.kinetic_energy() + world.potential_energy()


def _energy_scale(world: ballpit.World, half: float) -> float:
    """What rounding in the total energy is measured against: the kinetic energy plus what gravity
    could give or take across the box."""
    g = float(np.linalg.norm(world.gravity))
    return world.kinetic_energy() + float(np.sum(world.spheres.masses)) * g * 2.0 * half + 1e-300


# Found by the long search of the wider strategies (2026-12-06, seed 301, shrunk): 33 balls of 6.25 cm
# (10 g to 1 kg) at rest, all at the centre of an elastic frictionless 2 m box but one a radius beside
# them, RK2 at 1/60 s: in step 7, split at impacts and integrated in one interval under the resting
# solve's constant forces, the energy rose by 3.07 J (of 348 J): the solve, not converged at a hundred
# to one, left pushing contacts separating, and its forces did work (now scaled down until they do
# none, energy_guard.keep_interval).
_MIXED = (0.01, 0.01, 0.01, 0.01, 0.015625, 0.03125, 0.01, *[1.0] * 17, *[0.0625] * 8, 0.125)
COINCIDENT_MIXED_MASSES = Turned(
    gravity=(0.0, -9.81, 0.0),
    integrator="rk2",
    dt=1 / 60,
    positions=((0.0625, 0.0, 0.0), *[_Z] * (len(_MIXED) - 1)),
    velocities=(_Z,) * len(_MIXED),
    radii=(0.0625,) * len(_MIXED),
    masses=_MIXED,
    restitution=1.0,
    half=1.0,
    turn=_Z,
    squares=False,
    wall_restitution=1.0,
    wall_friction=0.0,
    steps=20,
)

# The same search (seed 302, shrunk): 40 balls of 6.25 cm and 1 kg at rest at the centre of the same
# box, RK2 at 1/60 s: in step 14, taken whole (crowded), the energy rose by 28.6 J (of 785 J), past
# the frame guard's last resort then (the motion relative to the centre of mass stopped, the rising
# balls taken back); its last resorts now hold the energy by construction (energy_guard.hold_frame).
COINCIDENT_FORTY = replace(
    COINCIDENT_MIXED_MASSES,
    positions=(_Z,) * 40,
    velocities=(_Z,) * 40,
    radii=(0.0625,) * 40,
    masses=(1.0,) * 40,
)

# The long search over main (seed 410, 2026-12-06, shrunk): a 5 mm, 0.1 kg ball in a corner of the box
# and a 0.1 mm, 1 g one just above it along gravity (−2, −3, −2), RK2 at 0.1 s: in step 3, split at
# impacts, the energy rose by 5.9e-5 J (of 0.83 J): the resting solve, not converged at a hundred to
# one, pushed the light ball out of the wedge between the heavy one and a wall, and its forces did
# more work than the light ball's speed could pay back (now the interval is taken back part way,
# energy_guard.keep_interval).
CORNER_HUNDRED_TO_ONE = replace(
    COINCIDENT_MIXED_MASSES,
    gravity=(-2.0, -3.0, -2.0),
    dt=0.1,
    positions=((-0.995, -0.995, -0.995), (-0.992055513627133, -0.992055513627133, -0.992055513627133)),
    velocities=(_Z, _Z),
    radii=(0.005, 0.0001),
    masses=(0.1, 0.001),
    steps=40,
)


def check_turned_box(box: Turned) -> None:
    """Run ``box``: after every step no state is non-finite, no ball's centre is beyond a wall, and an
    elastic frictionless box (integrated exactly) gains no energy beyond rounding."""
    world = box.world()
    steps = box.steps
    if box.strike is not None:  # let the others fall asleep (at most 2 s), then throw the striker
        for _ in range(int(2.0 / box.dt)):
            world.step(box.dt)
            if world.asleep.all():
                break
        box.throw(world)
    start, scale = _energy(world), _energy_scale(world, box.half)
    tolerance = 1e-9 * box.half  # rounding in the turned frame's coordinates
    for k in range(steps):
        crowded = world.crowded_steps
        world.step(box.dt)
        how = "whole (crowded)" if world.crowded_steps > crowded else "split at impacts"
        body = world.state.body
        assert np.isfinite(body).all(), f"step {k + 1}, {how}: a ball's state is not finite"
        beyond = box.beyond(world)
        out = np.flatnonzero(~(beyond <= tolerance))
        assert out.size == 0, (
            f"step {k + 1}, {how}: balls {out.tolist()} (r = {world.spheres.radii[out].tolist()}) are "
            f"{beyond[out].tolist()} m beyond a wall"
        )
        if box.elastic():
            gain = _energy(world) - start
            assert gain <= 1e-9 * scale, f"step {k + 1}, {how}: energy rose by {gain} J (of {scale} J)"


@WIDE
@given(pressed_into_corners(integrators=("euler",), timesteps=(0.05, 0.1, 0.2)))
def test_no_ball_leaves_a_turned_box_under_explicit_euler_at_large_steps(box):
    check_turned_box(box)


@WIDE
@example(CORNER_HUNDRED_TO_ONE)
@given(pressed_into_corners())
def test_no_ball_pressed_into_an_edge_or_corner_leaves_a_turned_box(box):
    check_turned_box(box)


@ONE
@example(COINCIDENT_MIXED_MASSES)
@example(COINCIDENT_FORTY)
@given(fast_in_turned_squares())
def test_no_ball_at_a_thousand_metres_a_second_leaves_a_turned_box_of_squares(box):
    check_turned_box(box)


@WIDE
@given(overlapping_starts())
def test_no_small_ball_starting_inside_a_big_one_is_pushed_out_of_the_box(box):
    check_turned_box(box)


@WIDE
@given(struck_sleepers())
def test_no_ball_leaves_the_box_when_a_sleeping_pile_is_struck(box):
    check_turned_box(box)


@WIDE
@given(mass_chains())
def test_no_ball_of_a_mass_chain_against_a_wall_leaves_the_box(box):
    check_turned_box(box)
