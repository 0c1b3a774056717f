"""The front run's volume budget and film-profile fit (pure functions, no SPH)."""
import numpy as np

from solver.film_fit import fit_film_profile
from solver.front import WALL_ZONE, ZONES, zone_budget


def test_zone_budget_splits_area_and_mass_at_the_zone_edges():
    """A rectangle of depth 0.5 from the wall (x = 0) to the toe x = 10 (h_n = 1), front
    length 3: wall [0, 2], body [2, 7], front [7, 10]; particles of volume 0.01 on a lattice,
    plus two inside the walls."""
    h_n, toe = 1.0, 10.0
    xs = np.arange(0.05, 10.0, 0.1)
    zs = np.full(xs.size, 0.5)
    gx, gz = np.meshgrid(np.arange(0.05, 10.0, 0.1), np.arange(0.05, 0.5, 0.1))
    x = np.concatenate([gx.ravel(), [-0.02, 4.0]])
    z = np.concatenate([gz.ravel(), [0.2, -0.01]])
    vol = np.full(x.size, 0.01)
    enclosed, mass = zone_budget(x, z, vol, xs, zs, toe, h_n, 3.0)
    assert list(ZONES) == ["wall", "body", "front", "in_walls"] and WALL_ZONE == 2.0
    # the surface falls from 0.5 to 0 over the last half step before the toe
    np.testing.assert_allclose(enclosed, [1.0, 2.5, 1.5 - 0.5 * 0.05 * 0.5, 0.0], atol=1e-12)
    np.testing.assert_allclose(mass, [20 * 5 * 0.01, 50 * 5 * 0.01, 30 * 5 * 0.01, 0.02], atol=1e-12)


def test_film_fit_recovers_viscosity_and_slip_and_rejects_too_few_points():
    z = np.arange(0.0, 1.3, 0.025)
    h = 0.96
    u = np.where(z <= h, 3.0 / 0.93 * (h * z - z * z / 2) + 0.04, np.nan)
    nu, slip = fit_film_profile(z, u, h, 0.1)
    assert abs(nu - 0.93) < 1e-9 and abs(slip - 0.04) < 1e-9
    assert np.isnan(fit_film_profile(z, u, 0.2, 0.1)[0])  # too thin for 5 points
