"""The input → action mapping: every binding of design.md's "Viewer controls" table, without GL."""

from __future__ import annotations

import numpy as np
import pytest

from ballpit.physics.dynamics.integrators import INTEGRATORS
from ballpit.viewer import controls
from ballpit.viewer.controls import Action, IntegratorAction, action_for_key

DESIGN_TABLE = {
    "X": Action.START,
    "SPACE": Action.PAUSE,
    "N": Action.STEP,
    "RIGHT": Action.STEP,
    "R": Action.RESET,
    "F5": Action.RELOAD,
    "_1": IntegratorAction.EULER,
    "_2": IntegratorAction.RK2,
    "_3": IntegratorAction.RK4,
    "_4": IntegratorAction.SYMPLECTIC,
    "TAB": Action.CAPTURE_MOUSE,
    "ESCAPE": Action.ESCAPE,
    "C": Action.CONTACTS,
    "V": Action.VELOCITIES,
    "T": Action.TRAILS,
    "H": Action.HUD,
    "F1": Action.HELP,
    "F12": Action.SCREENSHOT,
}


@pytest.mark.parametrize(("name", "action"), DESIGN_TABLE.items())
def test_each_key_of_the_design_table_maps_to_its_action(name, action):
    assert action_for_key(name) is action


@pytest.mark.parametrize(
    ("text", "action"),
    [("+", Action.FASTER), ("=", Action.FASTER), ("-", Action.SLOWER), ("_", Action.SLOWER)],
)
def test_plus_and_minus_are_read_from_the_typed_text(text, action):
    assert controls.action_for_text(text) is action


@pytest.mark.parametrize("name", ["EQUAL", "PLUS", "NUM_ADD", "MINUS", "NUM_SUBTRACT"])
def test_plus_and_minus_key_symbols_do_nothing_so_a_press_is_not_counted_twice(name):
    assert action_for_key(name) is None
    assert controls.action_for_text("x") is None


def test_ctrl_r_reloads_while_plain_r_resets():
    assert action_for_key("R", ctrl=True) is Action.RELOAD
    assert action_for_key("R") is Action.RESET


def test_unbound_keys_and_other_ctrl_chords_do_nothing():
    assert action_for_key("Z") is None
    assert action_for_key("X", ctrl=True) is None


def test_number_keys_choose_the_integrators_by_name():
    names = [controls.INTEGRATOR_ACTIONS[action_for_key(k)] for k in ("_1", "_2", "_3", "_4")]
    assert names == ["euler", "rk2", "rk4", "symplectic"]


@pytest.mark.parametrize("integrator", INTEGRATORS.values(), ids=lambda i: i.name)
def test_each_registered_integrator_has_its_key_on_both_rows_and_in_the_help(integrator):
    for name in (f"_{integrator.key}", f"NUM_{integrator.key}"):
        assert controls.INTEGRATOR_ACTIONS[action_for_key(name)] == integrator.name
    keys, what = next(row for row in controls.HELP if row[0].startswith("1/"))
    assert integrator.key in keys.replace(",", "/").split("/")
    assert integrator.label in what


def test_fly_keys_give_unit_camera_relative_directions():
    assert np.allclose(controls.fly_direction({"W"}), [0, 0, 1])
    assert np.allclose(controls.fly_direction({"S"}), [0, 0, -1])
    assert np.allclose(controls.fly_direction({"A"}), [-1, 0, 0])
    assert np.allclose(controls.fly_direction({"D"}), [1, 0, 0])
    assert np.allclose(controls.fly_direction({"Q"}), [0, -1, 0])
    assert np.allclose(controls.fly_direction({"E"}), [0, 1, 0])
    diagonal = controls.fly_direction({"W", "D", "X"})
    assert np.allclose(diagonal, [np.sqrt(0.5), 0, np.sqrt(0.5)])
    assert np.allclose(controls.fly_direction({"W", "S"}), 0)


def test_shift_flies_faster():
    assert controls.fly_speed_multiplier({"W"}) == 1.0
    assert controls.fly_speed_multiplier({"W", "LSHIFT"}) == controls.SHIFT_SPEEDUP
    assert controls.fly_speed_multiplier({"RSHIFT"}) == controls.SHIFT_SPEEDUP


def test_scrolling_changes_fly_speed_within_bounds():
    assert controls.scrolled_fly_speed(4.0, 1) == pytest.approx(4.0 * controls.SCROLL_FACTOR)
    assert controls.scrolled_fly_speed(4.0, -2) == pytest.approx(4.0 / controls.SCROLL_FACTOR**2)
    assert controls.scrolled_fly_speed(4.0, 1000) == controls.FLY_SPEED_RANGE[1]
    assert controls.scrolled_fly_speed(4.0, -1000) == controls.FLY_SPEED_RANGE[0]


def test_time_scale_doubles_and_halves_within_bounds():
    assert controls.faster(1.0) == 2.0
    assert controls.slower(1.0) == 0.5
    assert controls.faster(controls.TIME_SCALE_RANGE[1]) == controls.TIME_SCALE_RANGE[1]
    assert controls.slower(controls.TIME_SCALE_RANGE[0]) == controls.TIME_SCALE_RANGE[0]


def test_escape_releases_a_captured_mouse_and_quits_only_when_pressed_again():
    assert controls.escape_outcome(mouse_captured=True) == "release"
    assert controls.escape_outcome(mouse_captured=True, armed=True) == "release"
    assert controls.escape_outcome(mouse_captured=False) == "arm"
    assert controls.escape_outcome(mouse_captured=False, armed=True) == "quit"


def test_help_lists_every_control_of_the_design_table():
    keys = " ".join(k for k, _ in controls.HELP)
    for label in ("X", "Space", "N", "→", "R", "Ctrl+R", "F5", "1/2/3/4", "+ / −", "W A S D", "Q E",
                  "Shift", "Tab", "Esc", "C / V / T", "H / F1", "F12", "←", "Shift+←", "G", "P"):  # fmt: skip
        assert label in keys, label
    assert "scroll" in " ".join(w for _, w in controls.HELP)


def test_arrows_move_through_the_history_and_g_p_toggle_ghosts_and_plot():
    assert controls.action_for_key("LEFT") is Action.STEP_BACK
    assert controls.action_for_key("RIGHT") is Action.STEP
    assert controls.action_for_key("LEFT", shift=True) is Action.JUMP_BACK
    assert controls.action_for_key("RIGHT", shift=True) is Action.JUMP_FORWARD
    assert controls.action_for_key("G") is Action.GHOSTS
    assert controls.action_for_key("P") is Action.ENERGY_PLOT
    assert controls.action_for_key("X", shift=True) is Action.START  # Shift only changes the arrows


def test_reaching_in_keys_shoot_change_the_shot_speed_go_home_and_save():
    assert action_for_key("B") is Action.SHOOT
    assert action_for_key("B", shift=True) is Action.SHOT_SPEED
    assert action_for_key("HOME") is Action.HOME
    assert action_for_key("S", ctrl=True) is Action.SAVE
    assert action_for_key("S") is None and "S" in controls.FLY_KEYS  # plain S still flies back
    assert action_for_key("X", shift=True) is Action.START  # Shift changes only what it is bound for
    keys = " ".join(k for k, _ in controls.HELP)
    for label in ("left-drag", "B / Shift+B", "click a plane", "Home", "Ctrl+S"):
        assert label in keys, label
