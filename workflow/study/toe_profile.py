"""What zeta_u at the stations near the toe measures: a front run's velocity profiles against
lubrication theory, against the parabola on the run's own local depth, and the theory's own
second-order long-wave correction.

docs/scheme.md section 5's reference at station x* (measured upslope from the toe) is the parabola
u* = 3 (z/h - z^2 / (2 h^2)) on the theory's depth h(x*). For each run and station this prints

- the run's mean depth at the station (its ``mean_surface_elevation``) against the theory's, and
  the x* at which the theory has the run's depth: how far the run's front sits from the
  theory's for the same body (its toe is its foremost particle);
- the RMS of u* - reference over the reference's heights (zeta_u, as the campaign computes it)
  and over the heights below the run's depth with the parabola on that depth instead;
- the profile at a few heights.

``--theory`` prints the lubrication profile's second-order long-wave correction at the stations
(no run needed). Steady Stokes flow in the frame of the front, x downslope, z normal to the
belt, h_n = u_b = 1, the belt at u = -1, zero net flux through every section; with the leading
order u0 = -1 + 3 (s - s^2 / 2), s = z / h(x), and w0 = -int_0^z u0_x dz, the next terms of
the slow-variation expansion are O(h_x^2, h h_xx):
  p1 / mu = -u0_x (z-momentum, with the normal-stress condition p1(h) = 2 mu w0_z(h) = 0),
  v_zz = p1_x / mu - u0_xx, v(0) = 0, v_z(h) = -w0_x(h) (tangential stress),
and the profile is u* = 3 (1 - V / h) (s - s^2 / 2) + v, V = int_0^h v dz (flux zero). The
x-derivatives at fixed z are central differences of the exact lubrication front
(xi tan(theta) / h_n = atanh(eta) - eta). Inertia's first-order term (Re h_x) is printed
beside it: Re = u_b h_n / nu = 0.35 for the paper's fluid.

    python -m study.toe_profile RUN.nc [RUN.nc ...] [--theory]
"""
from __future__ import annotations

import argparse

import numpy as np
import xarray as xr

from solver import lubrication

SLOPE = np.radians(15.3)
HEIGHTS = (0.05, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6)


def eta_of_xi(xi: float) -> float:
    """The lubrication front's depth eta = h / h_n at xi = x* upslope from the toe."""
    return lubrication.front_eta(xi, SLOPE)


def _cumulative(y: np.ndarray, x: np.ndarray) -> np.ndarray:
    return np.concatenate([[0.0], np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))])


def second_order_profile(x_star: float, nz: int = 2001, dx: float = 1e-3) -> tuple[np.ndarray, np.ndarray]:
    """(s, du*): the second-order long-wave correction of the belt-frame profile at station
    x_star, on s = z / h in [0, 1] (module docstring)."""
    h = lambda x: eta_of_xi(-x)  # noqa: E731  (x downslope, the toe at x = 0)
    x0 = -x_star
    H = h(x0)
    s = np.linspace(0.0, 1.0, nz)
    z = s * H

    def u0(x):
        q = z / h(x)
        return -1.0 + 3.0 * (q - q ** 2 / 2)

    def u0_x(x):
        return (u0(x + dx) - u0(x - dx)) / (2 * dx)

    def w0_surface(x):
        hx = (h(x + dx) - h(x - dx)) / (2 * dx)
        q = H / h(x)
        return 3.0 * hx * (q ** 2 / 2 - q ** 3 / 3)

    u0_xx = (u0(x0 + dx) - 2 * u0(x0) + u0(x0 - dx)) / dx ** 2
    p1_x = (-u0_x(x0 + dx) + u0_x(x0 - dx)) / (2 * dx)
    w0_x_surface = (w0_surface(x0 + dx) - w0_surface(x0 - dx)) / (2 * dx)
    forcing = _cumulative(p1_x - u0_xx, z)
    v_z = forcing - forcing[-1] - w0_x_surface
    v = _cumulative(v_z, z)
    V = np.trapezoid(v, z)
    return s, 3.0 * (1 - V / H) * (s - s ** 2 / 2) + v - 3.0 * (s - s ** 2 / 2)


