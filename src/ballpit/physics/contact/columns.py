"""The contacts as the Jacobi sweeps read them (jacobi.py): one column per contact, vectors as (3, K) rows,
gathered once per solve."""

from __future__ import annotations

import numpy as np

from ..core.settings import ADD_UP_BINS_UP_TO, SWEEP_CHUNK
from . import contact_model as model
from .ends import Ends
from .rows import ContactRows


class ContactColumns(Ends):
    """What the sweeps need of the contacts, gathered once per solve, with vectors as (3, K) rows.

    Velocities are the rows of one (6, M) array [v; ω] of just the M balls the contacts touch; ``ends``
    are the columns of each contact's a then b. A sweep gathers both ends with one ``np.take`` and adds
    every contact's impulse to its two balls with one ``np.bincount``. Laid out by component, every
    other operation is on contiguous rows of K numbers, without broadcasting over a short axis.
    Friction and rolling resistance are solved as one (2, 3, K) block: the same update and the same
    cap, with their own effective masses and limits (zero limits where a material has none).
    """

    def __init__(self, contacts: ContactRows, split: bool = True, motion: np.ndarray | None = None) -> None:
        """The columns of ``contacts``, each ball's mass split among all its contacts (``split``; a
        caller that splits before its first sweep, as a soft frame's solve does, says False); ``motion``,
        if given, is the (2, 3, K) scratch of a full sweep (made here otherwise)."""
        super().__init__(contacts.a, contacts.b)
        k, m = self.k, self.m
        ima, imb = contacts.inv_mass_a, contacts.inv_mass_b
        iia, iib = contacts.inv_inertia_a, contacts.inv_inertia_b
        # each contact's 1/m and 1/I at both ends, up to SWEEP_CHUNK contacts; beyond, gathered from
        # each ball's (``inverse``) where a chunk needs them, not held (32 bytes a contact)
        self._masses = (ima, imb, iia, iib) if k <= SWEEP_CHUNK else None
        self.ra, self.rb = contacts.arm_lengths()
        self.n = np.ascontiguousarray(contacts.normal.T)
        # the friction cone μ·P_n and the rolling limit ρ_roll·P_n, per unit of normal impulse (the rows'
        # own arrays: ``jacobi._full_sweep`` forms their (2, K) block for each sweep)
        self.friction, self.rolling = contacts.friction, contacts.rolling
        # each ball's own m⁻¹ and I⁻¹, for adding the summed impulses to its velocity
        inv_mass, inv_inertia = np.zeros(m), np.zeros(m)
        inv_mass[self.ends[:k]], inv_mass[self.ends[k:]] = ima, imb
        inv_inertia[self.ends[:k]], inv_inertia[self.ends[k:]] = iia, iib
        self.inverse = np.stack((inv_mass, inv_inertia))  # (2, M): m⁻¹ for v's rows, I⁻¹ for ω's
        # 1/m_n of the unsplit balls, and bounds on how much a unit of impulse changes a contact's
        # velocity, for the convergence test
        inv_n, inv_t, _ = model.inverse_effective_masses(ima, imb, iia, iib, self.ra, self.rb)
        del ima, imb, iia, iib
        self.whole = inv_n
        self.inv_m_n, self.inv_m_t = float(inv_n.max()), float(inv_t.max())
        self.moving = contacts.moving
        self.surface = np.ascontiguousarray(contacts.surface.T) if self.moving else None
        self.spin = np.ascontiguousarray(contacts.spin.T) if self.moving else None
        # scratch for what each contact adds to its a (columns :K) then its b (K:), and for the slip
        # at the contact point and the relative spin (friction, rolling), kept for every sweep; beyond
        # ADD_UP_BINS_UP_TO entries the pushes are made and added up one row at a time (``apply``), in
        # one row of scratch instead of six (80 bytes a contact less)
        self.push = np.empty((1 if 12 * k > ADD_UP_BINS_UP_TO else 6, 2 * k))
        self.motion = np.empty((2, 3, k)) if motion is None else motion
        self.m_n: np.ndarray | None = None
        self.m_tr: np.ndarray | None = None
        if split:
            self.split()

    @property
    def ima(self) -> np.ndarray:
        """Each contact's a's 1/m (read only)."""
        return self._per_contact(0)

    @property
    def imb(self) -> np.ndarray:
        """Each contact's b's 1/m, 0 for a plane (read only)."""
        return self._per_contact(1)

    @property
    def iia(self) -> np.ndarray:
        """Each contact's a's 1/I (read only)."""
        return self._per_contact(2)

    @property
    def iib(self) -> np.ndarray:
        """Each contact's b's 1/I, 0 for a plane (read only)."""
        return self._per_contact(3)

    def _per_contact(self, which: int) -> np.ndarray:
        """``ima``, ``imb``, ``iia`` or ``iib`` (``which`` 0 to 3): kept, or gathered from each ball's
        (``inverse``: 1/m for 0 and 1, 1/I for 2 and 3; a's ends for even, b's for odd)."""
        if self._masses is not None:
            return self._masses[which]
        k = self.k
        ends = self.ends[k:] if which % 2 else self.ends[:k]
        return self.inverse[which // 2].take(ends)

    def normal_speeds(self, v: np.ndarray) -> np.ndarray:
        """Each contact's v_n = (v_a − v_b)·n from the (≥3, M) velocities ``v`` (spin does not change it
        on spheres), against a moving plane's surface: the contact model's ``normal_speed`` on these
        columns."""
        k = self.k
        if k <= SWEEP_CHUNK:
            g = v[:3].take(self.ends, axis=1)
            return model.normal_speed(g[:, :k], g[:, k:], self.n, self.surface, out=g[:, :k])
        vn = np.empty(k)  # SWEEP_CHUNK contacts at a time: the gathers of a chunk, not of all
        for lo in range(0, k, SWEEP_CHUNK):
            part = slice(lo, min(lo + SWEEP_CHUNK, k))
            v_a = np.take(v[:3], self.ends[:k][part], axis=1)
            v_b = np.take(v[:3], self.ends[k:][part], axis=1)
            surface = None if self.surface is None else self.surface[:, part]
            vn[part] = model.normal_speed(v_a, v_b, self.n[:, part], surface, out=v_a)
        return vn

    def split(self, pushing: np.ndarray | None = None) -> None:
        """Split each ball's mass among its contacts, or among those ``pushing`` only (at least one share
        each): each ball's ``shares`` and the effective masses ``m_n`` and ``m_tr`` (friction, then
        rolling, as (2, 1, K)). Beyond SWEEP_CHUNK contacts, ``m_n`` is formed a chunk at a time into
        the array of the last split (a soft frame splits once a substep) and m_t, m_r where a full
        sweep's chunk uses them (``tangent_masses``): not kept, 16 bytes a contact."""
        k = self.k
        if pushing is None:
            share = self.share
        else:
            # each ball's pushing contacts counted at both ends: whole numbers, exact in any order (the
            # sums of ones a count weighted by ``pushing`` made), with no 2K weights
            counts = np.bincount(self.ends[:k][pushing], minlength=self.m).astype(float)
            counts += np.bincount(self.ends[k:][pushing], minlength=self.m)
            share = np.maximum(counts, 1.0, out=counts)
        self.shares = share
        if k <= SWEEP_CHUNK:  # one chunk: m_t and m_r made here with m_n, once a split, and kept
            both = share.take(self.ends)
            sa, sb = both[:k], both[k:]
            inv_n, inv_t, inv_r = model.inverse_effective_masses(
                sa * self.ima, sb * self.imb, sa * self.iia, sb * self.iib, self.ra, self.rb
            )
            # model.effective_masses' reciprocals, m_t and m_r formed in their (2, 1, K) block
            self.m_n, self.m_tr = np.divide(1.0, inv_n, out=inv_n), np.empty((2, 1, k))
            np.divide(1.0, inv_t, out=self.m_tr[0, 0])
            np.divide(1.0, inv_r, out=self.m_tr[1, 0])
            return
        if self.m_n is None:
            self.m_n = np.empty(k)
        # each ball's n_b·m⁻¹ and n_b·I⁻¹, gathered per contact end: the same products as a contact's
        # share times its own m⁻¹ and I⁻¹
        self.split_inverse = split = share * self.inverse
        for lo in range(0, k, SWEEP_CHUNK):
            part = slice(lo, min(lo + SWEEP_CHUNK, k))
            # model.effective_masses' m_n: 1/(n_a·m_a⁻¹ + n_b·m_b⁻¹)
            inv_n = split[0].take(self.ends[:k][part])
            inv_n += split[0].take(self.ends[k:][part])
            np.divide(1.0, inv_n, out=self.m_n[part])

    def tangent_masses(self, part: slice) -> np.ndarray:
        """The friction and rolling effective masses m_t, m_r of the contacts ``part`` as (2, 1, chunk),
        with the masses split as the last ``split`` split them (``model.effective_masses``)."""
        if self.k <= SWEEP_CHUNK:
            return self.m_tr
        k, split = self.k, self.split_inverse
        ea, eb = self.ends[:k][part], self.ends[k:][part]
        m_t_r = np.empty((2, 1, len(ea)))
        _, m_t_r[0, 0], m_t_r[1, 0] = model.effective_masses(
            split[0].take(ea),
            split[0].take(eb),
            split[1].take(ea),
            split[1].take(eb),
            self.ra[part],
            self.rb[part],
        )
        return m_t_r
