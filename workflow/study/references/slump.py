"""A 2D gravity current from a rectangular release on a horizontal no-slip bed (docs/flow-slump.md).

The release, height H0 and length L0, rests against a free-slip end wall at x = 0, the
symmetry plane of a two-sided release; A = H0 L0 is the area per unit width of this half.
x is the distance from the wall, h(x, t) the depth, x_N(t) the front.

Newtonian fluid, kinematic viscosity nu. Lubrication theory (H. E. Huppert, J. Fluid Mech.
121, 1982, 43-58, the two-dimensional current of constant volume, alpha = 0):

  h_t = beta (h^3 h_x)_x,   beta = g / (3 nu),   h_x = 0 at x = 0,   int_0^x_N h dx = A.

Its similarity solution (derived in ``depth_profile``):

  x_N = eta_N (beta A^3 t)^(1/5),   h = (3 (x_N^2 - x^2) / (10 beta t))^(1/3),
  eta_N = (10/3)^(1/5) I^(-3/5),   I = int_0^1 (1 - s^2)^(1/3) ds = sqrt(pi) Gamma(4/3) / (2 Gamma(11/6)),

eta_N = 1.41124 (Huppert's 1.411).

Yield-stress fluid (Bingham or Herschel-Bulkley, yield stress tau_y, density rho,
l = tau_y / (rho g)): the current stops where the weight no longer exceeds the yield stress,
rho g h |h_x| <= tau_y (lubrication limit), which leaves h^2 = 2 l (x_N - x) behind the front,
whatever the consistency and index. Its relative error is of order l / h. A perfectly plastic
layer that has yielded throughout carries a longitudinal deviatoric stress as well; with it
(``final_shape_corrected``) the shape is h^2 - pi l h = 2 l (x_N - x), which carries the
O(l / h) correction of the slope that the lubrication limit leaves out.
"""
from __future__ import annotations

import math

import numpy as np

# I = int_0^1 (1 - s^2)^(1/3) ds = B(1/2, 4/3) / 2
PROFILE_INTEGRAL = math.sqrt(math.pi) * math.gamma(4.0 / 3.0) / (2.0 * math.gamma(11.0 / 6.0))
ETA_N = (10.0 / 3.0) ** 0.2 * PROFILE_INTEGRAL ** -0.6
SIMILARITY_EXPONENT = 0.2

# virtual time origin of the front from a rectangular release, in units of L0^2 / (beta H0^3):
# the lubrication equation solved from the rectangle (600 cells over 3 L0, BDF2 with 200 steps a
# decade, converged to the digits given) has its front within 0.3 % of
# eta_N (beta A^3 (t + t_v))^(1/5) past t = 0.3, with t_v = 0.2967 +- 0.0003 for 1 <= t <= 10
# (tests/test_flow_references.py re-derives it to 3 % on 150 cells)
RECTANGLE_TIME_SHIFT = 0.297


def spreading_rate(nu: float, g: float) -> float:
    """beta = g / (3 nu), the coefficient of h_t = beta (h^3 h_x)_x (Huppert 1982, whose g' is g
    for a current under air)."""
    return g / (3.0 * nu)


def front_position(t, A: float, nu: float, g: float):
    """Similarity front x_N = eta_N (g A^3 t / (3 nu))^(1/5) (Huppert 1982, 2D, alpha = 0),
    eta_N = ``ETA_N`` = 1.41124."""
    t = np.asarray(t, dtype=float)
    return ETA_N * (spreading_rate(nu, g) * A ** 3 * t) ** SIMILARITY_EXPONENT


def depth_profile(x, t: float, A: float, nu: float, g: float):
    """Similarity depth h(x, t) = (3 (x_N^2 - x^2) / (10 beta t))^(1/3)
    = (9 nu x_N^2 / (10 g t))^(1/3) (1 - (x/x_N)^2)^(1/3) for |x| <= x_N, 0 beyond.

    Derivation: with x_N proportional to t^(1/5) the current stretches uniformly, so the
    depth-averaged velocity is u = x x_N' / x_N = x / (5 t); lubrication gives
    u = -beta h^2 h_x, so (h^3)_x = -3 x / (5 beta t) and h^3 = 3 (x_N^2 - x^2) / (10 beta t),
    zero at the front. The volume int_0^x_N h dx = A then fixes x_N = ``front_position``.
    Symmetric in x (the two-sided release)."""
    x = np.abs(np.asarray(x, dtype=float))
    xn = front_position(t, A, nu, g)
    return np.cbrt(3.0 * np.maximum(xn * xn - x * x, 0.0) / (10.0 * spreading_rate(nu, g) * t))


