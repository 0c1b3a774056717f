"""Run the conveyor-belt case: probes at an interval, steady-state stop, averaging,
volume-consistency guard, checkpoints, and one NetCDF per run."""
from __future__ import annotations

import bisect
import math
import sys
from dataclasses import replace

import numba as nb
import numpy as np
import xarray as xr

from . import film_depth, film_fit, steady, warm
from .build import build_particles
from .checkpoint import Checkpointer, run_key
from .conveyor import ConveyorCase, build_scene, cold_start, lubrication_velocity, scheme_fluid, start_offsets
from .output import to_dataset
from .probes import C_SURFACE, FieldSampler, last_crossing, toe_position
from .progress import ProgressFile, chain
from .run import Runner
from .simulation import Simulation

SERIES = ("toe", "front_position", "front_equivalent", "uniform_depth", "enclosed_area", "mass_area",
          "number_density")
ZONES = ("wall", "body", "front", "in_walls")
WALL_ZONE = 2.0  # h_n: the upstream wall region (the belt taper and the corner flow)
FRONT_ANCHOR = 4.0  # h_n upstream of the first toe (at most half-way to the wall): x0 of the equivalent front


def zone_budget(x, z, volume, xs, zs, toe, h_n, front_length):
    """Area by zone: (enclosed, mass-implied), each over ZONES.

    Zones along the belt: wall (x < WALL_ZONE h_n), front (within ``front_length`` h_n of the
    toe) and the body between; in_walls holds fluid particles behind the upstream wall or
    under the belt surface (x < 0 or z < 0), which no enclosed area contains.
    Enclosed: the trapezoid integral of the free surface zs(xs) over the zone's x range.
    """
    edges = np.array([0.0, WALL_ZONE * h_n, toe - front_length * h_n, toe])
    edges[1:3] = np.clip(edges[1:3], 0.0, toe)
    xx = np.concatenate([[0.0], xs, [toe]])
    zz = np.concatenate([[zs[0] if zs.size else 0.0], zs, [0.0]])
    enclosed = np.zeros(len(ZONES))
    mass = np.zeros(len(ZONES))
    for k in range(3):
        lo, hi = edges[k], edges[k + 1]
        if hi > lo:
            xk = np.concatenate([[lo], xx[(xx > lo) & (xx < hi)], [hi]])
            enclosed[k] = float(np.trapezoid(np.interp(xk, xx, zz), xk))
    inside = (x >= 0.0) & (z >= 0.0)
    zone = np.searchsorted(edges[1:3], x, side="right")
    mass[:3] = np.bincount(zone[inside], weights=volume[inside], minlength=3)[:3]
    mass[3] = float(volume[~inside].sum())
    return enclosed, mass


def equivalent_front(x, volume, x0, h_n, h):
    """x0 + (fluid area downstream of x0) / h_n: where a layer of depth h_n holding the
    fluid downstream of the lab-fixed x0 would end. A front that advances by d at constant
    shape moves it by d; it sums every particle downstream of x0 (each weighted by a linear
    ramp over x0 +- h), so it does not jump as particles join or leave the tip or the
    surface as the toe and the h_n / 2 crossing do."""
    weight = np.clip((x - x0) / (2.0 * h) + 0.5, 0.0, 1.0)
    return float(x0 + np.dot(weight, volume) / h_n)


def strip_mean_velocity(x, z, u, volume, x_station, h):
    """Volume-weighted mean horizontal velocity of the fluid in a vertical strip at each
    x_station: sum_j V_j u_j w_j / sum_j V_j w_j, w_j = (1 - (dx / 2h)^2)^2 for |dx| < 2h
    (fluid above the bed). It is the depth-mean velocity q / h of the strip, from the
    particles themselves: no surface level, no interpolation. In the belt frame it is
    1 + q / (u_b h) with q the lab-frame flux carried by the particle velocities, 1 where a
    front is steady and shifting displaces little (at x* = 0.76, dp = 1 mm: 0.995 with
    skillen; 0.93 with lind, whose shifting moves the tip's particles besides)."""
    out = np.full(len(x_station), math.nan)
    for k, xs in enumerate(x_station):
        m = (np.abs(x - xs) < 2.0 * h) & (z >= 0.0)
        if m.any():
            w = volume[m] * (1.0 - ((x[m] - xs) / (2.0 * h)) ** 2) ** 2
            out[k] = float(np.dot(w, u[m]) / w.sum())
    return out


