"""The public API's argument checks (validation.py): each refusal names the argument and the bad value,
and what passes comes back as the numbers a step works with."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ballpit.physics.core import validation


@pytest.mark.parametrize(
    ("value", "error", "says"),
    [
        (math.nan, ValueError, "restitution must be finite, got nan"),
        (True, TypeError, "restitution must be a number, got True"),
        ("0.5", TypeError, "restitution must be a number, got '0.5'"),
        (10**400, ValueError, "restitution must be finite, got an integer too large for a float"),
        (1.5, ValueError, "restitution must be from 0 to 1, got 1.5"),
    ],
)
def test_a_bad_number_is_refused_naming_the_argument_and_the_value(value, error, says):
    with pytest.raises(error) as caught:
        validation.number("restitution", value, within=(0.0, 1.0))
    assert str(caught.value) == says


def test_a_number_passes_as_a_float_and_inf_only_where_allowed():
    assert validation.number("x", np.int64(3)) == 3.0 and type(validation.number("x", 3)) is float
    assert validation.number("crowd_limit", math.inf, infinite=True) == math.inf
    with pytest.raises(ValueError, match="crowd_limit must be finite, got inf"):
        validation.number("crowd_limit", math.inf)
    with pytest.raises(ValueError, match="drag must not be negative, got -1"):
        validation.number("drag", -1, nonnegative=True)


def test_a_unit_vector_keeps_its_direction_however_large_its_components():
    v = validation.unit_vector("normal", (1e300, 1e300, 0.0))  # its square would overflow
    assert v == pytest.approx([math.sqrt(0.5), math.sqrt(0.5), 0.0], rel=1e-15)
    with pytest.raises(ValueError, match=r"normal must not be a zero vector, got \(0, 0, 0\)"):
        validation.unit_vector("normal", (0, 0, 0))


def test_a_quaternion_is_normalised_and_a_zero_one_refused():
    assert validation.quaternion("orientation", (0, 0, 0, 2)).tolist() == [0.0, 0.0, 0.0, 1.0]
    with pytest.raises(ValueError, match="orientation must not be a zero quaternion"):
        validation.quaternion("orientation", (0, 0, 0, 0))
    with pytest.raises(ValueError, match=r"orientation must have 4 components, got \(1, 0, 0\)"):
        validation.quaternion("orientation", (1, 0, 0))


def test_a_vector_beyond_its_limit_is_refused_with_the_limit():
    with pytest.raises(ValueError, match="velocity must have components of at most 1e\\+09 in size"):
        validation.vector("velocity", (2e9, 0, 0), limit=validation.MAX_SPEED)


def test_a_plane_takes_a_normal_or_a_rotation_not_both():
    with pytest.raises(ValueError, match="give a plane's normal or its rotation, not both"):
        validation.plane((0, 0, 0), (0, 1, 0), (0, 0, 10), None, 0.5, 0.5, 0.0, (0, 0, 0), (0, 0, 0))
    center, q, extent, materials, _ = validation.plane(
        (1, 2, 3), (1, 0, 0), None, (2.0, 4.0), 0.5, 0.5, 0.0, (0, 0, 0), (0, 0, 0)
    )
    assert center.tolist() == [1.0, 2.0, 3.0] and extent == (2.0, 4.0) and materials["friction"] == 0.5
    # the shortest turn from +y to +x: 90° about −z
    assert q == pytest.approx([0.0, 0.0, -math.sqrt(0.5), math.sqrt(0.5)], abs=1e-15)


def test_balls_broadcast_every_argument_against_their_positions_and_name_a_bad_shape():
    rows = validation.balls(
        np.zeros((4, 3)), 0.5, [1, 2, 3, 4], (0, 0, 0), (0, 0, 0), (0, 0, 0, 1), 1.0, 0.5, 0, False
    )
    assert rows["mass"].tolist() == [1.0, 2.0, 3.0, 4.0] and rows["radius"].shape == (4,)
    with pytest.raises(ValueError, match=r"positions must have shape \(N, 3\), got shape \(4, 2\)"):
        validation.balls(np.zeros((4, 2)), 0.5, 1, (0, 0, 0), (0, 0, 0), (0, 0, 0, 1), 1.0, 0.5, 0, False)