def inertial_profile(x_star: float, reynolds: float, nz: int = 2001) -> tuple[np.ndarray, np.ndarray]:
    """(s, du*): inertia's first-order correction, Re_local h_x q(s) with q'' = f(s) the
    advective term of the leading-order flow, q(0) = 0, q'(1) = 0, flux zero."""
    P = np.polynomial.Polynomial
    q_ = P([0.0, 1.0])
    f = -3 * q_ * (1 - q_) * (-1 + 3 * q_ - 1.5 * q_ ** 2) + 9 * (1 - q_) * (q_ ** 2 / 2 - q_ ** 3 / 3)
    first = f.integ()
    q = (first - first(1.0)).integ()
    base = 3 * (q_ - q_ ** 2 / 2)
    dev = q - base * q.integ()(1.0)
    eta = eta_of_xi(x_star)
    h_x = -np.tan(SLOPE) * (1 - eta ** 2) / eta ** 2
    s = np.linspace(0.0, 1.0, nz)
    return s, reynolds * eta * h_x * dev(s)


def _rms(u: np.ndarray, ref: np.ndarray) -> float:
    m = np.isfinite(u) & np.isfinite(ref)
    return float(np.sqrt(np.mean((u[m] - ref[m]) ** 2)))


def run_report(path: str) -> None:
    with xr.open_dataset(path) as run:
        hn = float(run.attrs["h_n_m"])
        surface = run["mean_surface_elevation"] / hn
        velocity = run["mean_velocity_star"].load()
    print(path)
    for station in velocity["station"].values:
        depth = float(np.interp(station, surface["x_star"].values, surface.values))
        eta = eta_of_xi(station)
        u = velocity.sel(station=station)
        z = u["z_star"].values
        u = u.values
        theory = np.where(z <= eta, lubrication.belt_velocity(z / eta), np.nan)
        local = np.where(z <= depth, lubrication.belt_velocity(z / depth), np.nan)
        where = f"x* = {float(lubrication.xi_star(depth, SLOPE)):.3f}" if depth < 1.0 else "no x*: above h_n"
        print(f"  x* = {station}: depth {depth:.4f} h_n, theory {eta:.4f} (the theory has it at "
              f"{where}); RMS against the theory {_rms(u, theory):.4f}, against "
              f"the parabola on the run's depth {_rms(u, local):.4f}")
        if station < 2.0:
            for zz in HEIGHTS:
                k = int(np.argmin(abs(z - zz)))
                print(f"      z* {z[k]:.3f}: u* {u[k]:.4f}  theory {theory[k]:.4f}  on the run's depth {local[k]:.4f}")


def theory_report(reynolds: float) -> None:
    print(f"second-order long-wave and first-order inertial (Re = {reynolds:.3f}) corrections of the "
          "lubrication profile, du* at s = z / h:")
    for station in (0.76, 1.5, 9.7):
        for name, (s, d) in (("second order", second_order_profile(station)),
                             ("inertia", inertial_profile(station, reynolds))):
            at = " / ".join(f"{d[int(round(k * (len(s) - 1)))]:+.4f}" for k in (0.1, 0.25, 0.5, 0.75, 1.0))
            print(f"  x* = {station:5}: {name:12s} at s 0.1 / 0.25 / 0.5 / 0.75 / 1: {at}; "
                  f"RMS {np.sqrt(np.mean(d ** 2)):.4f}")


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="*")
    ap.add_argument("--theory", action="store_true", help="print the theory's own corrections")
    ap.add_argument("--reynolds", type=float, default=0.075 * 0.018760 / (5.6 / 1383.0),
                    help="u_b h_n / nu (default: the paper's case)")
    a = ap.parse_args(argv)
    if a.theory:
        theory_report(a.reynolds)
    for path in a.runs:
        run_report(path)


if __name__ == "__main__":
    main()
