"""Wendland C2 kernel: normalisation and gradient (docs/scheme.md section 6)."""
import numpy as np
import pytest

from solver.kernel import kernel, kernel_gradient


@pytest.mark.parametrize("h", [0.3, 1.0, 2.5e-3])
def test_kernel_integrates_to_one_in_2d(h):
    # radial quadrature: int_0^{2h} W(r) 2 pi r dr
    r = np.linspace(0.0, 2 * h, 200001)
    integral = np.trapezoid(kernel(r, h) * 2 * np.pi * r, r)
    assert integral == pytest.approx(1.0, abs=1e-8)


def test_kernel_vanishes_beyond_support():
    h = 0.7
    assert kernel(np.array([2 * h, 2.5 * h]), h).tolist() == [0.0, 0.0]


def test_gradient_matches_finite_differences():
    h = 1.3
    rng = np.random.default_rng(1)
    pts = rng.uniform(-2 * h, 2 * h, size=(200, 2))
    pts = pts[(np.hypot(*pts.T) < 1.95 * h) & (np.hypot(*pts.T) > 0.05 * h)]
    eps = 1e-6 * h
    gx, gz = kernel_gradient(pts[:, 0], pts[:, 1], h)
    x, z = pts[:, 0], pts[:, 1]
    fdx = (kernel(np.hypot(x + eps, z), h) - kernel(np.hypot(x - eps, z), h)) / (2 * eps)
    fdz = (kernel(np.hypot(x, z + eps), h) - kernel(np.hypot(x, z - eps), h)) / (2 * eps)
    scale = np.abs(fdx).max()
    np.testing.assert_allclose(gx, fdx, atol=1e-7 * scale)
    np.testing.assert_allclose(gz, fdz, atol=1e-7 * scale)
    # r_ab . gradW_ab < 0 inside the support
    assert np.all(pts[:, 0] * gx + pts[:, 1] * gz < 0)
