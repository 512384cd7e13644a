"""The energy plot (P) without a window: its curves' colours tell apart, its legend stays inside it."""

from __future__ import annotations

import colorsys
import itertools

import numpy as np

from ballpit.physics.integrators import INTEGRATORS
from ballpit.viewer.energyplot import KINETIC_COLOR, POTENTIAL_COLOR, EnergyTrace, legend, legend_layout


def test_kinetic_potential_and_every_integrators_total_have_hues_far_apart():
    """With ghosts on, the plot draws K, U and one total per integrator in its colour: K and U are each
    at least 30 degrees of hue from each other and from every integrator (K was green, as symplectic
    Euler is, and U blue, as RK4 is)."""
    colors = {"kinetic": KINETIC_COLOR[:3], "potential": POTENTIAL_COLOR[:3]}
    colors |= {name: integrator.rgb for name, integrator in INTEGRATORS.items()}
    hues = {name: colorsys.rgb_to_hsv(*rgb)[0] * 360 for name, rgb in colors.items()}
    for (a, ha), (b, hb) in itertools.combinations(hues.items(), 2):
        if a in INTEGRATORS and b in INTEGRATORS:
            continue  # the integrators' own colours are the registry's choice (Euler's and RK2's are
            # 27 degrees apart, a red and an orange)
        apart = min(abs(ha - hb), 360 - abs(ha - hb))
        assert apart >= 30, (a, b, apart)


def test_the_legend_wraps_into_rows_inside_the_plot():
    trace = EnergyTrace()
    trace.add(0.0, 1.0, 2.0, {name: 3.0 for name in INTEGRATORS})
    items = legend(trace.series(), ghosts=True)
    texts = [text for text, _ in items]
    assert texts == ["kinetic", "potential", *(f"E {i.label}" for i in INTEGRATORS.values())]
    widths = [7.0 * len(t) for t in texts]  # a 10-point monospaced font: about 7 px a character
    rect = (400.0, 250.0, 380.0, 170.0)
    places = legend_layout(widths, rect, line_height=14.0)
    x0, y0, w, h = rect
    for (x, y), width in zip(places, widths, strict=True):
        assert x0 <= x and x + width <= x0 + w and y0 <= y and y + 14.0 <= y0 + h
    rows = sorted({y for _, y in places})
    assert len(rows) == 2  # 6 labels do not fit in one row of 380 px: a second one above it
    # labels in a row do not overlap
    for row in rows:
        spans = sorted((x, x + width) for (x, y), width in zip(places, widths, strict=True) if y == row)
        assert all(a[1] <= b[0] for a, b in itertools.pairwise(spans))
    assert np.allclose(legend_layout([50.0], rect, 14.0), [(406.0, 254.0)])  # one fits at the start