class FrontMonitor:
    """Samples the probes every ``case.probes.interval``; ends the run at the end of the first
    steady window pair (the hold-out after the averaging window, solver/steady.py). Fires the
    area-drift guard."""

    def __init__(self, case: ConveyorCase):
        self.case = case
        self.interval = case.probes.interval
        p = case.probes
        self.x_star = np.round(np.arange(0.0, p.x_star_max + 0.5 * p.x_star_step, p.x_star_step), 10)
        self.z_star = np.round(np.arange(0.0, p.z_star_max + 0.5 * p.z_star_step, p.z_star_step), 10)
        self.stations = np.asarray(p.stations, dtype=float)
        self.detector = steady.SteadyDetector(case.criteria())
        self.state = "transient"
        self.t: list[float] = []
        self.series = {k: [] for k in SERIES}
        self.zone_enclosed: list[np.ndarray] = []
        self.zone_mass: list[np.ndarray] = []
        self.disorder: list[np.ndarray] = []  # (M_xx, M_zz, h |sum V gradW|) in the uniform zone
        self.surface: list[np.ndarray] = []  # z_max over x_star
        self.velocity: list[np.ndarray] = []  # u* over (station, z_star)
        self.station_u: list[np.ndarray] = []  # depth-mean u* of each station
        self.station_front: list[np.ndarray] = []  # equivalent front from each station's anchor
        self.x_anchor = math.nan  # x0 of the equivalent front, set at the first sample
        self.x_station_anchor = np.full(self.stations.size, math.nan)  # lab-fixed, at the first sample
        # the last sample's free surface along the whole fluid, (x, z_max) in the lab frame: the
        # shape a warm start at another dp fills (``warm.load``)
        self.last_surface = (np.zeros(0), np.zeros(0))

    @property
    def t_steady(self) -> float:
        """Start of the steady averaging window (NaN: not steady yet)."""
        return self.detector.t_steady

    def record(self, start: float = -math.inf) -> steady.Record:
        """The detector's quantities from the probe samples at or after ``start``."""
        i = bisect.bisect_left(self.t, start - 1e-9)
        n = len(self.t) - i
        return detector_record(self.case, self.x_star, self.t[i:], self.series["toe"][i:],
                               self.series["uniform_depth"][i:],
                               np.asarray(self.surface[i:], dtype=float).reshape(n, -1),
                               np.asarray(self.velocity[i:], dtype=float).reshape(n, self.stations.size, -1))

    def final_judgement(self) -> steady.Judgement:
        """The window pair ending at the last sample."""
        return steady.judge(self.record(), float(self.t[-1]), self.detector.crit)

    # ---- one sample ---------------------------------------------------------------
    def sample(self, sim: Simulation) -> dict:
        c, hn, ub = self.case, self.case.h_n, self.case.belt.speed
        dp = sim.scene.dp
        n = sim.n_active
        fl = sim.kind[:n] == 0
        xf = sim.x[:n][fl]
        toe = toe_position(xf, dp)
        fs = FieldSampler(sim)
        xs = np.arange(0.25 * dp, toe, 0.5 * dp)
        zs = fs.surface(xs, 0.0)
        enclosed = float(np.trapezoid(np.concatenate([[zs[0]], zs, [0.0]]),
                                      np.concatenate([[0.0], xs, [toe]])))
        vol = sim.mass[:n][fl] / sim.rho[:n][fl]
        mass_area = float(vol.sum())
        zone_enclosed, zone_mass = zone_budget(xf, sim.z[:n][fl], vol, xs, zs, toe, hn,
                                               c.probes.uniform_zone[0])
        # front position: the most downstream point where the surface is at half h_n (far less
        # noisy than the toe, which jumps by dp as particles join or leave the tip)
        front = last_crossing(xs, zs, 0.5 * hn)
        x_lab = toe - self.x_star * hn
        surface = np.interp(x_lab, xs, zs, left=np.nan, right=0.0)
        lo, hi = c.probes.uniform_zone
        zone = (self.x_star >= lo) & (self.x_star <= hi)
        depth = float(np.nanmean(surface[zone])) if np.isfinite(surface[zone]).any() else math.nan
        if math.isnan(self.x_anchor):
            self.x_anchor = max(toe - FRONT_ANCHOR * hn, 0.5 * toe)  # inside the fluid
            self.x_station_anchor = np.maximum(toe - self.stations * hn, 0.5 * toe)
        front_eq = equivalent_front(xf, vol, self.x_anchor, hn, sim.h)
        station_front = np.array([equivalent_front(xf, vol, xa, hn, sim.h) for xa in self.x_station_anchor])
        # velocity lines at the stations
        x_station = toe - self.stations * hn
        px = np.repeat(x_station, self.z_star.size)
        pz = np.tile(self.z_star * hn, self.stations.size)
        out = fs.points(px, pz)
        inside = out[0] >= C_SURFACE
        u_star = np.where(inside, (out[2] + ub) / ub, np.nan).reshape(self.stations.size, -1)
        station_u = (strip_mean_velocity(xf, sim.z[:n][fl], sim.u[:n][fl], vol, x_station, sim.h) + ub) / ub
        # interior number density in the uniform zone: mid-depth points
        zx = toe - np.linspace(lo, hi, 7) * hn
        nd = fs.points(np.repeat(zx, 3), np.tile(np.array([0.3, 0.45, 0.6]) * depth, zx.size))
        number_density = float(np.mean(nd[4]) * dp * dp) if np.isfinite(depth) else math.nan
        # particle disorder in the interior of the uniform zone (away from bed and surface)
        disorder = np.full(3, math.nan)
        if np.isfinite(depth):
            xa, za = sim.x[:n], sim.z[:n]
            core = np.flatnonzero(fl & (xa <= toe - lo * hn) & (xa >= toe - hi * hn)
                                  & (za >= 2.0 * sim.h) & (za <= depth - 2.0 * sim.h))
            if core.size:
                disorder = fs.disorder(core).mean(axis=1)
        return {"toe": toe, "front_position": front, "front_equivalent": front_eq, "uniform_depth": depth,
                "enclosed_area": enclosed, "station_u": station_u, "station_front": station_front,
                "mass_area": mass_area, "number_density": number_density,
                "zone_enclosed": zone_enclosed, "zone_mass": zone_mass, "disorder": disorder,
                "surface": surface, "velocity": u_star, "surface_line": (xs, zs)}

    def why_not_steady(self) -> str:
        """Which quantities drift beyond their allowance over the final window pair."""
        t = np.asarray(self.t)
        crit = self.detector.crit
        if t.size < 8 or t[-1] - t[0] < 2.0 * crit.window:
            return "the record is shorter than two averaging windows"
        j = self.final_judgement()
        if j.steady and j.averaging[0] < crit.min_time - 1e-9:
            return (f"{j.describe()}, but its averaging window starts before {crit.min_time:g} s (the end of "
                    "the belt's ramp plus steady.min_time)")
        return j.describe()

    def station_fronts(self) -> np.ndarray:
        """Equivalent front from each station's lab-fixed anchor over time, (time, station)."""
        return np.asarray(self.station_front, dtype=float).reshape(len(self.t), self.stations.size)

    def station_means(self) -> np.ndarray:
        """Depth-mean u* of each station over time, (time, station) (``strip_mean_velocity``)."""
        return np.asarray(self.station_u, dtype=float).reshape(len(self.t), self.stations.size)

    # ---- monitor protocol ------------------------------------------------------------
    def __call__(self, sim: Simulation):
        s = self.sample(sim)
        self.t.append(sim.t)
        for k in SERIES:
            self.series[k].append(s[k])
        self.zone_enclosed.append(s["zone_enclosed"])
        self.zone_mass.append(s["zone_mass"])
        self.disorder.append(s["disorder"])
        self.surface.append(s["surface"])
        self.last_surface = s["surface_line"]
        self.velocity.append(s["velocity"])
        self.station_u.append(s["station_u"])
        self.station_front.append(s["station_front"])
        drift = s["enclosed_area"] / s["mass_area"] - 1.0
        if abs(drift) > self.case.max_area_drift:
            return ("diverged", f"t = {sim.t:.6g} s: enclosed area differs from the mass-implied "
                    f"area by {100 * drift:+.1f} % (max_area_drift = {self.case.max_area_drift:g})")
        if self.state != "steady":
            w = self.detector.crit.window
            span = 2.0 * w + self.detector.crit.context + self.interval
            start = -math.inf if math.isnan(self.detector.t_first) else sim.t - span
            self.state = "steady" if self.detector.update(self.record(start)) else "transient"
            if self.state == "steady" and self.case.steady.stop:
                return ("completed", "")
        return None

    # ---- results ---------------------------------------------------------------------
    def dataset(self) -> xr.Dataset:
        c = self.case
        t = np.asarray(self.t)
        hn = c.h_n
        data = {
            "toe_position": (("time",), np.asarray(self.series["toe"]),
                             {"units": "m", "long_name": "toe (downstream end of the fluid), lab frame"}),
            "front_position": (("time",), np.asarray(self.series["front_position"]),
                               {"units": "m",
                                "long_name": "most downstream x where the free surface is at h_n / 2, lab frame"}),
            "front_equivalent": (("time",), np.asarray(self.series["front_equivalent"]),
                                 {"units": "m", "long_name": "x0 + fluid area downstream of x0 / h_n, lab frame "
                                  f"(x0 = {self.x_anchor:.6g} m, {FRONT_ANCHOR:g} h_n upstream of the first toe or "
                                  "half-way to the wall if nearer); "
                                  "zeta_f_body's front"}),
            "station_mean_velocity": (("time", "station"), self.station_means(),
                                      {"units": "1", "long_name": "depth-mean u* at the station: volume-weighted mean "
                                       "of the fluid particles within +-2h of it"}),
            "station_front": (("time", "station"), self.station_fronts(),
                              {"units": "m", "long_name": "x_s + fluid area downstream of x_s / h_n, lab frame, "
                               "x_s fixed at each station's x* upslope of the first toe (half-way to the wall if "
                               "nearer); a diagnostic"}),
            "uniform_depth": (("time",), np.asarray(self.series["uniform_depth"]),
                              {"units": "m", "long_name": "mean free-surface elevation over the uniform zone"}),
            "enclosed_area": (("time",), np.asarray(self.series["enclosed_area"]),
                              {"units": "m2", "long_name": "area between bed and free surface, wall to toe"}),
            "mass_area": (("time",), np.asarray(self.series["mass_area"]),
                          {"units": "m2", "long_name": "mass-implied area sum m/rho"}),
            "number_density": (("time",), np.asarray(self.series["number_density"]),
                               {"units": "1", "long_name": "interior kernel number density sum W dp^2"}),
            "zone_enclosed_area": (("time", "zone"), np.asarray(self.zone_enclosed).reshape(t.size, len(ZONES)),
                                   {"units": "m2", "long_name": "area between bed and free surface in each zone"}),
            "zone_mass_area": (("time", "zone"), np.asarray(self.zone_mass).reshape(t.size, len(ZONES)),
                               {"units": "m2",
                                "long_name": "mass-implied area sum m/rho of the fluid particles in each zone"}),
            "disorder": (("time", "moment"), np.asarray(self.disorder).reshape(t.size, 3),
                         {"units": "1", "long_name": "mean particle-arrangement moments in the uniform zone's "
                          "interior: M_xx, M_zz (1 on a lattice) and h |sum_b V_b gradW_ab| (0 on a lattice)"}),
            "surface_elevation": (("time", "x_star"), np.asarray(self.surface).reshape(t.size, -1),
                                  {"units": "m", "long_name": "free surface z_max (C = 0.5 level)"}),
            "velocity_star": (("time", "station", "z_star"),
                              np.asarray(self.velocity).reshape(t.size, self.stations.size, -1),
                              {"units": "1", "long_name": "(u + u_b) / u_b, belt frame, linear MLS interpolated"}),
        }
        ds = xr.Dataset(data, coords={
            "time": ("time", t, {"units": "s", "long_name": "probe time"}),
            "x_star": ("x_star", self.x_star, {"units": "1", "long_name": "distance upslope from the toe / h_n"}),
            "station": ("station", self.stations, {"units": "1", "long_name": "station x* upslope from the toe"}),
            "z_star": ("z_star", self.z_star, {"units": "1", "long_name": "bed-normal height / h_n"}),
            "moment": ("moment", ["M_xx", "M_zz", "grad_sum"]),
            "zone": ("zone", list(ZONES), {"long_name": f"wall: x < {WALL_ZONE:g} h_n; front: within "
                                            f"{c.probes.uniform_zone[0]:g} h_n of the toe; body: between; "
                                            "in_walls: fluid at x < 0 or z < 0"}),
        })
        ds["area_drift"] = (("time",), ds.enclosed_area.values / ds.mass_area.values - 1.0,
                            {"units": "1", "long_name": "enclosed / mass-implied area - 1"})
        # the film fit at the farthest station (x* = 9.7 in the paper's set), 2 h from bed and surface
        far = self.stations.size - 1
        depth_far = ds.surface_elevation.sel(x_star=self.stations[far], method="nearest").values / hn
        nu_ratio, slip = film_fit.fit_series(self.z_star, ds.velocity_star.values[:, far, :], depth_far,
                                             2.0 * c.ch * c.dp / hn)
        if not c.newtonian:  # the fit assumes the Newtonian film: meaningless here
            nu_ratio, slip = np.full_like(nu_ratio, np.nan), np.full_like(slip, np.nan)
        ds["film_viscosity_ratio"] = (("time",), nu_ratio, {
            "units": "1",
            "long_name": f"nu_eff / nu from the curvature of the u* profile at x* = {self.stations[far]:g}"})
        ds["film_slip"] = (("time",), slip, {
            "units": "1",
            "long_name": f"u* at the bed of the fitted profile at x* = {self.stations[far]:g} (0: no slip)"})
        sx, sz = self.last_surface
        ds["final_surface"] = (("surface_x",), np.asarray(sz, dtype=float), {
            "units": "m", "long_name": "free surface z_max (C = 0.5 level) at the last probe sample, wall to toe"})
        ds = ds.assign_coords(surface_x=("surface_x", np.asarray(sx, dtype=float),
                                         {"units": "m", "long_name": "x of final_surface, lab frame"}))
        # the averaging window A and its hold-out B: with steady.stop, the first steady pair;
        # otherwise (fixed end time, or no steady pair by max_time) the pair ending at the last
        # sample, steady only if it passes; a record shorter than two windows averages its final
        # window (all of it when shorter), not steady, without a hold-out. Nothing that is not
        # steady passes for steady.
        w = self.detector.crit.window
        j = None
        if c.steady.stop and self.detector.found is not None:
            j = self.detector.found
        elif t.size >= 8 and t[-1] - t[0] >= 2.0 * w - 1e-9:
            j = self.final_judgement()
        steady_found = j is not None and j.steady and j.averaging[0] >= self.detector.crit.min_time - 1e-9
        nan = math.nan
        (a0, a1), (b0, b1) = (j.averaging, j.holdout) if j is not None else \
            (((max(t[0], t[-1] - w), t[-1]) if t.size else (nan, nan)), (nan, nan))
        ds.attrs["steady_state_time_s"] = float(a0) if steady_found else nan
        ds.attrs["steady"] = int(steady_found)
        ds.attrs["averaging"] = "steady window" if steady_found else "final window, NOT steady"
        ds.attrs["window_start_s"], ds.attrs["window_end_s"] = float(a0), float(a1)
        ds.attrs["holdout_start_s"], ds.attrs["holdout_end_s"] = float(b0), float(b1)
        ds.attrs["steady_judgement"] = j.describe() if j is not None else "record shorter than two windows"
        ds.attrs["steady_min_time_s"] = float(self.detector.crit.min_time)
        ds.attrs["se_context_s"] = float(self.detector.crit.context)
        for q, r in (j.ratios.items() if j is not None else ()):
            ds.attrs[f"drift_ratio_{q.replace(' ', '_')}"] = float(r)
        if t.size >= 2:
            win = (t >= a0 - 1e-9) & (t <= a1 + 1e-9)
            tw = t[win]
            avg = ds.isel(time=win).mean("time")
            for k in ("surface_elevation", "velocity_star", "uniform_depth", "number_density", "area_drift"):
                long_name = ds.attrs["averaging"] + " mean of " + ds[k].attrs["long_name"]
                ds[f"mean_{k}"] = avg[k].assign_attrs(ds[k].attrs, long_name=long_name)
            ds["front_velocity"] = ((), steady.front_velocity_fit(tw, ds.toe_position.values[win])[0],
                                    {"units": "m s-1",
                                     "long_name": "toe velocity over the last second of the window, lab frame"})
            ds.attrs["average_window_s"] = float(tw[-1] - tw[0])
        return ds


