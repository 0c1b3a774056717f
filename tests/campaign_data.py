"""Synthetic campaign datasets (the layout of study.campaign.build) for tests that judge,
draw or report a campaign without running SPH."""
from __future__ import annotations

import numpy as np
import xarray as xr

from study.grid import case_id

DPS = (0.004, 0.002, 0.001)  # a constant refinement ratio, as the GCI needs
CHS = (1.5, 1.8, 2.2)
SHIFTS = ("skillen", "lind")
STATIONS = np.array([0.76, 1.5, 9.7])


def campaign(metric, steady=lambda dp, ch, sh: True, status=lambda dp, ch, sh: "completed",
             dps=DPS, chs=CHS, shifts=SHIFTS) -> xr.Dataset:
    """``metric(name, dp, ch, sh)`` gives zeta_f, zeta_h, zeta_h_paper, zeta_fs (floats) and
    zeta_u (one value per station); wall time grows as dp^-3."""
    shape = (len(dps), len(chs), len(shifts))
    scal = {k: np.full(shape, np.nan) for k in ("zeta_f", "zeta_h", "zeta_h_paper", "zeta_fs")}
    zu = np.full(shape + (STATIONS.size,), np.nan)
    st, wall = np.zeros(shape), np.zeros(shape)
    stat, cid = np.full(shape, "", dtype=object), np.full(shape, "", dtype=object)
    flat = []
    for i, dp in enumerate(dps):
        for j, ch in enumerate(chs):
            for k, sh in enumerate(shifts):
                stat[i, j, k] = status(dp, ch, sh)
                cid[i, j, k] = case_id(dp, ch, sh)
                wall[i, j, k] = 10.0 * (0.004 / dp) ** 3
                if stat[i, j, k] != "diverged":
                    for name in scal:
                        scal[name][i, j, k] = metric(name, dp, ch, sh)
                    zu[i, j, k] = metric("zeta_u", dp, ch, sh)
                    st[i, j, k] = float(bool(steady(dp, ch, sh)))
                    if st[i, j, k] == 0:
                        stat[i, j, k] = "not_steady"
                flat.append((i, j, k))
    dims = ("dp", "ch", "shifting")
    n_front = 50
    rng = np.random.default_rng(0)
    fx = np.broadcast_to(rng.uniform(0, 3, n_front), shape + (n_front,)).copy()
    fz = np.broadcast_to(rng.uniform(0, 1, n_front), shape + (n_front,)).copy()
    z_star = np.linspace(0, 1.3, 14)
    ds = xr.Dataset(
        {**{k: (dims, v) for k, v in scal.items()},
         "zeta_u": (dims + ("station",), zu),
         "steady": (dims, st), "status": (dims, stat.astype(str)), "case_id": (dims, cid.astype(str)),
         "wall_time": (dims, wall), "uniform_depth": (dims, 1 - scal["zeta_h"]),
         "mean_velocity": (dims + ("station", "z_star"),
                           np.broadcast_to(1.5 * z_star, shape + (STATIONS.size, z_star.size)).copy()),
         "front_x": (dims + ("front_particle",), fx), "front_z": (dims + ("front_particle",), fz),
         "front_speed": (dims + ("front_particle",), fz.copy()),
         "front_yielded": (dims + ("front_particle",), np.full(shape + (n_front,), np.nan))},
        coords={"dp": list(dps), "ch": list(chs), "shifting": list(shifts), "station": STATIONS,
                "z_star": z_star},
        attrs={"h_n_m": 0.01876, "normalising_depth_m": 0.0186})
    ds = ds.assign_coords(case=("case", [cid[ix] for ix in flat]))
    ds["case_dp"] = ("case", [dps[ix[0]] for ix in flat])
    ds["case_ch"] = ("case", [chs[ix[1]] for ix in flat])
    ds["case_shifting"] = ("case", [shifts[ix[2]] for ix in flat])
    ds["case_on_grid"] = ("case", [1 for _ in flat])
    ds["case_realisation"] = ("case", [0 for _ in flat])
    ds["case_status"] = ("case", [stat[ix] for ix in flat])
    ds["case_reason"] = ("case", ["" for _ in flat])
    ds["case_steady"] = ("case", [int(st[ix]) for ix in flat])
    ds["case_wall_time"] = ("case", [wall[ix] for ix in flat])
    ds["case_steps"] = ("case", [1000.0 for _ in flat])
    ds["case_cfl_acoustic"] = ("case", [np.nan for _ in flat])  # as from runs that did not record it
    ds["case_n_particles"] = ("case", [1000.0 for _ in flat])
    ds["case_steady_state_time"] = ("case", [3.0 for _ in flat])
    for k, v in scal.items():
        ds[f"case_{k}"] = ("case", [v[ix] for ix in flat])
    ds["case_zeta_u"] = (("case", "station"), np.stack([zu[ix] for ix in flat]))
    return ds