def fit_front_exponent(t, x_front, interval=(0.0, math.inf)) -> tuple[float, float]:
    """(b, se) of the least-squares line ln x_N = a + b ln t over the samples with t in the
    closed ``interval`` and t, x_N > 0 finite; se from the residuals' autocorrelation as every
    fitted trend of the project (solver.steady.trend_bound). The similarity solution
    has b = 1/5; a front x_N = c (t + t_v)^(1/5) has the local exponent t / (5 (t + t_v)),
    within 1 % of 1/5 only past ``exponent_time``. NaN, NaN with fewer than 3 samples."""
    from solver.steady import trend_bound
    t = np.asarray(t, dtype=float)
    x = np.asarray(x_front, dtype=float)
    ok = np.isfinite(t) & np.isfinite(x) & (t > 0) & (x > 0) & (t >= interval[0]) & (t <= interval[1])
    if ok.sum() < 3:
        return float("nan"), float("nan")
    return trend_bound(np.log(t[ok]), np.log(x[ok]))


def memory_time(L0: float, A: float, nu: float, g: float, fraction: float = 0.01) -> float:
    """The time past which the front from a rectangular release (length L0, area A, height
    H0 = A / L0) is within ``fraction`` of the similarity front ``front_position``.

    After T. V. Ball and H. E. Huppert ("Similarity solutions and viscous gravity current
    adjustment times", J. Fluid Mech., 2019), who measure the approach by the relative front
    difference p between the solution from a given initial shape and the similarity solution.
    Scaled by L0, H0 and L0^2 / (beta H0^3), the lubrication equation from the rectangle has no
    parameter left; its front is x_N = eta_N (beta A^3 (t + t_v))^(1/5) with
    t_v = ``RECTANGLE_TIME_SHIFT`` L0^2 / (beta H0^3), found numerically (module constant).
    Then p = (1 + t_v / t)^(1/5) - 1, so

      t_m = t_v / ((1 + fraction)^5 - 1),

    1 %: t_m = 5.8 L0^2 / (beta H0^3), where the similarity front is at 2.0 L0; 5 %: 1.1, at
    1.43 L0: the criterion x_N >= 2 L0 is the 1 % criterion. This is lubrication theory from
    the start; a release that is not shallow (H0 not much less than L0) first collapses under
    forces it leaves out, and for it t_m is an estimate of the order only."""
    H0 = A / L0
    t_v = RECTANGLE_TIME_SHIFT * L0 * L0 / (spreading_rate(nu, g) * H0 ** 3)
    return t_v / ((1.0 + fraction) ** 5 - 1.0)


def exponent_time(L0: float, A: float, nu: float, g: float, fraction: float = 0.01) -> float:
    """The time past which the front from a rectangular release (as ``memory_time``) advances
    with a local exponent d ln x_N / d ln t = t / (5 (t + t_v)) within ``fraction`` of 1/5:
    t_e = t_v (1 - fraction) / fraction. 1 %: t_e = 29 L0^2 / (beta H0^3), where the similarity
    front is at 2.8 L0, five times ``memory_time``(0.01): a fitted exponent (``fit_front_exponent``)
    needs a later interval than the front itself."""
    H0 = A / L0
    t_v = RECTANGLE_TIME_SHIFT * L0 * L0 / (spreading_rate(nu, g) * H0 ** 3)
    return t_v * (1.0 - fraction) / fraction


def final_shape(x, x_N: float, tau_y: float, rho: float, g: float):
    """Arrested depth of a yield-stress current, h = sqrt(2 tau_y (x_N - x) / (rho g)) for
    |x| <= x_N, 0 beyond: the lubrication stopping condition rho g h |h_x| = tau_y integrated
    from h(x_N) = 0. The profile of a perfectly plastic layer (J. F. Nye, Proc. R. Soc. A 207,
    1951, for ice sheets; K. F. Liu and C. C. Mei, J. Fluid Mech. 207, 1989, for Bingham fluid;
    G. P. Matson and A. J. Hogg, J. Non-Newtonian Fluid Mech. 142, 2007, 79-94, for the arrested
    dam break of Herschel-Bulkley fluid). Independent of the consistency and the index.
    Symmetric in x."""
    x = np.abs(np.asarray(x, dtype=float))
    return np.sqrt(2.0 * tau_y * np.maximum(x_N - x, 0.0) / (rho * g))


