"""Steady-state detection (solver/steady.py) on synthetic probe series."""
import math

import numpy as np
import pytest

from solver.steady import Record, SteadyCriteria, SteadyDetector, judge, line_fits, trend

U_B, H_N, DT = 0.075, 0.0188, 0.02
NX, NS, NZ = 121, 3, 41
SURFACE = np.linspace(0.0, 1.0, NX) ** 0.3  # z / h_n over x*
PROFILE = np.tile(np.linspace(0.0, 1.5, NZ), (NS, 1))  # u* over z* at each station
CRIT = SteadyCriteria()  # the case defaults: W = steady.average, f = steady.fraction


def ar1(rng, n, sigma, r=0.5):
    """An AR(1) series of standard deviation sigma and lag-1 correlation r."""
    e = rng.normal(0.0, sigma, n)
    out = np.empty(n)
    out[0] = e[0]
    for k in range(1, n):
        out[k] = r * out[k - 1] + math.sqrt(1.0 - r * r) * e[k]
    return out


def series(T=12.0, seed=0, depth_drift=0.0, surface_drift=0.0, station_drift=0.0, toe_speed=0.0,
           depth_noise=3e-4) -> Record:
    """Probe series every DT with the noise of a dp = 1 mm run (measured: the uniform depth wanders
    by 0.02-0.06 % h_n with lag-1 correlation 0.94-0.98 at this interval): the uniform depth
    h_u / h_n (1.001, AR(1) noise of depth_noise h_n, r = 0.96, drift depth_drift h_n per s), the
    surface and the station profiles (noise 0.002 h_n and 0.01 u_b per component, r = 0.5 and
    white; drifts per s), the toe (0.4 m, noise 0.3 mm, r = 0.9, moving at toe_speed u_b)."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, T + 1e-9, DT)
    n = t.size
    depth = 1.001 + depth_drift * t + ar1(rng, n, depth_noise, 0.96)
    surface = SURFACE[None, :] + surface_drift * t[:, None] \
        + np.stack([ar1(rng, n, 0.002) for _ in range(NX)], axis=1)
    stations = PROFILE[None] + station_drift * t[:, None, None] + rng.normal(0.0, 0.01, (n, NS, NZ))
    toe = 0.4 + U_B * toe_speed * t + ar1(rng, n, 3e-4, 0.9)
    return Record(t, toe, depth, surface, stations)


def first_steady(rec: Record, crit=CRIT):
    """The detector fed sample by sample as the front monitor feeds it: the steady pair, or None."""
    det = SteadyDetector(crit)
    for k in range(rec.t.size):
        sub = Record(rec.t[:k + 1], rec.toe[:k + 1], rec.depth[:k + 1], rec.surface[:k + 1], rec.stations[:k + 1])
        if det.update(sub if k == 0 else sub.span(rec.t[k] - 2.0 * crit.window - crit.context - DT)):
            return det.found
    return None


def test_line_fit_errors_match_the_scatter_of_means_and_slopes():
    """line_fits' standard errors of the mean and the slope against their spread over 400
    series, for white and correlated (r = 0.8) noise: within a factor 0.7-1.5."""
    t = np.arange(0.0, 1.0 + 1e-9, DT)
    for r in (0.0, 0.8):
        rows = np.stack([ar1(np.random.default_rng(seed), t.size, 1.0, r) for seed in range(400)])
        mean, se_mean, slope, se_slope = line_fits(t, rows)
        assert 0.7 * np.std(mean) < np.median(se_mean) < 1.5 * np.std(mean), r
        assert 0.7 * np.std(slope) < np.median(se_slope) < 1.5 * np.std(slope), r
    assert abs(trend(t, 3.0 * t + 1.0) - 3.0) < 1e-12
    assert np.isnan(trend(t[:2], t[:2]))


def test_depth_drifting_by_0_05_percent_of_h_n_a_second_is_never_steady():
    """The uniform depth drifts by 0.05 % h_n a second for 12 s, everything else still: never
    steady, for 10 of 10 noise realisations."""
    for seed in range(10):
        assert first_steady(series(depth_drift=5e-4, seed=seed)) is None, seed


def test_flat_series_with_the_same_noise_is_steady():
    """No drift and the same noise: steady in 12 s for 10 of 10 realisations, the averaging
    window starting by 3 s (the first pair ends at 2W = 6 s)."""
    for seed in range(10):
        found = first_steady(series(seed=seed))
        assert found is not None and found.averaging[0] <= 3.0 + 1e-9, seed


@pytest.mark.parametrize("drift", [dict(surface_drift=5e-4), dict(station_drift=5e-3), dict(toe_speed=5e-3)])
def test_a_drifting_surface_station_or_toe_is_never_steady(drift):
    """The whole surface rising by 0.05 % h_n a second, a station profile by 0.5 % u_b a
    second, or the toe creeping at 0.5 % u_b: never steady in 12 s, for 5 of 5 realisations."""
    for seed in range(5):
        assert first_steady(series(seed=seed, **drift)) is None, (drift, seed)


def test_a_drift_below_the_fraction_of_its_value_passes_however_small_its_se():
    """Noise-free series: the depth drifting by half of steady.fraction of itself over a window
    passes (its se is 0); by 1.5 times that fraction it does not."""
    f, w = CRIT.fraction, CRIT.window
    rec = series(depth_noise=0.0, seed=1)
    rec.surface[:] = SURFACE[None, :]
    rec.stations[:] = PROFILE[None]
    rec.toe[:] = 0.4
    for k, ok in ((0.5, True), (1.5, False)):
        rec.depth = 1.001 * (1.0 + k * f * rec.t / w)
        j = judge(rec, 3.0 * w, CRIT)
        assert j.steady is ok, (k, j.ratios)


def test_window_pair_and_min_time():
    """The averaging window is [t - 2W, t - W] and its hold-out [t - W, t]; no pair ends before
    min_time + 2W."""
    found = first_steady(series(T=14.0, seed=3), SteadyCriteria(min_time=2.5))
    assert found is not None
    a0, a1 = found.averaging
    w = CRIT.window
    assert a0 >= 2.5 - 1e-9 and a1 == pytest.approx(a0 + w) and found.holdout == pytest.approx((a1, a1 + w))


def monitor_with(rec: Record, stop: bool):
    """A front monitor holding the probe series ``rec`` (its surface and velocity grids filled
    from it), for dataset() and why_not_steady()."""
    import yaml

    from solver.conveyor import case_from_dict
    from solver.front import FrontMonitor
    from tests.conftest import EXAMPLES
    with open(EXAMPLES / "conveyor.yaml") as fh:
        d = yaml.safe_load(fh)
    d.update(dp=0.004, ch=1.5)
    d["steady"].update(stop=stop, max_time=float(rec.t[-1]), average=1.0, min_time=0.0)
    m = FrontMonitor(case_from_dict(d))
    hn = m.case.h_n
    n = rec.t.size
    m.t = list(rec.t)
    surface = np.full((n, m.x_star.size), np.nan)
    zone = m.x_star <= m.case.probes.uniform_zone[1] + 1e-9  # the surface the detector watches
    surface[:, zone] = np.interp(np.linspace(0, 1, int(zone.sum())), np.linspace(0, 1, NX),
                                 SURFACE)[None, :] * hn + (rec.depth[:, None] - 1.001) * hn
    velocity = np.full((n, m.stations.size, m.z_star.size), 1.0)
    m.series = {"toe": list(rec.toe), "front_position": list(rec.toe), "front_equivalent": list(rec.toe),
                "uniform_depth": list(rec.depth * hn), "enclosed_area": [1.0] * n, "mass_area": [1.0] * n,
                "number_density": [1.0] * n}
    m.surface, m.velocity = list(surface), list(velocity)
    m.station_u = [np.ones(m.stations.size)] * n
    m.station_front = [np.full(m.stations.size, 0.385)] * n
    m.zone_enclosed = m.zone_mass = [np.ones(4)] * n
    m.disorder = [np.ones(3)] * n
    return m


def test_fixed_end_time_judges_the_final_pair_and_says_why():
    """steady.stop: false: the run averages [T - 2W, T - W] and holds out [T - W, T], steady
    only if that pair is; a depth that thins by 0.5 % h_n a second fails on the depth, and the
    reason names it."""
    still = monitor_with(series(T=4.0, seed=4), stop=False)
    ds = still.dataset()
    assert ds.attrs["steady"] == 1
    assert (ds.attrs["window_start_s"], ds.attrs["window_end_s"], ds.attrs["holdout_end_s"]) == \
        pytest.approx((2.0, 3.0, 4.0))
    t = np.asarray(still.t)
    mean = np.mean(np.asarray(still.series["uniform_depth"])[(t >= 2.0 - 1e-9) & (t <= 3.0 + 1e-9)])
    assert float(ds["mean_uniform_depth"]) == pytest.approx(mean, rel=1e-12)
    thin = monitor_with(series(T=4.0, seed=4, depth_drift=-5e-3), stop=False)
    ds = thin.dataset()
    assert ds.attrs["steady"] == 0 and ds.attrs["averaging"] == "final window, NOT steady"
    reason = thin.why_not_steady()
    assert "depth" in reason and "toe" not in reason, reason


def test_equivalent_front_moves_with_a_block_and_ignores_a_tip_particle():
    """x0 + area downstream / h_n of a lattice block of depth h_n ending at L is L (to 0.01 dp:
    the ramp over x0 +- h summed on the lattice); it moves by d when the block moves by d, and
    one particle joining the tip moves it by dp^2 / h_n."""
    from solver.front import equivalent_front
    dp, hn, h = 1e-3, 0.02, 1.8 * np.sqrt(2) * 1e-3
    xc, zc = np.meshgrid((np.arange(300) + 0.5) * dp, (np.arange(20) + 0.5) * dp)
    x, vol = xc.ravel(), np.full(xc.size, dp * dp)
    x0 = 0.2137
    base = equivalent_front(x, vol, x0, hn, h)
    assert base == pytest.approx(0.3, abs=0.01 * dp)
    for d in (0.37 * dp, 2.5 * dp):
        assert equivalent_front(x + d, vol, x0, hn, h) == pytest.approx(0.3 + d, abs=0.01 * dp)
    tip = equivalent_front(np.append(x, 0.3 + 0.5 * dp), np.append(vol, dp * dp), x0, hn, h)
    assert tip - base == pytest.approx(dp * dp / hn, rel=1e-9)


def test_strip_mean_velocity_of_the_film_is_the_depth_mean():
    """On a lattice layer of depth H carrying the belt-frame film profile
    u* = 3 (z/H - z^2 / 2H^2), the strip mean is its depth mean 1 (midpoint rule over the
    rows: error dp^2 |u''| / 24 = 0.0003 here); particles below the bed do not count."""
    from solver.front import strip_mean_velocity
    dp, H, h = 1e-3, 0.0186, 1.8 * np.sqrt(2) * 1e-3
    xc, zc = np.meshgrid((np.arange(100) + 0.5) * dp, (np.arange(round(H / dp)) + 0.5) * dp)
    x, z = xc.ravel(), zc.ravel()
    Hd = round(H / dp) * dp
    u_star = 3.0 * (z / Hd - z * z / (2 * Hd * Hd))
    vol = np.full(x.size, dp * dp)
    got = strip_mean_velocity(x, z, u_star, vol, np.array([0.0317, 0.05, 0.0712]), h)
    np.testing.assert_allclose(got, 1.0, atol=dp ** 2 * 3 / Hd ** 2 / 24 * 1.01)
    # a stray particle under the bed with a wild velocity is ignored
    got2 = strip_mean_velocity(np.append(x, 0.05), np.append(z, -0.5 * dp), np.append(u_star, 50.0),
                               np.append(vol, dp * dp), np.array([0.05]), h)
    assert got2[0] == pytest.approx(got[1], rel=1e-12)
    assert np.isnan(strip_mean_velocity(x, z, u_star, vol, np.array([1.0]), h)[0])
