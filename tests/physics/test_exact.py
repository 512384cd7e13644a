"""physics/exact.py: sines and cosines from +, − and × within 1 ulp, and sums in the order they say."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ballpit.physics.core import exact


def _ulps(got: np.ndarray, want: np.ndarray) -> np.ndarray:
    return np.abs(got - want) / np.spacing(np.maximum(np.abs(want), 1e-300))


@pytest.mark.parametrize("span", [1e-6, 0.5, math.pi, 100.0, 1e5])
def test_sin_and_cos_are_within_one_ulp_of_the_c_library(span):
    x = np.random.default_rng(7).uniform(-span, span, 20_000)
    sin, cos = exact.sin_cos(x)
    # The C library's answers are within 0.55 ulp of the true values (glibc's documented bound).
    assert _ulps(sin, np.array([math.sin(v) for v in x])).max() <= 1.0
    assert _ulps(cos, np.array([math.cos(v) for v in x])).max() <= 1.0


def test_sin_and_cos_at_exact_angles():
    x = np.array([0.0, -0.0, math.pi / 6, math.pi / 2, math.pi, 1.5 * math.pi, -math.pi / 2, 5e-324])
    sin, cos = exact.sin_cos(x)
    assert sin[0] == 0.0 and not math.copysign(1.0, sin[0]) < 0
    assert sin[1] == 0.0 and math.copysign(1.0, sin[1]) < 0  # sin(−0) = −0
    assert cos[0] == cos[1] == 1.0
    assert (sin[2], cos[2]) == (math.sin(math.pi / 6), math.cos(math.pi / 6))  # 0.49999999999999994
    assert (sin[3], sin[4], sin[5], sin[6]) == (1.0, math.sin(math.pi), -1.0, -1.0)
    assert cos[4] == -1.0 and abs(cos[3]) < 1e-16 and abs(cos[5]) < 1e-15
    assert sin[7] == 5e-324 and cos[7] == 1.0
    s, c = exact.sin_cos(np.linspace(-40, 40, 1001))
    assert np.abs(s * s + c * c - 1.0).max() <= 4e-16


def test_huge_angles_are_taken_modulo_two_pi_first():
    x = np.array([1e7, -3e12, 1e300])
    sin, cos = exact.sin_cos(x)
    assert np.abs(sin * sin + cos * cos - 1.0).max() <= 4e-16
    # within the angles' own spacing of the true values (1e7 rad: 2e-9 rad apart)
    assert abs(sin[0] - math.sin(1e7)) < 1e-8 and abs(cos[0] - math.cos(1e7)) < 1e-8


def test_dot_and_norm_sum_from_first_to_last():
    # 1 + 2⁻⁵³ rounds to 1 and so does the next + 2⁻⁵³: summed first to last the tiny terms vanish,
    # and summed the other way round they would not.
    a = np.array([1.0, 2.0**-53, 2.0**-53])
    assert exact.dot_rows(a, np.ones(3)) == 1.0
    assert exact.dot_rows(a[::-1], np.ones(3)) == 1.0 + 2.0**-52
    rows = np.random.default_rng(1).normal(size=(1000, 3))
    assert np.array_equal(exact.norm_rows(rows), np.linalg.norm(rows, axis=1))  # NumPy's order over rows
    assert exact.norm_rows(np.array([3.0, 4.0, 12.0])) == 13.0


def test_total_adds_from_first_to_last():
    assert exact.total(np.array([1.0, 2.0**-53, 2.0**-53])) == 1.0
    assert exact.total(np.array([2.0**-53, 2.0**-53, 1.0])) == 1.0 + 2.0**-52
    assert exact.total(np.zeros(0)) == 0.0


def test_cross_gives_the_bits_of_numpy_cross_for_every_broadcast():
    rng = np.random.default_rng(11)
    for shape_p, shape_q in [((500, 3), (500, 3)), ((3,), (3, 3)), ((500, 3), (3,)), ((4, 1, 3), (1, 6, 3))]:
        p = rng.standard_normal(shape_p) * rng.choice([0.0, -0.0, 1.0, 1e-300, 1e300], size=shape_p)
        q = rng.standard_normal(shape_q) * rng.choice([0.0, -0.0, 1.0, 3.0], size=shape_q)
        got = exact.cross_rows(p, q)
        assert got.shape == np.cross(p, q).shape
        assert got.tobytes() == np.cross(p, q).tobytes()


def test_the_column_layout_gives_the_bits_of_the_row_layout():
    # (3, K) columns and (K, 3) rows of the same vectors: the same sums in the same order
    rng = np.random.default_rng(5)
    a, b = rng.standard_normal((200, 3)) * 1e3, rng.standard_normal((200, 3))
    assert exact.dot_cols(a.T, b.T).tobytes() == exact.dot_rows(a, b).tobytes()
    assert exact.norm_cols(a.T).tobytes() == exact.norm_rows(a).tobytes()
    scratch, out = np.empty((3, 200)), np.empty(200)
    assert exact.norm_cols(np.ascontiguousarray(a.T), scratch, out).tobytes() == exact.norm_rows(a).tobytes()
    assert exact.cross_cols(a.T, b.T).tobytes() == np.ascontiguousarray(exact.cross_rows(a, b).T).tobytes()
    column = np.array([1.0, 2.0**-53, 2.0**-53])[:, None]
    assert exact.dot_cols(column, np.ones((3, 1)))[0] == 1.0  # first to last, as dot_rows


def test_a_correctly_rounded_total_does_not_depend_on_the_order():
    x = np.array([1.0, 2.0**-53, 2.0**-53])
    assert exact.correctly_rounded_total(x) == exact.correctly_rounded_total(x[::-1]) == 1.0 + 2.0**-52
    assert exact.total(x) == 1.0  # one addition at a time loses the small terms
