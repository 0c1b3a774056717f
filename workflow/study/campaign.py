"""Reduce per-case results into the campaign dataset: dimensions (dp, ch, shifting) for the
grid (a grid point's realisations averaged, ``ensemble_mean``), and a flat ``case`` table of
every case (grid, its realisations, and extra)."""
from __future__ import annotations

import numpy as np
import yaml
import xarray as xr

from . import stability
from .grid import Case, axis_label, axis_values

SCALARS = ("zeta_f", "zeta_f_se", "zeta_f_body", "zeta_f_body_se", "zeta_h", "zeta_h_se", "zeta_h_paper",
           "zeta_h_paper_se", "zeta_fs", "zeta_fs_se", "zeta_fs_measured",
           "zeta_f_holdout", "zeta_f_holdout_se", "zeta_h_holdout", "zeta_h_holdout_se",
           "zeta_fs_holdout", "zeta_fs_holdout_se")
STATION_METRICS = ("zeta_u", "zeta_u_se", "zeta_u_measured", "zeta_u_holdout", "zeta_u_holdout_se")
HOLDOUT_Z = 2.0  # a metric differs from its hold-out where |difference| > HOLDOUT_Z se of the difference
ROUND_OFF = 1e-12  # a difference no larger is the rounding of two means of equal samples


def holdout_shift(value, se, holdout, holdout_se):
    """(hold-out - value, its se, whether they differ by more than HOLDOUT_Z se), elementwise."""
    diff = np.asarray(holdout, dtype=float) - np.asarray(value, dtype=float)
    se_diff = np.hypot(np.asarray(se, dtype=float), np.asarray(holdout_se, dtype=float))
    with np.errstate(invalid="ignore"):
        differs = np.isfinite(diff) & np.isfinite(se_diff) & (np.abs(diff) > np.maximum(HOLDOUT_Z * se_diff, ROUND_OFF))
    return diff, se_diff, differs


def holdout_moves(ds: xr.Dataset, i: int) -> list[tuple[str, float, float]]:
    """The metrics of case i (in the case table) whose hold-out differs from their value by more
    than HOLDOUT_Z se: (name, hold-out - value, se of the difference)."""
    out = []
    names = [(k, k, None) for k in ("zeta_f", "zeta_h", "zeta_fs")]
    names += [(f"zeta_u x*={s:g}", "zeta_u", j) for j, s in enumerate(ds["station"].values)]
    for name, k, j in names:
        if f"case_{k}_holdout" not in ds:
            continue
        at = (i,) if j is None else (i, j)
        diff, se, differs = holdout_shift(*(ds[f"case_{k}{e}"].values[at] for e in ("", "_se", "_holdout",
                                                                                   "_holdout_se")))
        if differs:
            out.append((name, float(diff), float(se)))
    return out
RUN_NUMBERS = {
    "wall_time": ("wall_time_s", "s", "wall-clock time of the run"),
    "steps": ("steps", "1", "time steps"),
    "n_particles": ("n_particles", "1", "particles (fluid and wall)"),
    "simulated_time": ("simulated_time_s", "s", "simulated time"),
    "steady_state_time": ("steady_state_time_s", "s", "start of the steady averaging window"),
    "threads": ("threads", "1", "threads"),
    "cfl_acoustic": ("cfl_acoustic", "1", "C_CFL of the acoustic limit the run used (cfl_rule)"),
    "started": ("started_unix", "s", "when the run started, seconds since 1970-01-01 UTC"),
    "ended": ("ended_unix", "s", "when the run ended, seconds since 1970-01-01 UTC"),
}
FRONT_XSTAR = 3.0  # particles within this x* of the toe are kept for the front figure


def _front_particles(run: xr.Dataset, max_n: int):
    """Fluid particle positions (x*, z*) within FRONT_XSTAR of the toe in the final snapshot,
    their lab-frame speed |u| / u_b, and for a Herschel-Bulkley fluid whether each has
    yielded (1: mu below the cap max_viscosity, 0: at the cap; NaN for a Newtonian fluid)."""
    nan = np.full(max_n, np.nan)
    if "snapshot" not in run.dims or "toe_position" not in run or run.sizes.get("time", 0) == 0:
        return nan, nan.copy(), nan.copy(), nan.copy()
    s = run.isel(snapshot=-1)
    hn = float(run.attrs["h_n_m"])
    toe = float(run["toe_position"].values[-1])
    f = s["kind"].values == 0
    xs = (toe - s["x"].values[f]) / hn
    zs = s["z"].values[f] / hn
    keep = (xs >= -0.5) & (xs <= FRONT_XSTAR)
    xs, zs = xs[keep][:max_n], zs[keep][:max_n]
    px, pz, pv, py = (np.full(max_n, np.nan) for _ in range(4))
    px[:xs.size], pz[:zs.size] = xs, zs
    case = yaml.safe_load(run.attrs["case_yaml"])
    if "u" in s and "w" in s:
        pv[:xs.size] = np.hypot(s["u"].values[f], s["w"].values[f])[keep][:max_n] / case["belt"]["speed"]
    if "mu" in s:
        mu = s["mu"].values[f][keep][:max_n]
        py[:mu.size] = (mu < 0.999 * float(case["max_viscosity"])).astype(float)
    return px, pz, pv, py