def final_runout(A: float, tau_y: float, rho: float, g: float) -> float:
    """Front x_N of the arrested current of area A when it has ``final_shape`` all the way to
    the wall: A = int_0^x_N h dx = (2/3) sqrt(2 tau_y / (rho g)) x_N^(3/2), so
    x_N = (9 A^2 rho g / (8 tau_y))^(1/3). Its depth at the wall is (3 A tau_y / (rho g))^(1/3);
    a release lower than that does not yield at the wall (``release_runout``)."""
    return (9.0 * A * A * rho * g / (8.0 * tau_y)) ** (1.0 / 3.0)


def release_runout(H0: float, L0: float, tau_y: float, rho: float, g: float) -> float:
    """Arrested front of a rectangular release (height H0, length L0) in the lubrication limit.

    Where the surface is flat the fluid is unyielded, so fluid near the wall moves only once
    the slumping front has lowered it. If H0^3 >= 3 A tau_y / (rho g) (A = H0 L0) the whole
    release yields and x_N = ``final_runout``(A); otherwise a plateau h = H0 stays at the wall
    up to x_1 = L0 - rho g H0^2 / (3 tau_y), ``final_shape`` beyond it, and the volume
    gives x_N = L0 + rho g H0^2 / (6 tau_y). Both give x_N = 1.5 L0 at H0^2 = 3 tau_y L0 / (rho g)."""
    if H0 ** 3 >= 3.0 * H0 * L0 * tau_y / (rho * g):
        return final_runout(H0 * L0, tau_y, rho, g)
    return L0 + rho * g * H0 * H0 / (6.0 * tau_y)


def release_shape(x, H0: float, L0: float, tau_y: float, rho: float, g: float):
    """Arrested depth of a rectangular release in the lubrication limit: ``final_shape`` through
    ``release_runout``, capped at H0 (the plateau that stays at the wall when the release does
    not yield there; where it does, the shape is below H0 everywhere and the cap does nothing)."""
    x_N = release_runout(H0, L0, tau_y, rho, g)
    return np.minimum(final_shape(x, x_N, tau_y, rho, g), H0)


# ---- beyond the lubrication limit: the plastic layer's longitudinal stress ----------------
# 2 int_0^h N dz with N = tau_y sqrt(1 - (1 - z/h)^2), the longitudinal deviatoric stress of the
# yielded layer, is (pi / 2) tau_y h: the balance -h_x (h - pi l / 2) = l, the front step pi l
FRONT_STEP = math.pi  # in units of l


def yield_length(tau_y: float, rho: float, g: float) -> float:
    """l = tau_y / (rho g), the length of the arrested shapes."""
    return tau_y / (rho * g)


def front_distance_corrected(h, tau_y: float, rho: float, g: float):
    """x_N - x at depth h of ``final_shape_corrected``: h^2 / (2 l) - pi h / 2; zero at the front
    step h = pi l."""
    h = np.asarray(h, dtype=float)
    ell = yield_length(tau_y, rho, g)
    return h * h / (2.0 * ell) - 0.5 * FRONT_STEP * h


def final_shape_corrected(x, x_N: float, tau_y: float, rho: float, g: float):
    """Arrested depth of a perfectly plastic layer beyond the lubrication limit,

      h^2 - pi l h = 2 l (x_N - x),   h = pi l / 2 + sqrt((pi l / 2)^2 + 2 l (x_N - |x|)),

    l = tau_y / (rho g), for |x| <= x_N, 0 beyond: a vertical front step of height pi l.

    The slope solves -h_x (h - pi l / 2) = l, the depth-integrated x-balance of a perfectly
    plastic layer that has yielded throughout, derived here (docs/flow-slump.md) under the
    assumptions of N. Dubash, N. J. Balmforth, A. C. Slim and S. Cochard, "What is the final
    shape of a viscoplastic slump?", J. Non-Newtonian Fluid Mech. 158, 2009, 91-100, who expand
    the same problem to third order in the aspect ratio (their equations were not at hand to
    compare term by term). With the bed shear tau_y and the surface free,
    d/dx int_0^h sigma_xx dz = tau_y; the shear stress is tau_y (1 - z/h) to leading order,
    so the von Mises (plane Tresca) yield condition leaves the longitudinal deviatoric stress
    N = (sigma_xx - sigma_zz) / 2 = tau_y sqrt(1 - (1 - z/h)^2), tensile where the layer
    extends, and int_0^h sigma_xx dz = -rho g h^2 / 2 + 2 int_0^h N dz = -rho g h^2 / 2
    + (pi / 2) tau_y h: the slope's O(l / h) correction to the lubrication limit (higher orders
    are not claimed). The expansion fails where h ~ l, at the front: there the
    shape is cut at the root h = pi l of its integral (a front step); the front region moves
    x_N by O(l) (``release_runout_corrected``). Tends to ``final_shape`` as l / h -> 0, the
    depth higher by pi l / 2 + O(l^2 / h). Symmetric in x."""
    x = np.abs(np.asarray(x, dtype=float))
    ell = yield_length(tau_y, rho, g)
    c = 0.5 * FRONT_STEP * ell
    h = c + np.sqrt(c * c + 2.0 * ell * np.maximum(x_N - x, 0.0))
    return np.where(x <= x_N, h, 0.0)


