"""The contact model's formulas (contact_model.py), checked against the impulse laws they are built
from: Δv_a = (P_n·n + P_t)/m_a, Δω_a = (−ρ_a·n × P_t + R)/I_a and the opposite on b."""

from __future__ import annotations

import numpy as np
import pytest

from ballpit.physics.contact import contact_model


def two_balls(seed: int = 1, k: int = 7) -> dict:
    """K contacts between random balls: masses, inertias, radii, velocities, spins and unit normals,
    per-contact vectors as (3, K) columns."""
    rng = np.random.default_rng(seed)
    mass_a, mass_b = rng.uniform(0.5, 5.0, (2, k))
    radius_a, radius_b = rng.uniform(0.1, 1.0, (2, k))
    n = rng.normal(size=(3, k))
    n /= np.sqrt((n * n).sum(axis=0))
    return {
        "inv_mass_a": 1 / mass_a,
        "inv_mass_b": 1 / mass_b,
        "inv_inertia_a": 1 / (0.4 * mass_a * radius_a**2),
        "inv_inertia_b": 1 / (0.4 * mass_b * radius_b**2),
        "arm_a": radius_a,
        "arm_b": radius_b,
        "n": n,
        "v_a": rng.normal(size=(3, k)),
        "v_b": rng.normal(size=(3, k)),
        "w_a": rng.normal(size=(3, k)),
        "w_b": rng.normal(size=(3, k)),
    }


def applied(b: dict, normal: np.ndarray, friction: np.ndarray, rolling: np.ndarray) -> dict:
    """The balls of ``b`` after the impulses, by the impulse laws written out."""
    n, cross = b["n"], lambda p, q: np.cross(p.T, q.T).T
    push = normal * n + friction
    out = dict(b)
    out["v_a"] = b["v_a"] + push * b["inv_mass_a"]
    out["v_b"] = b["v_b"] - push * b["inv_mass_b"]
    out["w_a"] = b["w_a"] + (-b["arm_a"] * cross(n, friction) + rolling) * b["inv_inertia_a"]
    out["w_b"] = b["w_b"] + (-b["arm_b"] * cross(n, friction) - rolling) * b["inv_inertia_b"]
    return out


def velocity(b: dict) -> np.ndarray:
    return contact_model.contact_velocity(
        b["v_a"], b["w_a"], b["v_b"], b["w_b"], b["n"], b["arm_a"], b["arm_b"]
    )


def masses(b: dict) -> tuple:
    keys = ("inv_mass_a", "inv_mass_b", "inv_inertia_a", "inv_inertia_b", "arm_a", "arm_b")
    return tuple(b[k] for k in keys)


def test_a_solid_ball_on_a_plane_has_masses_m_then_two_sevenths_m_then_its_inertia():
    # m = 2 kg, r = 0.5 m: I = 2/5·m·r² = 0.2; against a plane (no inverse mass or inertia, no arm)
    # m_t = 1/(1/m + r²/I) = m/(1 + 5/2) = 2m/7, the mass a rolling ball's friction sees.
    m_n, m_t, m_r = contact_model.effective_masses(
        np.array([0.5]), np.zeros(1), np.array([5.0]), np.zeros(1), np.array([0.5]), np.zeros(1)
    )
    assert m_n[0] == 2.0 and m_t[0] == pytest.approx(4 / 7, rel=1e-15) and m_r[0] == pytest.approx(0.2)


def test_spin_never_changes_a_spheres_normal_speed():
    b = two_balls()
    spun = {**b, "w_a": b["w_a"] + 10.0, "w_b": b["w_b"] - 3.0}
    normal = (velocity(b) * b["n"]).sum(axis=0)
    assert np.allclose((velocity(spun) * b["n"]).sum(axis=0), normal, atol=1e-12)
    assert np.array_equal(
        contact_model.normal_speed(b["v_a"], b["v_b"], b["n"]),
        contact_model.normal_speed(spun["v_a"], spun["v_b"], b["n"]),
    )


def test_a_normal_impulse_meets_its_target_speed_when_it_pushes_and_never_pulls():
    b = two_balls()
    v_n = contact_model.normal_speed(b["v_a"], b["v_b"], b["n"])
    m_n = contact_model.effective_masses(*masses(b))[0]
    target = np.full(len(v_n), 0.25)
    p = contact_model.normal_impulse(np.zeros(len(v_n)), m_n, target, v_n)
    after = applied(b, p, np.zeros_like(b["n"]), np.zeros_like(b["n"]))
    pushes = p > 0.0
    assert pushes.any() and not pushes.all()
    speed = contact_model.normal_speed(after["v_a"], after["v_b"], b["n"])
    assert np.allclose(speed[pushes], 0.25, atol=1e-12)
    assert np.all(speed[~pushes] >= 0.25)  # already leaving faster: no pull holds it back
    assert np.all(p >= 0.0)


def test_the_stick_impulses_stop_both_the_slip_and_the_relative_spin_in_one_block():
    b = two_balls(seed=3)
    n = b["n"]
    contact = velocity(b)
    slip = contact - (contact * n).sum(axis=0) * n
    spin = b["w_a"] - b["w_b"]
    p, r = contact_model.stick(slip, spin, n, contact_model.stick_terms(*masses(b)))
    assert np.allclose((p * n).sum(axis=0), 0.0, atol=1e-12)  # friction lies in the tangent plane
    after = applied(b, np.zeros(n.shape[1]), p, r)
    contact = velocity(after)
    assert np.abs(contact - (contact * n).sum(axis=0) * n).max() < 1e-12
    assert np.abs(after["w_a"] - after["w_b"]).max() < 1e-12


def test_within_limit_scales_longer_impulses_onto_the_cone_and_leaves_shorter_ones():
    candidate = np.array([[3.0, 0.3], [4.0, 0.4], [0.0, 0.0]])  # lengths 5 and 0.5
    limited = contact_model.within_limit(candidate.copy(), np.array([1.0, 1.0]))
    assert limited[:, 0] == pytest.approx([0.6, 0.8, 0.0], rel=1e-15)
    assert np.array_equal(limited[:, 1], candidate[:, 1])


def test_an_overlap_is_shared_by_inverse_mass_and_a_plane_takes_none_of_it():
    part_a, part_b = contact_model.separation_parts(np.array([1.0, 0.5]), np.array([3.0, 0.0]))
    assert part_a.tolist() == [0.25, 1.0] and part_b.tolist() == [-0.75, -0.0]


def test_a_spring_of_no_frequency_is_rigid_and_a_stiff_one_tends_to_rigid():
    rigid = contact_model.softness(0.0, 1.0, 1 / 240)
    assert (rigid.bias_rate, rigid.mass_scale, rigid.impulse_scale) == (0.0, 1.0, 0.0)
    stiff = contact_model.softness(1e9, 1.0, 1 / 240)
    assert stiff.mass_scale == pytest.approx(1.0, abs=1e-9) and stiff.impulse_scale < 1e-9
    soft = contact_model.softness(30.0, 10.0, 1 / 240)
    assert soft.mass_scale + soft.impulse_scale == pytest.approx(1.0, rel=1e-15)  # a2·a3 + a3 = 1
