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


def test_oscillatory_and_divergent_are_flagged():
    h = np.array([4.0, 2.0, 1.0])
    assert gci(h, [1.2, 0.9, 1.05]).status == "oscillatory"
    assert np.isnan(gci(h, [1.2, 0.9, 1.05]).order)
    assert gci(h, [1.0, 1.1, 1.5]).status == "divergent"
    assert gci(h[:2], [1.0, 1.1]).status == "insufficient"


def test_pareto_front_and_cheapest():
    cost = [1, 2, 3, 4, 5, np.nan]
    err = [0.5, 0.6, 0.2, 0.25, 0.1, 0.01]
    assert pareto_front(cost, err).tolist() == [True, False, True, False, True, False]
    assert cheapest_meeting(cost, err, 0.3) == 2
    assert cheapest_meeting(cost, err, 0.05) is None