def checkpoint_key(case: ConveyorCase, threads: int) -> str:
    """A checkpoint resumes only the same case, on the same solver sources and thread count
    (another thread count sums in another order: the result would not be bit-for-bit)."""
    return run_key(case.to_yaml(), threads)


def start_flux_ratio(case: ConveyorCase, warm_state, quiet: bool = True) -> tuple[float, str]:
    """(r, how the start's depth was chosen): r = the scheme's film flux over the exact one
    (``film_depth``; the start is the steady front of ``conveyor.scheme_fluid(case, r)``), or
    1 (``start_depth: theory``, or when the film stops, with the reason). NaN for the block
    and warm starts, which do not use it."""
    if warm_state is not None or case.start != "lubrication":
        return math.nan, f"not used (start: {case.start})"
    if case.start_depth == "theory":
        return 1.0, "theory: h_n"
    try:
        film = film_depth.scheme_normal_depth(case)
    except RuntimeError as exc:
        note = f"theory: h_n, because {exc}"
        if not quiet:
            print(f"warning: start depth from the film not possible; {note}", file=sys.stderr)
        return 1.0, note
    if not quiet:
        print(f"start depth: {film.describe()}", file=sys.stderr)
    return film.flux_ratio, film.describe()


def run_front(case: ConveyorCase, quiet: bool = True, checkpoint=None, progress=None) -> xr.Dataset:
    """Run the case to steady state (or max_time) and return its dataset.

    With ``checkpoint`` (a path), the run resumes from a matching checkpoint there and
    writes one every ``case.checkpoint_interval`` seconds of simulated time; the caller
    removes it once the result is safely written. With ``progress`` (a path), the run's
    progress is written there every few wall seconds (solver/progress.py).
    """
    warm_note = ""
    state = None
    if case.start == "warm":
        try:
            state = warm.load(case.warm_from)
        except (OSError, ValueError) as exc:  # a diverged or missing source: the scheme's cold start
            warm_note = f"fallback to the scheme's start ({cold_start(case)}): {exc}"
            if not quiet:
                print(f"warning: warm start not possible, {warm_note}", file=sys.stderr)
    if state is None and warm_note:
        case = replace(case, start=cold_start(case), warm_from=None)
    ckpt = None
    saved = None
    if checkpoint is not None:
        ckpt = Checkpointer(checkpoint, case.checkpoint_interval, checkpoint_key(case, nb.get_num_threads()))
        saved = ckpt.load()
    if saved is not None and saved.get("start") is not None:
        flux_ratio, depth_note = saved["start"]  # the start's film is not run again
    else:
        flux_ratio, depth_note = start_flux_ratio(case, state, quiet)
    used = math.isfinite(flux_ratio)
    scene = build_scene(case, state, flux_ratio if used else 1.0)
    parts = build_particles(scene)
    if state is not None:  # the source's arrangement instead of the lattice
        parts = warm.carry_arrangement(parts, scene, state)
    f = parts.kind == 0
    if case.start_perturbation > 0.0:
        dx, dz = start_offsets(int(f.sum()), case.start_perturbation * case.dp, case.perturbation_seed)
        parts.x[f] += dx
        parts.z[f] += dz
    if state is not None:
        parts.u[f], parts.w[f] = state.velocity_at(parts.x[f], parts.z[f])
    elif case.start_velocity == "lubrication":
        parts.u[f], parts.w[f] = lubrication_velocity(case, scene, parts.x[f], parts.z[f])
    sim = Simulation(scene, parts)
    monitor = FrontMonitor(case)
    runner = Runner(scene, sim, monitors=[monitor], final_snapshot=True)
    resumed = False
    if ckpt is not None:
        ckpt.start = (flux_ratio, depth_note)
        resumed = saved is not None
        if resumed:
            ckpt.restore(runner, saved)
        monitor = runner.monitors[0]
    report = ProgressFile(progress, case.name, monitor, case.steady.max_time) if progress else None
    res = runner.run(quiet=quiet, on_step=chain(ckpt, report))
    if report is not None:
        report.write(runner, res.status)
    front_ds = monitor.dataset()
    if res.status == "completed" and not front_ds.attrs["steady"]:
        res.status = "not_steady"
        res.reason = f"no steady state by max_time = {case.steady.max_time:g} s: " + monitor.why_not_steady()
    run_ds = to_dataset(res)
    # keep only the final snapshot (the particle distribution of the paper's Fig. 7)
    if "snapshot" in run_ds.dims and run_ds.sizes["snapshot"] > 1:
        run_ds = run_ds.isel(snapshot=[-1])
    run_ds = run_ds.rename({"time": "diag_time"})
    ds = xr.merge([front_ds, run_ds], combine_attrs="override")
    ds.attrs.update(run_ds.attrs)
    ds.attrs.update({
        "title": f"sph-surge conveyor-belt front, case '{case.name}'",
        "h_n_m": case.h_n, "normalising_depth_m": case.normalising_depth, "belt_speed_m_s": case.belt.speed,
        "slope_deg": case.slope_deg, "ch": case.ch, "shifting": case.shifting,
        "simulated_time_s": float(runner.sim.t), "resumed_from_checkpoint": int(resumed),
        "case_yaml": case.to_yaml(),
        "warm_start": warm_note or (f"from {case.warm_from}" if case.start == "warm" else "no"),
        "start_body_depth_h_n": scheme_fluid(case, flux_ratio).h_n / case.h_n if used else math.nan,
        "start_flux_ratio": flux_ratio, "start_depth": depth_note,
        "n_fluid": int(runner.sim.n_fluid), "n_boundary": int(runner.sim.n - runner.sim.n_fluid),
    })
    return ds


