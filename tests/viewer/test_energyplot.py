"""The panel's energy plot without a window: its curves have colours that tell apart."""

from __future__ import annotations

import colorsys
import itertools

from ballpit.physics.dynamics.integrators import INTEGRATORS
from ballpit.viewer.energyplot import KINETIC_COLOR, POTENTIAL_COLOR


def test_kinetic_potential_and_every_integrators_total_have_hues_far_apart():
    """With ghosts on, the energy plot draws K, U and one total per integrator in its colour: K and U
    are each at least 30 degrees of hue from each other and from every integrator (K was green, as
    symplectic Euler is, and U blue, as RK4 is)."""
    colors = {"kinetic": KINETIC_COLOR[:3], "potential": POTENTIAL_COLOR[:3]}
    colors |= {name: integrator.rgb for name, integrator in INTEGRATORS.items()}
    hues = {name: colorsys.rgb_to_hsv(*rgb)[0] * 360 for name, rgb in colors.items()}
    for (a, ha), (b, hb) in itertools.combinations(hues.items(), 2):
        if a in INTEGRATORS and b in INTEGRATORS:
            continue  # the integrators' own colours are the registry's choice (Euler's and RK2's are
            # 27 degrees apart, a red and an orange)
        apart = min(abs(ha - hb), 360 - abs(ha - hb))
        assert apart >= 30, (a, b, apart)
