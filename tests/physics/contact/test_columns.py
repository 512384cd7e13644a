"""The contacts as the Jacobi sweeps read them: each ball touched is one column, and a contact's normal
speed read from those columns is (v_a − v_b)·n, whether formed at once or a chunk at a time."""

import numpy as np
import pytest

from ballpit.physics.contact import columns
from ballpit.physics.contact.columns import ContactColumns
from ballpit.physics.contact.rows import ContactRows

R, M = 0.5, 2.0


def random_rows(k: int, n_balls: int, seed: int = 3) -> ContactRows:
    """``k`` contacts between ``n_balls`` balls of mass M, random unit normals; ball n_balls is a plane."""
    rng = np.random.default_rng(seed)
    a = rng.integers(0, n_balls, k)
    b = (a + 1 + rng.integers(0, n_balls, k)) % (n_balls + 1)  # never a ball against itself
    normal = rng.normal(size=(k, 3))
    normal /= np.sqrt((normal * normal).sum(axis=1))[:, None]
    plane = b == n_balls
    inv_mass, inv_inertia = 1 / M, 1 / (0.4 * M * R * R)
    return ContactRows(
        a=a,
        b=b,
        normal=normal,
        radius_a=np.full(k, R),
        radius_b=np.where(plane, 0.0, R),
        inv_mass_a=np.full(k, inv_mass),
        inv_mass_b=np.where(plane, 0.0, inv_mass),
        inv_inertia_a=np.full(k, inv_inertia),
        inv_inertia_b=np.where(plane, 0.0, inv_inertia),
        restitution=np.zeros(k),
        friction=np.full(k, 0.5),
        rolling=np.zeros(k),
        surface=np.zeros((k, 3)),
        spin=np.zeros((k, 3)),
        moving=False,
        static=n_balls,
    )


@pytest.mark.parametrize("chunk", [None, 4])
def test_normal_speeds_are_the_relative_velocity_along_each_normal(monkeypatch, chunk):
    rows = random_rows(k=23, n_balls=9)
    if chunk is not None:  # a chunk at a time, as a crowd's contacts are read
        monkeypatch.setattr(columns, "SWEEP_CHUNK", chunk)
    cols = ContactColumns(rows)
    velocity = np.random.default_rng(5).normal(size=(10, 3))  # ball 9 stands for the plane
    velocity[9] = 0.0
    v = velocity[cols.balls].T  # the (3, M) columns of the balls the contacts touch
    expected = ((velocity[rows.a] - velocity[rows.b]) * rows.normal).sum(axis=1)
    np.testing.assert_allclose(cols.normal_speeds(v), expected, rtol=0, atol=1e-12)


def test_every_contact_end_is_the_column_of_its_ball():
    rows = random_rows(k=15, n_balls=6)
    cols = ContactColumns(rows)
    k = cols.k
    assert list(cols.balls[cols.ends[:k]]) == list(rows.a)
    assert list(cols.balls[cols.ends[k:]]) == list(rows.b)
    np.testing.assert_array_equal(cols.n, rows.normal.T)