def ensemble_size(ds: xr.Dataset) -> int:
    """The most realisations a grid point of a campaign dataset averages (1: no ensemble)."""
    if "realisations" in ds:
        return max(int(ds["realisations"].max()), 1)
    return int(ds.attrs.get("realisations", 1))


def _metric(m: xr.Dataset, k: str):
    """Metric k of one case's metrics dataset (NaN where absent: metrics written before it)."""
    return m[k].values if k in m else np.nan


def ensemble_mean(values: np.ndarray, errors: np.ndarray | None = None) -> tuple:
    """(mean, se) of one metric over n realisations (axis 0; NaN where a realisation has none).

    With one finite value, that value and its se. With n > 1, the mean of the finite values and
    se = sqrt(max(s^2, mean se_i^2) / n): s^2 is their sample variance, which holds the spread
    between realisations that a single window's se_i does not; the mean of the se_i^2 bounds it
    from below, so that a few realisations that happen to agree do not claim a smaller error
    than each window's own sampling gives. NaN where no value is finite."""
    values = np.asarray(values, dtype=float)
    shape = values.shape[1:]
    errors = np.full(values.shape, np.nan) if errors is None else \
        np.broadcast_to(np.asarray(errors, dtype=float), values.shape)
    ok = np.isfinite(values)
    n = ok.sum(axis=0)
    safe_n = np.maximum(n, 1)
    mean = np.where(n > 0, np.where(ok, values, 0.0).sum(axis=0) / safe_n, np.nan)
    var = np.where(ok, (values - mean) ** 2, 0.0).sum(axis=0) / np.maximum(n - 1, 1)
    within_ok = ok & np.isfinite(errors)
    within = np.where(within_ok, errors ** 2, 0.0).sum(axis=0) / np.maximum(within_ok.sum(axis=0), 1)
    se = np.sqrt(np.maximum(var, within) / safe_n)
    single = np.where(ok, errors, 0.0).sum(axis=0)  # the one finite value's se
    se = np.where(n > 1, se, np.where(n == 1, single, np.nan))
    if not shape:
        return float(mean), float(se)
    return mean.reshape(shape), se.reshape(shape)


def worst_member(members: list[tuple]) -> tuple:
    """The (case, run) whose status a grid point takes: the first diverged realisation, else the
    first that did not complete, else realisation 0 (members in realisation order)."""
    def rank(member):
        status = member[1].attrs["status"]
        return 0 if status == "diverged" else 1 if status != "completed" else 2
    return min(members, key=rank)  # min keeps the first of equal rank


