"""Contact rows: what the solver needs of each touching (or speculative) contact, built once per
interval: both bodies' inverse masses and inertias, the lever arms, the mixed materials, and the
colours that let contacts sharing no ball be solved together.

Material mixing (README, "Contact model"): restitution e = e_a·e_b, friction μ = sqrt(μ_a·μ_b),
rolling friction ρ = sqrt(ρ_a·ρ_b). Balls are rows 0…N−1; row N is the static world (planes), with
zero inverse mass (docs/architecture.md, "Conventions").
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..core import exact
from ..core.contacts import SPHERE_PLANE, ContactPoints, take_indices
from ..core.settings import ONE_COLOUR_CHECK_UP_TO
from ..core.state import State, shallow_copy
from ..dynamics import moving_planes
from ..dynamics.model import Model
from . import contact_model
from .contact_model import Impulses

_ZERO = np.zeros(1)


@dataclass
class ContactRows:
    """Per-contact arrays the solver needs; built once per interval from the contact points."""

    a: np.ndarray  # first ball
    b: np.ndarray  # second ball, or the static row N for a plane
    normal: np.ndarray  # (K, 3), towards a
    # the lever arms (centre → contact point) are r_a = −radius_a·n and r_b = radius_b·n (``arm_lengths``)
    radius_a: np.ndarray | None  # (K,) a's radius (None once the arms are made, ``forget_radii``)
    radius_b: np.ndarray | None  # (K,) b's radius, zero for planes
    inv_mass_a: np.ndarray | None  # (None while let go of, ``forget_masses``)
    inv_mass_b: np.ndarray | None
    inv_inertia_a: np.ndarray | None
    inv_inertia_b: np.ndarray | None
    restitution: np.ndarray
    friction: np.ndarray
    rolling: np.ndarray  # rolling resistance ρ·r (m): angular impulse per unit normal impulse
    surface: np.ndarray  # (K, 3) velocity of b's surface at the contact beyond b's own (moving planes)
    spin: np.ndarray  # (K, 3) angular velocity of that surface (a turning plane's ω)
    moving: bool  # whether any contact has a moving surface (else surface and spin are zero)
    static: int  # the static world's row (the number of balls)
    # |r_a| and |r_b| kept once the radii are let go (``forget_radii``); None: made from the radii
    arms: tuple[np.ndarray, np.ndarray] | None = None
    # each body's 1/m and 1/I (N + 1 rows, the static world's last), as the four columns above were
    # gathered from, for ``recall_masses``
    body_inverse: tuple[np.ndarray, np.ndarray] | None = None

    def __len__(self) -> int:
        return len(self.a)

    def arm_lengths(self, idx: np.ndarray | slice = slice(None)) -> tuple[np.ndarray, np.ndarray]:
        """|r_a| and |r_b| of the contacts ``idx``: the radii, or zero on a plane's side, as the lengths
        of the lever arms −radius_a·n and radius_b·n (read only)."""
        a, b = self._arms
        return a[idx], b[idx]

    @cached_property
    def _arms(self) -> tuple[np.ndarray, np.ndarray]:
        """Every contact's |r_a| and |r_b|, formed once (the solves ask for them several times an
        interval; each row's length is the same whichever rows are asked for)."""
        if self.arms is not None:
            return self.arms
        n = self.normal
        a, b = exact.norm_rows(-self.radius_a[:, None] * n), exact.norm_rows(self.radius_b[:, None] * n)
        a.flags.writeable = b.flags.writeable = False
        return a, b

    @cached_property
    def colours(self) -> list[np.ndarray]:
        """Groups of contacts sharing no ball, for the colour-by-colour sweeps (found when first asked)."""
        return colour(self.a, self.b, self.static)

    def normal_speeds(self, v: np.ndarray, idx: np.ndarray | slice = slice(None)) -> np.ndarray:
        """Each contact's normal speed v_n (negative: closing) of the contacts ``idx``, from the (N+1, 3)
        velocities ``v`` (row N the static world), against a moving plane's surface: the contact model's
        ``normal_speed`` on these rows."""
        surface = self.surface[idx].T if self.moving else None
        v_a, v_b = v.take(self.a[idx], axis=0).T, v.take(self.b[idx], axis=0).T  # faster than v[a]
        return contact_model.normal_speed(v_a, v_b, self.normal[idx].T, surface)

    def subset(self, mask: np.ndarray) -> ContactRows:
        """The contacts where ``mask`` holds."""
        kept = ("moving", "static", "body_inverse")
        idx = take_indices(mask)
        found = (*kept, "colours", "_arms", "arms")  # worked out from the rows, not rows themselves
        fields = {
            k: None if v is None else v.take(idx, axis=0) for k, v in vars(self).items() if k not in found
        }
        arms = None if self.arms is None else (self.arms[0].take(idx), self.arms[1].take(idx))
        return ContactRows(
            **fields, moving=self.moving, static=self.static, arms=arms, body_inverse=self.body_inverse
        )

    def forget_radii(self) -> None:
        """Keep the lever arms' lengths (``arm_lengths``) and let go of the radii they are made of:
        16 bytes a contact. Subsets and copies keep the lengths of their rows."""
        self.arms = self._arms
        self.radius_a = self.radius_b = None

    def forget_masses(self) -> None:
        """Let go of the contacts' inverse masses and inertias (32 bytes a contact), for a solve that
        reads them per ball (``ContactColumns.inverse``); ``recall_masses`` gathers them again."""
        self.inv_mass_a = self.inv_mass_b = self.inv_inertia_a = self.inv_inertia_b = None

    def recall_masses(self) -> None:
        """The inverse masses and inertias ``forget_masses`` let go of, gathered again from the bodies'
        (the same values)."""
        if self.inv_mass_a is not None:
            return
        inv_mass, inv_inertia = self.body_inverse
        self.inv_mass_a, self.inv_mass_b = inv_mass[self.a], inv_mass[self.b]
        self.inv_inertia_a, self.inv_inertia_b = inv_inertia[self.a], inv_inertia[self.b]