def detector_record(case: ConveyorCase, x_star, t, toe, depth, surface, velocity) -> steady.Record:
    """The detector's quantities from probe samples: depth and surface [m] over h_n, the surface
    over x* up to the uniform zone's end (zeta_fs's range)."""
    hn = case.h_n
    x_detect = np.asarray(x_star) <= case.probes.uniform_zone[1] + 1e-9
    return steady.Record(np.asarray(t, dtype=float), np.asarray(toe, dtype=float),
                         np.asarray(depth, dtype=float) / hn, np.asarray(surface, dtype=float)[:, x_detect] / hn,
                         np.asarray(velocity, dtype=float))


def record_of(ds: xr.Dataset, case: ConveyorCase) -> steady.Record:
    """The detector's quantities (``FrontMonitor.record``) from a run's probe series."""
    return detector_record(case, ds["x_star"].values, ds["time"].values, ds["toe_position"].values,
                           ds["uniform_depth"].values, ds["surface_elevation"].values, ds["velocity_star"].values)


def recorded_case(ds: xr.Dataset, sets=()) -> ConveyorCase:
    """The case a run recorded (``case_yaml``), with ``sets`` (KEY=VALUE, as --set) applied; a
    record's steady keys that the detection no longer reads are left out, so that an older run
    replays with today's rule (and its own recorded steady.average as W, and min_time)."""
    import yaml
    from dataclasses import fields
    from .overrides import apply_overrides
    from .conveyor import Steady, case_from_dict
    d = yaml.safe_load(ds.attrs["case_yaml"])
    known = {f.name for f in fields(Steady)}
    d["steady"] = {k: v for k, v in (d.get("steady") or {}).items() if k in known}
    return case_from_dict(apply_overrides(d, sets))


def replay(ds: xr.Dataset, case: ConveyorCase | None = None, crit: steady.SteadyCriteria | None = None):
    """The first steady window pair the detector finds on a run's probe series (None: none),
    with the criteria of the run's own case unless ``crit`` is given."""
    if case is None:
        case = recorded_case(ds)
    rec = record_of(ds, case)
    det = steady.SteadyDetector(crit or case.criteria())
    w = det.crit.window
    for k in range(rec.t.size):
        span = 2.0 * w + det.crit.context + case.probes.interval
        if det.update(rec.span(rec.t[k] - span if k else -math.inf, rec.t[k])):
            break
    return det.found
