"""GCI and observed order on manufactured sequences; Pareto front on a small table."""
import numpy as np
import pytest

from study.convergence import gci
from study.pareto import cheapest_meeting, pareto_front


def test_second_order_sequence_is_recovered():
    h = np.array([4.0, 2.0, 1.0])
    r = gci(h, 1 + 0.1 * h ** 2)
    assert r.status == "monotone"
    assert r.order == pytest.approx(2.0, abs=1e-9)
    assert r.extrapolated == pytest.approx(1.0, abs=1e-12)
    # e_a = 0.3/1.1, GCI = 1.25 e_a / 3
    assert r.gci_fine == pytest.approx(1.25 * (0.3 / 1.1) / 3, rel=1e-9)


def test_non_constant_refinement_ratio():
    h = np.array([3.0, 2.0, 1.0])
    r = gci(h, 2 - 0.05 * h ** 1.5)
    assert r.order == pytest.approx(1.5, abs=1e-8)
    assert r.extrapolated == pytest.approx(2.0, abs=1e-9)


@pytest.mark.parametrize("order", [0.3, 1.0, 2.0, 4.0])
def test_finer_pair_refined_more(order):
    """dp = 2, 1.75, 1.25 (r32 = 1.14, r21 = 1.4): an exact power law gives eps21 / eps32 up to
    ln r21 / ln r32 = 2.52, above the constant-ratio bound of 1, and is still monotone."""
    h = np.array([2.0, 1.75, 1.25])
    r = gci(h, 0.01 + 0.02 * h ** order)
    assert r.status == "monotone"
    assert r.order == pytest.approx(order, rel=1e-8)
    assert r.extrapolated == pytest.approx(0.01, abs=1e-9)


def test_no_positive_order_fits_on_a_non_constant_ratio():
    """dp = 2, 1.75, 1.25 and values 2.4, 2.3, 2.0: eps21 / eps32 = 3 exceeds ln r21 / ln r32,
    the p -> 0 limit, so no power law with p > 0 passes through them."""
    assert gci([2.0, 1.75, 1.25], [2.4, 2.3, 2.0]).status == "divergent"


def test_oscillatory_and_divergent_are_flagged():
    h = np.array([4.0, 2.0, 1.0])
    assert gci(h, [1.2, 0.9, 1.05]).status == "oscillatory"
    assert np.isnan(gci(h, [1.2, 0.9, 1.05]).order)
    assert gci(h, [1.0, 1.1, 1.5]).status == "divergent"
    assert gci(h[:2], [1.0, 1.1]).status == "insufficient"
    assert gci([2.0, 1.0, 1.0], [1.3, 1.1, 1.0]).status == "insufficient"  # one resolution twice


def test_pareto_front_and_cheapest():
    cost = [1, 2, 3, 4, 5, np.nan]
    err = [0.5, 0.6, 0.2, 0.25, 0.1, 0.01]
    assert pareto_front(cost, err).tolist() == [True, False, True, False, True, False]
    assert cheapest_meeting(cost, err, 0.3) == 2
    assert cheapest_meeting(cost, err, 0.05) is None