def contact_rows(model: Model, state: State, c: ContactPoints) -> ContactRows:
    """Masses, lever arms, mixed materials and surface motion of the contacts ``c``, in colours."""
    sph, pl = model.spheres, model.planes
    with_static = lambda arr: np.concatenate((arr, _ZERO))  # noqa: E731 - row N is the static world
    radius, inv_mass, inv_inertia = (with_static(a) for a in (sph.radius, sph.inv_mass, sph.inv_inertia))
    if state.sleep.any:  # a sleeping ball an awake one leans on holds like a plane (sleeping.py)
        held = np.append(state.sleep.asleep, False)
        inv_mass[held], inv_inertia[held] = 0.0, 0.0
    on_plane = c.kind == SPHERE_PLANE
    p = np.where(on_plane, c.other, 0)
    o = np.where(on_plane, 0, c.other)

    def mixed(ball: np.ndarray, plane: np.ndarray, rule) -> np.ndarray:
        other = np.where(on_plane, plane[p] if len(plane) else 0.0, ball[o])
        return rule(ball[c.a], other)

    moving = model.moving_planes()
    # no moving plane: zero, one read-only row seen K times (read only while ``moving``; ``subset``
    # takes real rows of it)
    surface = spin = np.broadcast_to(np.zeros(3), (len(c), 3))
    if moving:  # a plane's surface moves at v + ω × (p − c) under the contact point
        surface, spin = np.zeros((len(c), 3)), np.zeros((len(c), 3))
        surface[on_plane] = moving_planes.surface_velocity(model, state, p[on_plane], c.point[on_plane])
        spin[on_plane] = model.plane_spin()[p[on_plane]]
    ra, rb = radius[c.a], radius[c.b]
    # Rolling resistance acts through the rolling radius: r for a ball on a plane, the reduced
    # radius 2·r_a·r_b/(r_a + r_b) between two balls.
    roll_radius = np.where(on_plane, ra, 2.0 * ra * rb / np.where(on_plane, 1.0, ra + rb))
    return ContactRows(
        a=c.a,
        b=c.b,
        normal=c.normal,
        radius_a=ra,
        radius_b=rb,
        inv_mass_a=inv_mass[c.a],
        inv_mass_b=inv_mass[c.b],
        inv_inertia_a=inv_inertia[c.a],
        inv_inertia_b=inv_inertia[c.b],
        restitution=mixed(sph.restitution, pl.restitution, np.multiply),
        friction=np.sqrt(mixed(sph.friction, pl.friction, np.multiply)),
        rolling=np.sqrt(mixed(sph.rolling_friction, pl.rolling_friction, np.multiply)) * roll_radius,
        surface=surface,
        spin=spin,
        moving=moving,
        static=sph.count,
        body_inverse=(inv_mass, inv_inertia),
    )


