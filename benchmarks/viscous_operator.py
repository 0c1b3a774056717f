"""How well does the laminar viscous term of the pair loop reproduce nu u'' on the particle
arrangement a front run ends with? Reads front runs (NetCDF with a final snapshot) and, for
the fluid of the uniform zone (x* from 6 to 12), sets the exact belt-frame film velocity

    U(z) = (g sin theta / nu) (H z - z^2 / 2)     (H: the run's final uniform depth)

on every fluid particle (and its odd extension U(z) = (g sin theta / nu)(H z + z^2 / 2) on the
wall particles below z = 0, as the no-slip mDBC mirror gives), evaluates the term

    a_a = sum_b m_b 4 nu (r_ab.gradW_ab) / ((rho_a + rho_b)(r^2 + eta^2)) (U_a - U_b)

and prints its mean over bed rows (z < 2h), the interior and the surface rows (z > H - 2h) as
a fraction of the exact nu U'' = -g sin theta: the operator's effective nu / nu on that
arrangement, without and with the consistent laminar term's correction (minus 2 nu G . grad u
where div r >= 1.9, ``forces.correct_viscous_term``). The same for a square lattice of the same
depth. It also prints the interior
means of M_zz = -sum_b V_b F_ab z_ab^2 and h G_z = h sum_b V_b F_ab z_ab, which give the
operator's response by Taylor expansion: M_zz + 2 G_z U'/U'' with U'/U'' = -(H - z).
Masses are taken as rho0 dp^2 (the runs store densities, not masses: within 1 %).

    python benchmarks/viscous_operator.py RUN.nc [RUN.nc ...]
"""
from __future__ import annotations

import argparse
import math

import numpy as np
import xarray as xr
import yaml

from solver.conveyor import case_from_dict
from solver.forces import VISCOUS_CORRECTION_MIN_DIVR
from solver.kernel import grad_coefficient


def operator_response(x, z, kind, rho, mass, h, nu, g_s, depth, bands):
    """Mean and spread of a_a / (-g_s) over each band of particle indices."""
    def film(zz):
        return np.where(zz >= 0, g_s / nu * (depth * zz - zz * zz / 2), g_s / nu * (depth * zz + zz * zz / 2))

    u = film(z)
    fac = grad_coefficient(h)
    eta2 = 0.01 * h * h
    volume = mass / rho
    out = {}
    for name, idx in bands.items():
        acc, cor = [], []
        for a in idx:
            d2 = (x - x[a]) ** 2 + (z - z[a]) ** 2
            nb = np.flatnonzero((d2 < 4 * h * h) & (d2 > 0))
            r2 = d2[nb]
            F = fac * (1 - np.sqrt(r2) / h / 2) ** 3
            vt = 4 * nu * F * r2 / ((rho[a] + rho[nb]) * (r2 + eta2))
            raw = (mass[nb] * vt * (u[a] - u[nb])).sum()
            # the consistent laminar term (forces.correct_viscous_term): minus 2 nu G . grad u
            # where div r = -sum V F r^2 >= 1.9, G = sum V F r_ab, grad u = sum V (u_b - u_a) F r_ab
            dx, dz, V = x[a] - x[nb], z[a] - z[nb], volume[nb]
            if -(V * F * r2).sum() >= VISCOUS_CORRECTION_MIN_DIVR:
                gx, gz = (V * F * dx).sum(), (V * F * dz).sum()
                dux, duz = (V * (u[nb] - u[a]) * F * dx).sum(), (V * (u[nb] - u[a]) * F * dz).sum()
                raw_c = raw - 2 * nu * (gx * dux + gz * duz)
            else:
                raw_c = raw
            acc.append(raw / (-g_s))
            cor.append(raw_c / (-g_s))
        out[name] = (float(np.mean(acc)), float(np.std(acc)), len(idx), float(np.mean(cor)))
    return out


