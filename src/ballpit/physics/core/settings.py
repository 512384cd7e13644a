"""The physics' tuning constants, in one place: each with its unit and why it has its value.

The modules of the step import them from here (``from .settings import CONTACT_SLOP``), so this is the
one file to read or change. What a user may set per world (``world.solver_iterations``,
``world.crowd_limit``, a scene's timestep) only takes its default from here. The defaults of a ball's
and a plane's own properties (``BALL_RADIUS``, ``FRICTION``, ...) stay in ``model.py``, beside the
signatures the scene schema reads them from; the bounds on valid input stay in ``validation.py``.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

# --- The step -------------------------------------------------------------------------------------

# The step a scene, the viewer and the command line take unless told otherwise (s): 240 Hz.
DEFAULT_TIMESTEP = 1.0 / 240.0
# A step is split at most this many times (intervals); past it the rest of the step is finished
# conservatively: the balls that could meet anything stop where they are
# (``step.split.finish_conservatively``). A pathological pile-up, not a textbook scene, gets there.
MAX_INTERVALS = 1_000

# A plane turns only at this rate or faster (rad/s, about 1.5e-154: the rate whose square is the
# smallest normal double; ``Model.plane_spin``). Slower, the rate √(ω·ω) is formed from squares that
# underflow (at 2.6e-195 rad/s it is 0 while ω is not, and ω / rate was NaN), and the plane would take
# 1e140 years to turn a millionth of a radian: every stage of the step takes it as still.
SLOWEST_TURN = math.sqrt(sys.float_info.min)

# --- Contact ----------------------------------------------------------------------------------------

# Balls closer than this (m) are in contact: the solver holds them, time of impact stops here …
CONTACT_SLOP = 1e-5
# … or closer than this fraction of the smallest ball's radius, if that is less: a fixed 10 µm let a
# 100 nm ball touch every wall of a 20 µm box at once, and leave it. One definition of touching for
# every stage of the step: ``Model.contact_slop``.
SLOP_PER_RADIUS = 1e-3

# The overlap (m) a world may start with: a scene's balls may press this far into each other or a plane
# (the default of its ``[world] overlap_tolerance``, README; scene/schema.py reads it from here). A
# micrometre: nothing shows, and the step moves it apart as it does any overlap deeper than
# PENETRATION_TOLERANCE.
OVERLAP_TOLERANCE = 1e-6

# --- Zero, for lengths, speeds and directions -------------------------------------------------------

# Lengths (m) and speeds (m/s) at or below this are zero where a direction or a ratio is formed from
# them: two ball centres this close are coincident (their contact normal is taken as +y), a ball's
# centre this close to a plane's face (relative to its distance, beyond a metre) is on the face (the
# normal is the plane's), a ball slower than this keeps its pairs the longest (no division by its
# speed), and an argument shorter than this is a zero vector. A thousandth of a nanometre: rounding,
# at the sizes a world holds (a radius is at least 1e-9 m).
TINY = 1e-12
# A unit normal whose dot product with +y is within this of −1 is −y: the shortest turn from +y is
# then not defined, and the plane is turned 180° about x (dimensionless).
ANTIPARALLEL = 1e-12
# Gram–Schmidt over the planes holding a ball (resting.hold_by_planes): a normal whose part off the
# directions already found is shorter than this (a unit vector's, dimensionless) adds none.
NEW_DIRECTION = 1e-6
# Added to a squared length (or an inverse inertia sum) before it divides: no 0/0 where it is zero.
# Far below any impulse², inertia⁻¹ or length² a step forms, and far above the smallest double.
NO_ZERO_DIVIDE = 1e-300
# A ball's orientation may have any length a step can normalise (every step does): not one whose squared
# length (dimensionless) underflows to nothing (a zero quaternion) or overflows (steppable.py).
SHORTEST_TURN2 = 1e-24

# --- Broad phase (pairs.py, broadphase.py) ------------------------------------------------------------

# Broad-phase boxes cover this many steps of each ball's path, so most steps reuse the pairs.
BROAD_PHASE_STEPS = 4
# … or as far as a ball travels this fraction of its radius, if that is sooner (but never less than
# the step itself) …
BROAD_PHASE_REACH = 0.2
# … and are grown by this fraction of the ball's radius, so slow balls keep their pairs for longer.
BROAD_PHASE_MARGIN = 0.1
# The cells are looked up in a table when there are at most this many per ball (a pile), else by
# searching the sorted cell keys (balls spread far apart).
DENSE_CELLS_PER_BALL = 16
# Up to this many boxes, testing every pair at once costs fewer array operations than the grid.
ALL_PAIRS_UP_TO = 48
# Sphere–plane pairs are tested for this many (ball, plane) pairs at a time, planes taken together: a
# handful of balls and planes in one pass, a crowd one plane at a time.
PLANE_PAIRS_AT_ONCE = 4096
# The grid's cell is this many times the median box's largest side (or the largest box, if smaller):
# the smallest cell that still holds most boxes whole keeps the fewest boxes per cell to test (in a
# packed pile a cell of twice the median box holds ~8× fewer than one as large as the largest box).
CELL_PER_MEDIAN_BOX = 2.0
# Balls the escape test takes at a time: its scratch stays in the cache, and it stops at the first escape.
ESCAPE_CHUNK = 8192

# --- Crowded steps (step/plan.py, step/soft.py) --------------------------------------------------

# Default of ``World.crowd_limit``: a step in which more than this many pairs not yet touching may meet
# is crowded (taken as a soft-step frame, softstep.py).
CROWD_LIMIT = 32
# Splitting a step costs a pass over every contact per impact: with this many kept pairs or more, any
# meeting (or touching contact) makes the step crowded (a pile, not a textbook scene).
CROWD_PAIRS = 256
# A contact overlapping by more than this fraction of its ball's radius makes the step crowded: the
# soft step pushes such balls apart with its planes holding, instead of jumping them apart by positions.
CROWD_OVERLAP = 0.02
# The pairs of a crowded step are those within this many times the distance they could close.
SPECULATIVE_REACH = 2.0
# A crowded step is taken as soft substeps only while no ball it moves travels more than this fraction
# of its radius in one substep (before, by its speed and acceleration; after, as it moved): beyond it a
# substep could carry a ball past a contact it never measured.
SUBSTEP_TRAVEL = 1.0
# A frame the soft step cannot hold is tried again with twice the substeps, at most this many times,
# before the step is split at impacts.
RETRIES = 2
# ... and while no pair overlaps by more than this fraction of the smaller radius (25 %: well short of
# passing through, and deep enough that a landing pile's transient overlaps do not undo frames).
DEEP_OVERLAP = 0.25

# --- The soft step of a crowded step (softstep.py) -------------------------------------------------

# Contact stiffness (Hz) and damping ratio of an overlap's soft spring, and the fastest it pushes
# overlapping balls apart (m/s): Box2D v3's defaults.
CONTACT_HERTZ = 60.0
DAMPING_RATIO = 10.0
MAX_PUSH = 3.0
# The stiffness is capped at this fraction of the substep rate (Hz per Hz, 1/h): a spring much stiffer
# than its substeps can follow overshoots within one (Box2D v3's cap, a quarter) …
SOFT_RATE_CAP = 0.25
# … and contacts with a plane take this many times the stiffness of those between balls (Box2D's
# static softness: a plane does not give way, so its contacts may be stiffer).
PLANE_STIFFNESS = 2.0
# A contact takes a share of its balls' mass in a substep's solve when it is pressed already or would
# close its gap within this many substeps at its normal speed (a speculative contact still far from
# closing takes none, so it does not soften the ones that carry the load).
PUSH_AHEAD = 2.0
# Overlaps up to this fraction of the smaller radius are left to the soft spring (which holds a
# resting pile with some give); only deeper ones are moved apart by positions after the substeps.
# A soft contact rests at the overlap its load F needs, s_eq = F·(1/m_a + 1/m_b)/ω² (ω = 2π·60 Hz:
# about 5 % of a radius at the bottom of a 200-ball pile seven balls deep). Moved apart to less, the
# spring would push less than the load, sink back and be moved apart again, every frame: a pile that
# never stands still. So the spring remembers how far it was moved apart (``WarmStart.apart``, up to
# s_eq) and keeps pushing as if that overlap were still there: it holds the load at the slop.
SLOP = 0.01
# Overlaps deeper than the slop are moved back to this fraction of it, not to it, so they are not
# caught again next frame (separate.py) …
SLOP_RETURN = 0.8
# An interval under the resting solve's forces whose energy rose by less than this fraction of its
# kinetic energy and the potential energy it exchanged gained it by rounding alone (1e-16 of them on
# the bundled incline), and is left as it is (energy_guard.keep_interval).
INTERVAL_ROUNDING = 1e-12
# A soft frame that gained energy gives it back first by taking the balls that rose back along their
# moves, each by at most this fraction of its radius (half the slop), keeping its velocity: a settled
# pile's springs lift it by micrometres a frame, and stopping its motion for that instead hid the
# motion the positions still made (energy_guard.hold_frame).
GUARD_TAKE_BACK = 0.5 * SLOP
# … and only the contacts a move of up to this many times the deepest deficit could reach take part:
# the others, farther apart than that, cannot be closed by moving these apart.
SEPARATE_REACH = 2.0
# Jacobi sweeps per substep: with the bias, then without it (relax). Friction and rolling resistance
# are updated in the last sweep of each; the others update the normal impulses alone. Relaxing with
# 4 instead of 2 (three normal-only sweeps, cheap) took pile.toml's worst overlap while landing at
# 1/60 s x 4 from 15 % of a radius to 8 %: the relax is what stops the arrivals within a substep.
SOLVE_SWEEPS = 4
RELAX_SWEEPS = 4
# Jacobi sweeps that move apart, by positions, the overlaps deeper than SLOP the substeps left.
SEPARATE_SWEEPS = 16
# Jacobi sweeps of a large wave (JACOBI_FROM contacts or more) in the restitution pass (impacts.normal_solve;
# normal impulses only).
RESTITUTION_SWEEPS = 4
# Jacobi sweeps of each wave of the soft step's impacts (impacts.waves_from): a wave whose contacts share
# no ball is exact after one; a contact a wave leaves still closing arrives again in the next. With 4,
# pile.toml's landing took 800 waves and 3,074 sweeps; with 2, 945 and 2,110 (cheaper: a wave costs
# about what a sweep does).
WAVE_SWEEPS = 2
# A soft-step contact whose normal is within this cosine of square to gravity (about 3°) holds up no
# weight: when the frame's impacts changed it, the next frame's warm start keeps no more than it came
# with (softstep.py), so a struck touching chain's compression is not pushed again (with the last
# substep's impulse, the balls the waves left still moved on at up to 4 % of the striker's speed at
# 1/60 s; now below 1 %). Capping every contact the impacts changed (at its old warm start plus twice
# its share of the weight) left pile.toml's landing overlapping 0.33 r; with 0.05 it lands at 0.094 r
# (0.081 r before the waves, 0.113 r with no cap at all; test_robustness allows 0.1 r).
LEVEL = 0.05

# --- Time of impact (toi.py) ------------------------------------------------------------------------

# Impacts whose times are this close (as an overlap, in radii) are resolved together: a pile of 1,000
# balls landing then takes ~4 intervals per step instead of ~19. A lone impact is still met exactly.
IMPACT_OVERLAP = 0.005
# Conservative advancement steps by gap / (closing-speed bound), and the bound counts the speed along
# the surface: a ball hopping a tenth of a millimetre while it rolls at 3 m/s took 48 steps and more to
# land. A pair still advancing after this many steps leaps to the earliest time its gap along the
# normal could close (``toi.earliest``); the pairs that land within them are found exactly as before.
LEAP_AFTER = 8
# Conservative advancement steps per call: a pair still converging after them reports the time it
# reached, a safe lower bound, and the step integrates to it and asks again.
MAX_ADVANCE_STEPS = 48

# --- Penetration (penetration.py) -------------------------------------------------------------------

# Overlaps shallower than this (m) are left alone by the step: rounding, not penetration …
PENETRATION_TOLERANCE = 1e-7
# … or than this fraction of the smallest ball's radius, if that is less (a 100 nm ball could otherwise
# sink its whole radius into a wall).
OVERLAP_PER_RADIUS = 1e-5
# Gauss–Seidel sweeps over the overlapping contacts (twice as many Jacobi sweeps, which move a split
# ball only its share).
PENETRATION_SWEEPS = 4

# --- Impacts (impacts.py) ---------------------------------------------------------------------------

# The most waves one impact sets off; what still arrives after them is stopped (e = 0). A touching
# line needs one wave per ball.
MAX_WAVES = 64
# A wave is solved until no contact's speed changes by more than CONVERGED in a sweep, or this many
# sweeps (at least the world's solver_iterations): a ball struck from two sides needs about 15.
WAVE_ITERATIONS = 50
# The stop (and the crowded step's bounce) is solved over the contacts within this many balls of a
# closing one.
BOUNCE_HOPS = 3
# A bounce is solved afresh (no warm start, nothing to hold at rest): Jacobi sweeps per iteration.
BOUNCE_JACOBI_SWEEPS = 1
# Normal speeds (m/s) within this of a contact's minimum normal speed count as not approaching
# (rounding, not an impact).
APPROACH_SPEED = 1e-6

# --- Contact solves (solver.py, jacobi.py, resting.py; the contact model is contact_model.py) ---------

# Up to this many contacts, the colouring first checks whether any ball has two of them (one colour
# then, as the first round of Luby's method would find, at a fraction of its cost).
ONE_COLOUR_CHECK_UP_TO = 64

# Default of ``World.solver_iterations``: projected Gauss–Seidel sweeps per solve.
SOLVER_ITERATIONS = 10
# A sweep that changes no contact velocity by more than this (m/s) ends the iterations early.
CONVERGED = 1e-9
# From this many contacts on, a solve updates all of them at once (``jacobi.py``): per sweep it costs a
# fixed number of NumPy calls instead of a few dozen per colour.
JACOBI_FROM = 64
# A Jacobi sweep with mass splitting moves each contact only part of the way a Gauss–Seidel update
# would; it takes this many Jacobi sweeps for each Gauss–Seidel iteration asked for (with one, a pile
# of 200 balls kept jittering at 5 mm/s; with two it comes to rest below 1e-8 m/s).
JACOBI_SWEEPS = 2
# Friction and rolling resistance are updated in every fourth Jacobi sweep (and the last); the sweeps
# between update the normal impulses alone, at about a fifth of the cost. Friction converges more
# slowly than the normal impulses need it to, but its warm start carries it from step to step: the
# 200-ball settling pile came to rest at 3e-10 m/s this way (2e-9 with friction in every sweep); with
# friction in every tenth sweep of a bounce it kept creeping at 6 mm/s.
JACOBI_FRICTION_EVERY = 4
# A Jacobi solve numbers the balls its contacts touch by sorting the contact ends when the world has
# more than this many balls per end (few contacts in a big world), else from a table over the world.
SORT_ENDS_FROM = 8
# A Jacobi solve adds up the rows of per-end values with one np.bincount over bins r·M + ball while
# there are at most this many entries (rows × 2K): the bins are kept, 8 bytes an entry (1 MiB here).
# Beyond it, one np.bincount a row, as fast at that size, and the bins are not kept: at 100,000 balls
# they were 6 rows × 2 ends × 8 bytes a contact, about 290 bytes a ball in a settled pile.
ADD_UP_BINS_UP_TO = 1 << 17
# A full Jacobi sweep forms its per-contact temporaries (the gathered spins and velocities, the slip,
# the friction candidates) this many contacts at a time: every value is one contact's own, so the
# impulses are the same, and a settled pile of 100,000 balls holds a few chunks' worth of them, not
# about 290 bytes a ball.
SWEEP_CHUNK = 1 << 14
# Resting forces found over less than this fraction of a step do not warm-start the next solve.
WARM_START_SPAN = 0.5
# Planes win (resting.hold_by_planes): when the resting solve leaves a ball sinking into a plane (or a
# sleeping ball) it touches by more than this fraction of its radius over one interval, the ball is held
# by that plane. Gauss–Seidel moves momentum through a light ball between a heavy ball and a wall at
# about m_light/m_heavy per sweep: at a mass ratio of 47 ten sweeps left a 9.8 mm ball sinking 2.7 mm an
# interval, and the heavy ball carried it through the wall. A converged solve sinks ~1e-9 radii.
HOLD_SINK = 0.01
# Sweeps over a held ball's plane contacts after the hold: exact after one against square walls.
HOLD_PASSES = 3
# The hold reaches this many layers of balls out from a held ball's planes (a chain pressing it).
HOLD_LAYERS = 8
# A contact between two balls both held along its normal gives way to no impulse: its ends' inverse
# masses along the normal, |P·n|²/m (rounding leaves 1e-17 of them, not 0), are below this fraction of
# their whole 1/m (dimensionless).
HELD_ALONG = 1e-9

# --- Sleeping (sleeping.py) -------------------------------------------------------------------------

# A ball is still below this speed, and below this surface speed from spin |ω|·r (m/s; Box2D's default).
SLEEP_SPEED = 0.05
# An island falls asleep when all its balls have been still this long (s; Box2D's default).
TIME_TO_SLEEP = 0.5

# --- Integration (integrators.py) -------------------------------------------------------------------

# Balls RK4's fast path takes at a time: its scratch columns then stay in the cache.
RK4_CHUNK = 8192

# --- The energy guards (energy_guard.py) ----------------------------------------------------------


@dataclass(frozen=True)
class EnergyGuards:
    """Which energy guards are on (energy_guard.py: its rule, and what each keeps): all of them, unless
    a test switches one off to show what it prevents (``Model.guards``)."""

    impulses: bool = True
    lift: bool = True
    frame: bool = True
    push: bool = True
