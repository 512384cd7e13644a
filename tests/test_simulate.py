"""The headless runner in-process: step plans, energies, the recorded outputs against a direct run."""

from __future__ import annotations

import pytest

from ballpit.simulate import MAX_STEPS, TooManySteps, step_plan


def test_step_plan_ends_exactly_and_refuses_more_than_max_steps():
    assert step_plan(0.105, 0.01) == [(10, 0.01), (1, pytest.approx(0.005))]
    assert step_plan(1.0, 0.25) == [(4, 0.25)]
    assert sum(n for n, _ in step_plan(1.0, 1.0 / MAX_STEPS)) == MAX_STEPS
    with pytest.raises(TooManySteps, match=r"1e\+301 steps; the limit is 1e\+09"):
        step_plan(10.0, 1e-300)
    with pytest.raises(TooManySteps, match="inf steps"):
        step_plan(1e300, 1e-300)
