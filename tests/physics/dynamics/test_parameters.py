"""A World's parameters (parameters.py): each checks what is written, naming itself and the value, and
keeps it in the model, where the step reads it."""

from __future__ import annotations

import numpy as np
import pytest

import ballpit


def test_each_kind_of_parameter_keeps_what_passes_in_the_model_under_its_name():
    world = ballpit.World()
    world.gravity = (0, -3, 0)
    world.substeps = 4
    world.sleep = np.bool_(True)
    world.restitution_threshold = None
    world.integrator = "RK2"
    assert world.model.gravity.tolist() == [0.0, -3.0, 0.0] and world.model.substeps == 4
    assert world.model.sleep is True and world.model.restitution_threshold is None
    assert world.integrator == "rk2" and world.model.integrator.name == "rk2"


def test_gravity_reads_as_a_read_only_vector_and_each_parameter_refuses_by_name():
    world = ballpit.World()
    with pytest.raises(ValueError, match="read-only"):
        world.gravity[1] = 0.0
    with pytest.raises(ValueError, match="substeps must be a whole number from 1 to"):
        world.substeps = 0
    with pytest.raises(TypeError, match="sleep must be true or false, got 'yes'"):
        world.sleep = "yes"
    with pytest.raises(ValueError, match="integrator must be one of euler, rk2, rk4, symplectic, got 'rk3'"):
        world.integrator = "rk3"
    with pytest.raises(ValueError, match="linear_drag must not be negative, got -1"):
        world.linear_drag = -1
    assert type(world).gravity.__doc__.startswith("Gravity (m/s²)")
