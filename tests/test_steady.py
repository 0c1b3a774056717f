"""Steady-state detection on synthetic signals."""
import numpy as np

from solver.steady import SteadyCriteria, drifts, is_steady, trend

UB, HN = 0.075, 0.0188
CRIT = SteadyCriteria(window=1.0, front_velocity=0.01, depth=0.005, velocity=0.02, min_time=0.5)


def signals(t, tau=None, drift=0.0, noise=0.0, seed=0):
    """toe, depth, station u*: exponential approach with time constant tau (the toe only
    when it does not drift), a linear drift of the toe (m/s), and noise."""
    rng = np.random.default_rng(seed)
    approach = np.exp(-t / tau) if tau else 0.0 * t
    toe = (0.40 + (0.0 if drift else 0.02 * approach) + drift * t
           + noise * 1e-4 * rng.standard_normal(t.size))
    depth = HN * (1 - 0.05 * approach) + noise * 2e-5 * rng.standard_normal(t.size)
    u = np.stack([1.0 + 0.2 * approach, 1.1 + 0.1 * approach], axis=1)
    return toe, depth, u


def first_steady(t, toe, depth, u):
    for k in range(3, t.size + 1):
        if is_steady(t[:k], toe[:k], depth[:k], u[:k], CRIT, UB, HN):
            return t[k - 1]
    return None


def test_trend_is_least_squares_slope():
    t = np.linspace(0, 2, 50)
    assert abs(trend(t, 3.0 * t + 1.0) - 3.0) < 1e-12
    assert np.isnan(trend(t[:2], t[:2]))


def test_fires_on_converging_signal_and_not_before():
    t = np.arange(0, 10, 0.02)
    toe, depth, u = signals(t, tau=0.8, noise=1.0)
    ts = first_steady(t, toe, depth, u)
    assert ts is not None
    # toe speed 0.02/0.8 exp(-t/0.8) falls below 1 % u_b once t > 0.8 ln(0.025/0.00075) = 2.8 s,
    # judged over the trailing 1 s window
    assert 2.8 < ts < 5.0


def test_does_not_fire_on_drifting_front():
    t = np.arange(0, 10, 0.02)
    toe, depth, u = signals(t, tau=0.8, drift=0.02 * UB, noise=1.0)  # creeps at 2 % u_b
    assert first_steady(t, toe, depth, u) is None


def test_does_not_fire_on_thinning_layer():
    t = np.arange(0, 10, 0.02)
    toe, depth, u = signals(t, tau=0.5)
    depth = depth - 0.01 * HN * t  # thins by 1 % h_n per second
    assert first_steady(t, toe, depth, u) is None
    d = drifts(t, toe, depth, u, 1.0)
    assert abs(d["depth_change"] / HN + 0.01) < 1e-3


def test_window_must_be_filled_after_min_time():
    t = np.arange(0, 1.6, 0.02)
    toe, depth, u = signals(t)  # perfectly steady from the start
    ok = lambda k, crit=CRIT: is_steady(t[:k], toe[:k], depth[:k], u[:k], crit, UB, HN)  # noqa: E731
    assert not ok(50)  # t = 0.98: the 1 s window is not filled
    assert not ok(70)  # t = 1.38: the window would start before min_time = 0.5
    assert ok(80)  # t = 1.58
    assert not ok(80, SteadyCriteria(min_time=5.0))


def test_fixed_end_time_averages_the_final_window():
    """steady.stop: false: the run goes on to max_time and averages its final window, flagged
    steady when that window starts after steady state was detected; with the stop, the
    window starts at the detection."""
    import yaml

    from solver.conveyor import case_from_dict
    from solver.front import FrontMonitor
    from tests.conftest import EXAMPLES
    with open(EXAMPLES / "conveyor.yaml") as fh:
        d = yaml.safe_load(fh)
    d.update(dp=0.004, ch=1.5)

    def window(stop, t_steady):
        d["steady"].update(stop=stop, max_time=4.0, average=2.0)
        m = FrontMonitor(case_from_dict(d))
        m.t = list(np.arange(0.0, 4.0 + 1e-9, 0.02))
        depth = np.where(np.asarray(m.t) < 1.5, 0.010, 0.018)  # a step the window must see or not
        m.series = {"toe": [0.4] * len(m.t), "uniform_depth": list(depth), "enclosed_area": [1.0] * len(m.t),
                    "mass_area": [1.0] * len(m.t), "number_density": [1.0] * len(m.t)}
        m.surface = [np.zeros(m.x_star.size)] * len(m.t)
        m.velocity = [np.ones((m.stations.size, m.z_star.size))] * len(m.t)
        m.t_steady = t_steady
        ds = m.dataset()
        return ds.attrs["steady"], float(ds["mean_uniform_depth"])

    steady, depth = window(True, 1.0)  # window [1, 3]: a quarter of it before the step
    assert steady == 1 and abs(depth - (0.25 * 0.010 + 0.75 * 0.018)) < 2e-4
    steady, depth = window(False, 1.0)  # window [2, 4], after the detection
    assert steady == 1 and abs(depth - 0.018) < 1e-12
    steady, depth = window(False, 3.0)  # detected inside the final window: not steady
    assert steady == 0 and abs(depth - 0.018) < 1e-12