def moments(x, z, volume, h, idx, depth):
    fac = grad_coefficient(h)
    gz, mzz = [], []
    for a in idx:
        d2 = (x - x[a]) ** 2 + (z - z[a]) ** 2
        nb = np.flatnonzero((d2 < 4 * h * h) & (d2 > 0))
        F = fac * (1 - np.sqrt(d2[nb]) / h / 2) ** 3
        dz = z[a] - z[nb]
        gz.append((volume[nb] * F * dz).sum())
        mzz.append(-(volume[nb] * F * dz * dz).sum())
    gz, mzz = np.array(gz), np.array(mzz)
    predicted = float(np.mean(mzz + 2 * gz * (-(depth - z[idx]))))
    return float(h * gz.mean()), float(mzz.mean()), predicted


def report(path):
    ds = xr.open_dataset(path)
    hn, dp, h = ds.attrs["h_n_m"], float(ds.attrs["dp"]), float(ds.attrs["h"])
    rho0 = float(ds.attrs["rho0"])
    data = yaml.safe_load(ds.attrs["case_yaml"])
    data.pop("start_perturbation", None)  # an experiment's start beyond the key's cap reads too
    case = case_from_dict(data)
    nu = case.viscosity / case.density
    g_s = case.gravity * math.sin(case.theta)
    s = ds.isel(snapshot=-1)
    ok = np.isfinite(s.x.values)
    x, z, kind, rho = s.x.values[ok], s.z.values[ok], s.kind.values[ok], s.rho.values[ok]
    mass = np.full(x.size, rho0 * dp * dp)
    depth = float(np.nanmean(ds.uniform_depth.values[-10:]))
    xs = (ds.toe_position.values[-1] - x) / hn
    zone = (kind == 0) & (xs > 6) & (xs < 12)
    bands = {"bed rows": np.flatnonzero(zone & (z < 2 * h)),
             "interior": np.flatnonzero(zone & (z >= 2 * h) & (z <= depth - 2 * h)),
             "surface rows": np.flatnonzero(zone & (z > depth - 2 * h))}
    res = operator_response(x, z, kind, rho, mass, h, nu, g_s, depth, bands)
    hgz, mzz, pred = moments(x, z, mass / rho, h, bands["interior"], depth)
    # a square lattice of the same depth, fluid above z = 0, walls below
    nz = int(round(depth / dp))
    X, Z = np.meshgrid((np.arange(-40, 40) + 0.5) * dp, (np.arange(-4, nz) + 0.5) * dp)
    lx, lz = X.ravel(), Z.ravel()
    lk = (lz < 0).astype(int)
    lrho = np.full(lx.size, rho0)
    lm = np.full(lx.size, rho0 * dp * dp)
    H = nz * dp
    mid = np.abs(lx) < 10 * dp
    lat = operator_response(lx, lz, lk, lrho, lm, h, nu, g_s, H, {
        "bed rows": np.flatnonzero(mid & (lk == 0) & (lz < 2 * h)),
        "interior": np.flatnonzero(mid & (lk == 0) & (lz >= 2 * h) & (lz <= H - 2 * h)),
        "surface rows": np.flatnonzero(mid & (lk == 0) & (lz > H - 2 * h))})
    print(f"\n{path}: {case.shifting}, dp = {dp * 1e3:g} mm, t = {float(ds.attrs['simulated_time_s']):.2f} s, "
          f"depth {depth / hn:.4f} h_n")
    print("  effective nu / nu of the viscous term (mean, spread, particles; then with the consistent"
          " correction):")
    for name in res:
        a, b, n, c = res[name]
        la, lc = lat[name][0], lat[name][3]
        print(f"    {name:13s} run arrangement {a:.3f} (sd {b:.2f}, {n}), corrected {c:.3f}   "
              f"lattice {la:.3f}, corrected {lc:.3f}")
    print(f"  interior: h <G_z> = {hgz:+.4f}, <M_zz> = {mzz:.4f}; Taylor prediction M_zz + 2 G_z U'/U'' = {pred:.3f}")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("runs", nargs="+")
    for p in ap.parse_args(argv).runs:
        report(p)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
