"""Quintic Wendland (C2) kernel in 2D, support 2h.

W(q) = alpha (1 - q/2)^4 (2q + 1), q = r/h, alpha = 7 / (4 pi h^2).
gradW_ab = F(r) r_ab with F = -5 alpha / h^2 (1 - q/2)^3, so r_ab . gradW_ab = F r^2 < 0.
"""
import math

import numba as nb
import numpy as np

ETA2 = 0.01  # eta^2 / h^2: the regularisation r^2 + eta^2 of 1 / r^2 in the laminar and diffusion terms


@nb.njit(inline="always", cache=True)
def alpha_2d(h):
    """Normalisation alpha = 7 / (4 pi h^2) (the only place it is written)."""
    return 7.0 / (4.0 * math.pi * h * h)


@nb.njit(inline="always", cache=True)
def grad_coefficient(h):
    """fac = -5 alpha / h^2, so that gradW_ab = grad_factor(q, fac) r_ab."""
    return -5.0 * alpha_2d(h) / (h * h)


@nb.njit(inline="always", cache=True)
def w_value(q, alpha):
    s = 1.0 - 0.5 * q
    return alpha * s * s * s * s * (2.0 * q + 1.0)


@nb.njit(inline="always", cache=True)
def grad_factor(q, fac):
    """F such that gradW_ab = F r_ab; fac = -5 alpha / h^2."""
    s = 1.0 - 0.5 * q
    return fac * s * s * s


def kernel(r: np.ndarray, h: float) -> np.ndarray:
    """W(r) for an array of distances (zero beyond 2h)."""
    q = np.asarray(r, dtype=float) / h
    s = np.clip(1.0 - 0.5 * q, 0.0, None)
    return alpha_2d(h) * s ** 4 * (2.0 * q + 1.0)


def kernel_gradient(dx: np.ndarray, dz: np.ndarray, h: float):
    """gradW at displacement (dx, dz) = r_ab (zero beyond 2h)."""
    r = np.hypot(dx, dz)
    s = np.clip(1.0 - 0.5 * r / h, 0.0, None)
    F = grad_coefficient(h) * s ** 3
    return F * dx, F * dz