def colour(a: np.ndarray, b: np.ndarray, static: int) -> list[np.ndarray]:
    """Split contacts into groups in which no ball appears twice (the static row may repeat).

    Each round takes every contact whose priority is the lowest among the contacts on both its balls
    (Luby's independent sets); priorities are a fixed hash of the index, so colouring is deterministic.
    """
    remaining = np.arange(len(a))
    if 0 < len(a) <= ONE_COLOUR_CHECK_UP_TO:  # a few contacts on different balls: one colour
        ends = np.concatenate((a, b[b != static]))
        ends.sort()
        if not np.count_nonzero(ends[1:] == ends[:-1]):
            return [remaining]
    priority = (remaining.astype(np.uint64) * np.uint64(2654435761)) % np.uint64(4294967291)
    order = np.argsort(priority, kind="stable")
    rank = np.empty(len(a), np.int64)
    rank[order] = np.arange(len(a))
    colours = []
    lowest = np.empty(static + 1, np.int64)
    while remaining.size:
        ra, rb = a[remaining], b[remaining]
        r = rank[remaining]
        lowest.fill(len(a))
        np.minimum.at(lowest, ra, r)
        dynamic_b = rb != static
        np.minimum.at(lowest, rb[dynamic_b], r[dynamic_b])
        chosen = (lowest[ra] == r) & (~dynamic_b | (lowest[rb] == r))
        colours.append(remaining[chosen])
        remaining = remaining[~chosen]
    return colours


def rows_at_end(
    model: Model, state: State, c: ContactPoints, rows: ContactRows, lin: np.ndarray, h: float, warm: Impulses
) -> ContactRows:
    """The contact rows of ``c`` as they will be ``h`` seconds on, on turning planes (``rows`` as they
    are now, ``lin`` the balls' free accelerations, ``warm`` the warm-start impulses, whose friction is
    turned onto the new tangent planes in place).

    The resting solve makes the velocities at the end of its interval satisfy the contacts, so it must
    ask it of the contacts as they are then: on a plane turning at ω the normal will have turned by ω·h,
    and the surface under the ball moves at v_p + ω × (p₁ − c₁) where the ball will be (its path under
    its free acceleration and its own contact's warm-start force). Asked of today's normal and today's
    surface velocity instead, a ball rolling at s along the plane ends the interval approaching or
    leaving it at about 2·ω·s·h (the Coriolis term of the plane's turning frame), and drifts into it or
    off it by about ω·s·h² a step: a see-saw's rolling balls sank a few µm and then floated just beyond
    the contact slop, where every step split at their little falls.

    The normal turns by Rodrigues' formula with each plane's cos(ω·h) and sin(ω·h) taken once per plane
    from ``exact.sin_cos`` (a few planes, not balls).
    """
    pl = model.planes
    on_plane = c.kind == SPHERE_PLANE
    spins = model.plane_spin()  # a plane too slow for its rate to be formed does not turn
    turning = spins.any(axis=1)
    on = (on_plane & turning[np.where(on_plane, c.other, 0)]).nonzero()[0]
    if on.size == 0:
        return rows
    plane, ball = c.other[on], c.a[on]
    spin = spins[plane]
    rates = [exact.norm_floats(x, y, z) for x, y, z in spins.tolist()]
    sin_all, cos_all = _sin_cos(np.array(rates) * h)
    sin, cos = sin_all[plane, None], cos_all[plane, None]
    axis = spin / np.array(rates)[plane, None]
    n = rows.normal[on]
    # Rodrigues: n·cos θ + (k × n)·sin θ + k·(k·n)·(1 − cos θ)
    turned = (
        n * cos + exact.cross_rows(axis, n) * sin + axis * (exact.dot_rows(axis, n)[:, None] * (1.0 - cos))
    )
    push = (warm.normal[on, None] * n + warm.friction[on]) * (rows.inv_mass_a[on] / h)[:, None]
    body, radius = state.body, model.spheres.radius[ball, None]
    centre = model.integrator.path_end(body[ball, 0:3], body[ball, 3:6], lin[ball] + push, h)
    plane_centre = state.planes.center[plane] + pl.velocity[plane] * h
    normal, surface = rows.normal.copy(), rows.surface.copy()
    normal[on] = turned
    surface[on] = pl.velocity[plane] + exact.cross_rows(spin, centre - radius * turned - plane_centre)
    friction = warm.friction[on]
    warm.friction[on] = friction - exact.dot_rows(friction, turned)[:, None] * turned
    end = shallow_copy(rows)  # the same contacts (and colours, if found), their normals and surfaces
    end.normal, end.surface = normal, surface  # turned; the lever arms turn with the normal
    end.__dict__.pop("_arms", None)
    return end


# The planes' sines and cosines by their angles' bits: planes turning steadily turn by the same angles
# every whole step, so they are worked out once (as moving_planes keeps its turns).
_SIN_COS: dict[bytes, tuple[np.ndarray, np.ndarray]] = {}
_SIN_COS_KEPT = 256


def _sin_cos(angle: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``exact.sin_cos`` of a few planes' angles (not math's: its bits depend on the CPU), remembered."""
    key = angle.tobytes()
    found = _SIN_COS.get(key)
    if found is None:
        if len(_SIN_COS) >= _SIN_COS_KEPT:
            _SIN_COS.clear()
        sin, cos = exact.sin_cos(angle)
        sin.flags.writeable = cos.flags.writeable = False
        found = _SIN_COS[key] = (sin, cos)
    return found