def _area_corrected(h: float, tau_y: float, rho: float, g: float) -> float:
    """int h dx of ``final_shape_corrected`` from the front to where its depth is h:
    int_{pi l}^h s (s / l - pi / 2) ds = h^3 / (3 l) - pi h^2 / 4 - pi^3 l^2 / 12."""
    ell = yield_length(tau_y, rho, g)
    return h ** 3 / (3.0 * ell) - FRONT_STEP * h * h / 4.0 - FRONT_STEP ** 3 * ell * ell / 12.0


def release_runout_corrected(H0: float, L0: float, tau_y: float, rho: float, g: float) -> float:
    """Arrested front of a rectangular release (height H0, length L0, area A = H0 L0) with
    ``final_shape_corrected``, from the volume.

    As ``release_runout``: if the shape through the front that holds A is no deeper than H0 at
    the wall (``_area_corrected``(H0) >= A), the whole release yields: its depth h_w at the wall
    solves h_w^3 / (3 l) - pi h_w^2 / 4 - pi^3 l^2 / 12 = A and x_N = h_w^2 / (2 l) - pi h_w / 2.
    Otherwise a plateau h = H0 stays at the wall up to x_1 = L0 - ``_area_corrected``(H0) / H0 and
    x_N = x_1 + H0^2 / (2 l) - pi H0 / 2. Both give the same x_N where the plateau appears. A
    release no higher than the front step pi l does not move (x_N = L0).

    The front region (h ~ l), where the expansion fails, is replaced by the step at h = pi l;
    another rule there moves x_N by O(l): cutting the shape at its vertical tangent h = pi l / 2
    instead puts the front of the shipped release (H0 = 50 mm, L0 = 100 mm, l = 1.25 mm) 1.4 mm
    (0.5 %) farther than the 261.0 mm here, against 282.1 mm in the lubrication limit."""
    ell = yield_length(tau_y, rho, g)
    A = H0 * L0
    h_f = FRONT_STEP * ell
    if H0 <= h_f:
        return L0
    a_H0 = _area_corrected(H0, tau_y, rho, g)
    if a_H0 < A:  # the wall keeps its plateau
        return L0 - a_H0 / H0 + float(front_distance_corrected(H0, tau_y, rho, g))
    lo, hi = h_f, H0  # the area rises with h above pi l / 2: bisect
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if _area_corrected(mid, tau_y, rho, g) < A:
            lo = mid
        else:
            hi = mid
        if hi - lo <= 1e-15 * hi:
            break
    return float(front_distance_corrected(0.5 * (lo + hi), tau_y, rho, g))


def release_shape_corrected(x, H0: float, L0: float, tau_y: float, rho: float, g: float):
    """Arrested depth of a rectangular release with the plastic correction:
    ``final_shape_corrected`` through ``release_runout_corrected``, capped at H0 (the plateau, or
    the whole release where it is no higher than pi l)."""
    x_N = release_runout_corrected(H0, L0, tau_y, rho, g)
    return np.minimum(final_shape_corrected(x, x_N, tau_y, rho, g), H0)


def runout_ratio(H0: float, L0: float, tau_y: float, rho: float, g: float) -> float:
    """x_N / H0: the arrested front's distance from the end wall (``release_runout``) over the
    release height."""
    return release_runout(H0, L0, tau_y, rho, g) / H0


def spreads_five_heights(H0: float, L0: float, tau_y: float, rho: float, g: float) -> bool:
    """Whether the release spreads to at least 5 times its height: the arrested front's
    distance from the end wall is at least 5 H0 (``runout_ratio`` >= 5), the front having
    started at L0. The half-current is then at least 5 times as long as the release is high."""
    return runout_ratio(H0, L0, tau_y, rho, g) >= 5.0