def build(cases: list[Case], runs: list[xr.Dataset], metrics: list[xr.Dataset],
          front_particles: int = 4000) -> xr.Dataset:
    """The campaign dataset from each case's run and metrics datasets (same order). The grid
    arrays over (dp, ch, shifting) hold the grid cases at the physical axes' first values (those
    of the first case); every case, each axis's value included, is in the flat ``case`` table."""
    base = next((c.axes for c in cases if c.on_grid), ())
    grid = [c for c in cases if c.on_grid and c.axes == base]
    dps = sorted({c.dp for c in grid}, reverse=True)
    chs = sorted({c.ch for c in grid})
    shs = list(dict.fromkeys(c.shifting for c in grid))
    stations = metrics[0]["station"].values
    x_star = next((r["x_star"].values for r in runs if "x_star" in r.coords), np.zeros(0))
    z_star = next((r["z_star"].values for r in runs if "z_star" in r.coords), np.zeros(0))
    shape = (len(dps), len(chs), len(shs))
    arr = lambda *extra: np.full(shape + extra, np.nan)  # noqa: E731
    data = {k: arr() for k in SCALARS}
    for k in STATION_METRICS:
        data[k] = arr(stations.size)
    for k in RUN_NUMBERS:
        data[k] = arr()
    data["uniform_depth"] = arr()
    data["mean_surface"] = arr(x_star.size)
    data["mean_velocity"] = arr(stations.size, z_star.size)
    data["front_x"] = arr(front_particles)
    data["front_z"] = arr(front_particles)
    data["front_speed"] = arr(front_particles)
    data["front_yielded"] = arr(front_particles)
    steady = np.zeros(shape)
    status = np.full(shape, "missing", dtype=object)
    reason = np.full(shape, "", dtype=object)
    case_ids = np.full(shape, "", dtype=object)

    n_real = np.zeros(shape, dtype=int)
    cells: dict[tuple, list] = {}
    for c, run, m in zip(cases, runs, metrics):
        if c.on_grid and c.axes == base:
            cells.setdefault((dps.index(c.dp), chs.index(c.ch), shs.index(c.shifting)), []).append((c, run, m))
    for ix, members in cells.items():
        members.sort(key=lambda cm: cm[0].realisation)
        c, run, m = members[0]  # realisation 0: the case as configured
        n_real[ix] = len(members)
        for k in SCALARS + STATION_METRICS:
            if k.endswith("_se"):
                continue
            cell = data[k][ix].shape
            values = np.array([np.broadcast_to(_metric(mm, k), cell) for _, _, mm in members])
            errors = (np.array([np.broadcast_to(_metric(mm, f"{k}_se"), cell) for _, _, mm in members])
                      if f"{k}_se" in data else None)
            data[k][ix], se = ensemble_mean(values, errors)
            if errors is not None:
                data[f"{k}_se"][ix] = se
        for k, (attr, _, _) in RUN_NUMBERS.items():  # a run's cost: the mean over the realisations
            data[k][ix] = np.mean([float(r.attrs.get(attr, np.nan)) for _, r, _ in members])
        means = [r for _, r, _ in members if "mean_surface_elevation" in r and r.attrs["status"] != "diverged"]
        if means:
            data["uniform_depth"][ix] = np.mean([float(r["mean_uniform_depth"]) / r.attrs["h_n_m"] for r in means])
            data["mean_surface"][ix] = np.mean([r["mean_surface_elevation"].values / r.attrs["h_n_m"]
                                                for r in means], axis=0)
            data["mean_velocity"][ix] = np.mean([r["mean_velocity_star"].values for r in means], axis=0)
        if run.attrs["status"] != "diverged":  # a diverged run keeps no final state
            (data["front_x"][ix], data["front_z"][ix], data["front_speed"][ix],
             data["front_yielded"][ix]) = _front_particles(run, front_particles)
        # the grid point counts as completed and steady only if every realisation is
        worst_case, worst_run = worst_member([(cc, r) for cc, r, _ in members])
        status[ix], reason[ix], case_ids[ix] = worst_run.attrs["status"], worst_run.attrs["reason"], c.id
        if worst_case is not c and reason[ix]:
            reason[ix] = f"{worst_case.id}: {reason[ix]}"
        steady[ix] = min(float(mm["steady"]) for _, _, mm in members)

    dims = ("dp", "ch", "shifting")
    ds = xr.Dataset(
        {**{k: (dims, data[k]) for k in SCALARS + tuple(RUN_NUMBERS)},
         **{k: (dims + ("station",), data[k]) for k in STATION_METRICS},
         "uniform_depth": (dims, data["uniform_depth"], {"units": "1", "long_name": "uniform depth h_u / h_n"}),
         "mean_surface": (dims + ("x_star",), data["mean_surface"]),
         "mean_velocity": (dims + ("station", "z_star"), data["mean_velocity"]),
         "front_x": (dims + ("front_particle",), data["front_x"]),
         "front_z": (dims + ("front_particle",), data["front_z"]),
         "front_speed": (dims + ("front_particle",), data["front_speed"]),
         "front_yielded": (dims + ("front_particle",), data["front_yielded"]),
         "steady": (dims, steady, {"units": "1", "long_name": "1: metrics from a steady window"}),
         "status": (dims, status.astype(str)),
         "reason": (dims, reason.astype(str)),
         "case_id": (dims, case_ids.astype(str)),
         "realisations": (dims, n_real, {"units": "1", "long_name": "realisations averaged (ensemble)"})},
        coords={"dp": ("dp", np.array(dps), {"units": "m", "long_name": "particle spacing"}),
                "ch": ("ch", np.array(chs), {"units": "1", "long_name": "h / dp"}),
                "shifting": ("shifting", np.array(shs, dtype=str)),
                "station": ("station", stations, {"units": "1", "long_name": "station x*"}),
                "x_star": ("x_star", x_star, {"units": "1"}), "z_star": ("z_star", z_star, {"units": "1"})})
    for k in SCALARS:
        ds[k].attrs.update(metrics[0][k].attrs if k in metrics[0] else {})
    for k in STATION_METRICS:
        ds[k].attrs.update(metrics[0][k].attrs if k in metrics[0] else {})
    for k, (_, units, long) in RUN_NUMBERS.items():
        ds[k].attrs.update(units=units, long_name=long)
    ds["mean_surface"].attrs.update(units="1", long_name="steady free surface h/h_n")
    ds["mean_velocity"].attrs.update(units="1", long_name="steady u* (belt frame)")
    ds["front_x"].attrs.update(units="1", long_name="final fluid particles near the front, x* upslope of toe")
    ds["front_z"].attrs.update(units="1", long_name="final fluid particles near the front, z/h_n")
    ds["front_speed"].attrs.update(units="1", long_name="final speed near the front, lab frame, |u| / u_b")
    ds["front_yielded"].attrs.update(
        units="1", long_name="1: yielded (viscosity below the cap), 0: unyielded; NaN: newtonian")

    # flat table of every case, extra ones included
    ds = ds.assign_coords(case=("case", [c.id for c in cases]))
    ds["case_dp"] = ("case", [c.dp for c in cases], {"units": "m"})
    ds["case_ch"] = ("case", [c.ch for c in cases])
    ds["case_shifting"] = ("case", [c.shifting for c in cases])
    ds["case_on_grid"] = ("case", [int(c.on_grid) for c in cases])
    axes = list(dict.fromkeys(k for c in cases for k, _ in c.axes))
    ds["case_realisation"] = ("case", [c.realisation for c in cases])
    for key in axes:  # each physical axis's value of each case
        ds[f"case_axis_{axis_label(key)}"] = ("case", axis_values(cases, key), {"long_name": f"physical axis {key}"})
    ds.attrs["axes"] = ",".join(axis_label(k) for k in axes)
    ds["case_tag"] = ("case", np.array([c.tag or "" for c in cases], dtype=str))
    ds["case_status"] = ("case", [r.attrs["status"] for r in runs])
    ds["case_steady"] = ("case", [int(m["steady"]) for m in metrics])
    ds["case_reason"] = ("case", [r.attrs["reason"] for r in runs])
    for k, (attr, units, _) in RUN_NUMBERS.items():
        ds[f"case_{k}"] = ("case", [float(r.attrs.get(attr, np.nan)) for r in runs], {"units": units})
    for k in SCALARS:
        ds[f"case_{k}"] = ("case", [float(m[k]) if k in m else np.nan for m in metrics])
    for k in ("zeta_u", "zeta_u_se", "zeta_u_holdout", "zeta_u_holdout_se"):
        ds[f"case_{k}"] = (("case", "station"), np.stack([m[k].values if k in m else np.full(stations.size, np.nan)
                                                         for m in metrics]))
    # stability: margins to each guard, the detector that fired, the swept settings
    marg = [stability.margins(r) for r in runs]
    for k, long in (("density_margin", "max density deviation / its guard"),
                    ("penetration_margin", "max wall penetration / its guard"),
                    ("area_drift_margin", "max |area drift| / its guard"),
                    ("energy_ratio", "peak kinetic energy / (0.5 M u_b^2)"),
                    ("end_time", "simulated time at the end of the run")):
        ds[f"case_{k}"] = ("case", [m[k] for m in marg], {"units": "s" if k == "end_time" else "1", "long_name": long})
    ds["case_detector"] = ("case", [stability.detector(r.attrs["status"], r.attrs["reason"]) for r in runs])
    ds["case_safe"] = ("case", [int(stability.is_safe(r.attrs["status"], m)) for r, m in zip(runs, marg)],
                       {"long_name": f"survived with every margin below {stability.SAFE_FRACTION:g}"})
    ds["case_settings"] = ("case", [yaml.safe_dump(stability.case_settings(r), sort_keys=False) for r in runs])
    rheologies = {yaml.safe_load(r.attrs["case_yaml"]).get("rheology", "newtonian") for r in runs}
    ds.attrs["rheology"] = "newtonian" if rheologies == {"newtonian"} else ", ".join(sorted(rheologies))
    return ds
