"""The standard error of a window mean and slope (solver/timeseries.py) against the known scatter
of synthetic series: AR(1) with correlation times 0.1, 1 and 5 s, and a slow wander (strong
or faint) under white noise, sampled as the probes are (0.02 s), a 3 s window read with the shipped context."""
import math

import numpy as np
import pytest

from benchmarks.window_metrics import DT, WINDOW, ar1
from solver.conveyor import Steady
from solver.timeseries import window_fits

SERIES = 1000  # the ratio's own scatter over this many series is about 3 %


def _ratios(y, n_context):
    t = np.arange(y.shape[1]) * DT
    m, se, b, sb = window_fits(t, y, n_context)
    return math.sqrt(np.mean(se ** 2)) / np.std(m), math.sqrt(np.mean(sb ** 2)) / np.std(b)


@pytest.mark.parametrize("tau", [0.1, 1.0, 5.0])
def test_se_of_window_mean_and_slope_is_calibrated(tau):
    """RMS reported se over the standard deviation of 1000 window means (and slopes): within
    0.7-1.4 at each correlation time, with steady.context s of samples before the window."""
    n_c, n_w = round(Steady().context / DT), round(WINDOW / DT)
    y = ar1(n_c + n_w, DT, tau, np.random.default_rng(11), SERIES)
    r_mean, r_slope = _ratios(y, n_c)
    assert 0.7 <= r_mean <= 1.4, r_mean
    assert 0.7 <= r_slope <= 1.4, r_slope


def test_slow_wander_under_white_noise_is_calibrated():
    """White noise (sd 0.5) over an AR(1) of 2 s: the se of the window mean within 0.7-1.4."""
    rng = np.random.default_rng(12)
    n_c, n_w = round(Steady().context / DT), round(WINDOW / DT)
    y = 0.5 * rng.standard_normal((SERIES, n_c + n_w)) + ar1(n_c + n_w, DT, 2.0, rng, SERIES)
    r_mean, r_slope = _ratios(y, n_c)
    assert 0.7 <= r_mean <= 1.4 and 0.7 <= r_slope <= 1.4, (r_mean, r_slope)


def test_a_faint_slow_wander_under_white_noise_reads_low():
    """White noise (sd 1) over 0.3 times an AR(1) of 3 s, a near-front velocity's make-up: the sum
    stops inside the noise's correlation and misses the wander's share, so the se of the window
    mean reads low (about 0.55; solver/timeseries.py states the limit), while the slope's holds."""
    rng = np.random.default_rng(15)
    n_c, n_w = round(Steady().context / DT), round(WINDOW / DT)
    y = rng.standard_normal((SERIES, n_c + n_w)) + 0.3 * ar1(n_c + n_w, DT, 3.0, rng, SERIES)
    r_mean, r_slope = _ratios(y, n_c)
    assert 0.4 <= r_mean <= 0.7 and 0.7 <= r_slope <= 1.4, (r_mean, r_slope)


def test_a_window_alone_cannot_see_a_correlation_as_long_as_itself():
    """Without a context the se of a 5 s-correlated series is far too small (below half): why the
    se reads the samples before the window."""
    n_w = round(WINDOW / DT)
    y = ar1(n_w, DT, 5.0, np.random.default_rng(13), SERIES)
    assert _ratios(y, 0)[0] < 0.5


def test_a_step_before_the_window_does_not_widen_its_se():
    """The autocovariance comes from the samples before the window when they hold a window's worth:
    a level that steps by 100 sd at the window's start leaves the window's se that of its noise."""
    rng = np.random.default_rng(14)
    n_w = round(WINDOW / DT)
    y = rng.standard_normal((200, 3 * n_w))
    y[:, 2 * n_w:] += 100.0
    _, se, _, _ = window_fits(np.arange(3 * n_w) * DT, y, 2 * n_w)
    assert math.sqrt(np.mean(se ** 2)) == pytest.approx(1 / math.sqrt(n_w), rel=0.3)


def test_degenerate_rows():
    """Fewer than 3 finite samples: NaN; a flat row: se 0; NaN samples are skipped."""
    t = np.arange(10) * DT
    y = np.vstack([np.full(10, np.nan), np.ones(10), np.r_[np.arange(5.0), np.nan, np.arange(4.0)]])
    m, se, b, sb = window_fits(t, y)
    assert np.isnan(m[0]) and np.isnan(se[0])
    assert m[1] == 1.0 and se[1] == 0.0 and sb[1] == 0.0
    assert np.isfinite(se[2])
