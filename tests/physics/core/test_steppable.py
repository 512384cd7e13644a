"""What a step can step (steppable.py): a non-finite or out-of-range value written straight into the
arrays is named and refused before the step, and one a step made is named after it."""

from __future__ import annotations

import numpy as np
import pytest

from ballpit.physics.core import steppable
from ballpit.physics.core.validation import MAX_SPEED


def body(n: int = 3) -> np.ndarray:
    b = np.zeros((n, 13))
    b[:, 9] = 1.0  # unit orientations
    return b


def test_a_good_block_passes_and_a_bad_value_is_named_by_ball_and_field():
    steppable.reject_unsteppable_state(body())
    bad = body()
    bad[2, 4] = np.nan
    with pytest.raises(
        ValueError, match=r"sphere #2 has a non-finite velocity \(nan\); the world was not stepped"
    ):
        steppable.reject_unsteppable_state(bad)
    fast = body()
    fast[1, 3] = 2 * MAX_SPEED
    with pytest.raises(ValueError, match="sphere #1 has beyond 1e\\+09 in its velocity"):
        steppable.reject_unsteppable_state(fast)


def test_a_step_that_made_a_state_non_finite_is_a_floating_point_error_naming_the_ball():
    assert steppable.step_fault(body()) is None
    bad = body()
    bad[1, 0] = np.inf
    fault = steppable.step_fault(bad)
    assert isinstance(fault, FloatingPointError) and "sphere #1" in str(fault) and "undone" in str(fault)
