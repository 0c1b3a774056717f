"""A running simulation: particle state kept sorted by cell, one step at a time."""
from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np

from . import boundary, cells, forces, guards, implicit, integrate, packing, rheology, shifting
from .build import Particles, build_particles
from .kernel import alpha_2d
from .scene import MAX_SHIFT, SURFACE_THRESHOLD, Scene

_STRESS = ("sxx", "sxz", "szx", "szz")  # the stress form's last transpose stress
_SORTED = ("x", "z", "u", "w", "rho", "mass", "drho_prev", "kind", "wall", "gx", "gz", "pid")
_SHIFTING = ("cell_volume", "wnx", "wnz")  # read by the shifting sums alone
_SHIFT = ("shift_dx", "shift_dz")  # the last shift, pending its density correction
_IMPLICIT = ("implicit_cx", "implicit_cz")  # the last implicit correction, CG's next start
_VISCOUS = ("viscous_scale", "viscous_cx", "viscous_cz")  # the consistent laminar term's factors


def default_domain(scene: Scene) -> tuple[float, float, float, float]:
    """Fluid and walls' bounding box, 4h beyond on the sides and below, and half the
    height (at least 4h) above."""
    rects = scene.fluid.extents() + list(scene.walls)
    x0 = min(r.x[0] for r in rects)
    x1 = max(r.x[1] for r in rects)
    z0 = min(r.z[0] for r in rects)
    z1 = max(r.z[1] for r in rects)
    m = 4.0 * scene.h
    if scene.domain is not None:
        x0, x1, z0, z1 = (*scene.domain.x, *scene.domain.z)
    else:
        x0, x1, z0, z1 = x0 - m, x1 + m, z0 - m, z1 + max(0.5 * (z1 - z0), m)
    if scene.periodic_x is not None:
        x0, x1 = scene.periodic_x
    return x0, x1, z0, z1


@dataclass
class StepInfo:
    dt: float = 0.0
    limit: int = 0
    dt_limits: tuple = (0.0, 0.0, 0.0)


class Simulation:
    """Owns the particle arrays and advances them by docs/scheme.md section 6."""

    def __init__(self, scene: Scene, particles: Particles | None = None):
        self.scene = scene
        p = particles if particles is not None else build_particles(scene)
        self.n = p.n
        self.x, self.z, self.u, self.w = p.x.copy(), p.z.copy(), p.u.copy(), p.w.copy()
        self.rho, self.mass, self.cell_volume = p.rho.copy(), p.mass.copy(), p.cell_volume.copy()
        self.kind, self.wall, self.pid = p.kind.copy(), p.wall.copy(), p.pid.copy()
        self.gx, self.gz = p.gx.copy(), p.gz.copy()
        # inward wall normal of each boundary particle (towards its ghost node)
        gdx, gdz = np.nan_to_num(p.gx - p.x), np.nan_to_num(p.gz - p.z)
        norm = np.hypot(gdx, gdz)
        safe = np.where(norm > 0, norm, 1.0)
        self.wnx, self.wnz = np.where(norm > 0, gdx / safe, 0.0), np.where(norm > 0, gdz / safe, 0.0)
        self.drho_prev = np.zeros(self.n)
        self.n_fluid = int((self.kind == 0).sum())
        # each particle's kinematic viscosity (Herschel-Bulkley: from the last strain rate;
        # at rest the cap mu_max / rho0)
        self.nu_p = np.full(self.n, scene.nu)
        self.nu_max_now = scene.nu

        s = scene
        self.h, self.rho0, self.c0, self.nu = s.h, s.fluid.density, s.c0, s.nu
        self.B = self.c0 ** 2 * self.rho0 / 7.0
        num = s.numerics
        self.delta = num.density_diffusion or 0.0
        self.diffusion = self.delta > 0
        self.shift_method = num.shifting.method
        shifting_on = self.shift_method != "none"
        self.viscous_correction = bool(num.viscous_correction)
        # each particle's laminar factor and first-order correction c, from the last evaluation
        # (viscous_correction; ``forces.viscous_scale_factors``)
        self.viscous_scale = np.ones(self.n if self.viscous_correction else 1)
        self.viscous_cx = np.zeros(self.n if self.viscous_correction else 1)
        self.viscous_cz = np.zeros(self.n if self.viscous_correction else 1)
        self.variable_viscosity = not s.fluid.newtonian
        self.strain_correction = self.variable_viscosity and bool(s.fluid.strain_rate_correction)
        # the last strain rate (strain_rate_correction; a placeholder otherwise)
        self.gamma_p = np.zeros(self.n if self.strain_correction else 1)
        self.implicit = s.implicit_viscosity
        # the stress form's transpose term (nothing to add where the viscosity is one constant)
        self.stress_form = self.variable_viscosity and num.viscous_form == "stress"
        # its transpose stress S = nu (grad u)^T from the last evaluation (placeholders otherwise)
        for name in _STRESS:
            setattr(self, name, np.zeros(self.n if self.stress_form else 1))
        self.volume_relaxation = num.volume_relaxation or 0.0
        self.mdbc = num.boundary == "mdbc"
        self.cfl_acoustic = s.cfl_acoustic  # C of the acoustic limit (cfl_rule)
        # the pair loop's compile-time switches (``forces.PairOptions``) and its slots
        self.pair_options = forces.PairOptions(
            diffusion=(2 if num.density_diffusion_reference == "column" else 1) if self.diffusion else 0,
            packing=2 if self.volume_relaxation > 0 else (1 if shifting_on else 0),
            laminar_correction=self.viscous_correction,
            rheology=(2 if self.strain_correction else 1) if self.variable_viscosity else 0,
            stress=self.stress_form,
            artificial=bool(num.artificial_viscosity),
            implicit_walls=(2.0 if self.mdbc else 1.0) if self.implicit else 0.0)
        self.slots = forces.slot_layout(self.pair_options)
        self.nq = self.slots.nq
        self.pair_loop = forces.make_pair_loop(self.pair_options)
        self.substeps = s.viscous_substeps  # RKC stages rather than CG (no CG start to carry)
        self.sorted_fields = (_SORTED + (_SHIFTING + _SHIFT if self.pair_options.packing else ())
                              + (("nu_p",) if self.variable_viscosity else ())
                              + (("gamma_p",) if self.strain_correction else ())
                              + (_STRESS if self.stress_form else ())
                              + (_VISCOUS if self.viscous_correction else ())
                              + (_IMPLICIT if self.implicit and not self.substeps else ()))
        self.solver_iterations = 0  # CG iterations of the implicit viscous solves, summed
        self.rkc_stages = 0  # stages of the sub-stepped viscous updates, summed
        self.mdbc_update = boundary.make_mdbc_update(num.mdbc_velocity == "corrected",
                                                     bool(num.no_penetration))
        self.n_lattice = boundary.lattice_number_density(s.ch)

        x0, x1, z0, z1 = default_domain(s)
        self.domain = (x0, x1, z0, z1)
        self.grid = cells.Grid.cover(x0, x1, z0, z1, 2.0 * self.h, s.periodic_x is not None)
        self.walls = np.array([[w.x[0], w.x[1], w.z[0], w.z[1]] for w in s.walls]).reshape(-1, 4)
        self.moving = np.array([w.moving for w in s.walls] or [False])
        # wall velocities are constant once every ramp has ended
        self.ramps_end = max([w.ramp_delay + w.ramp_time for w in s.walls] or [0.0])
        self.vwall_final = boundary.wall_velocities(s.walls, self.ramps_end)

        self.nthreads = nb.get_num_threads()
        # implicit viscosity: the pair loop's list of fluid pairs, CG scratch
        cap = implicit.pair_capacity(self.n, s.ch, self.nthreads) if self.implicit else 0
        self.pairs = forces.pair_list(self.nthreads, cap)
        if self.implicit:
            self.product_shares = implicit.product_shares(self.nthreads, self.n)
            rows = implicit.SUBSTEP_WORK_ROWS if self.substeps else implicit.WORK_ROWS
            self.solver_work = np.zeros((rows, self.n))
        cg = self.implicit and not self.substeps
        self.implicit_cx = np.zeros(self.n if cg else 1)
        self.implicit_cz = np.zeros(self.n if cg else 1)
        self.acc = np.zeros((self.nthreads, self.n, self.nq))
        self.out = np.zeros((self.nq, self.n))
        self.vmax_t = np.zeros(self.nthreads)
        self.split = np.zeros(self.nthreads + 1, dtype=np.int64)
        self.cell = np.zeros(self.n, dtype=np.int64)
        self.order = np.zeros(self.n, dtype=np.int64)
        self.start = np.zeros(self.grid.ncells + 2, dtype=np.int64)
        self.cells = self.grid.cell_list(self.start)  # start is refilled in place by each sort
        self.constants = forces.PairConstants(
            h=self.h, nu=self.nu, hc0=self.h * self.c0, rho0=self.rho0,
            k_hyd=self.rho0 * s.gravity[1] / self.B, k_col=self.rho0 * s.gravity[1] / self.c0 ** 2,
            delta=self.delta, av=(num.artificial_viscosity or 0.0) * self.h * self.c0)
        self.p = np.zeros(self.n)
        self.irho = np.zeros(self.n)  # 1 / rho, for the pair loop
        self.shift_dx = np.zeros(self.n)
        self.shift_dz = np.zeros(self.n)
        self.surface_flag = np.zeros(self.n, dtype=np.int8)
        self.near_flag = np.zeros(self.n, dtype=np.int8)
        tangential = shifting_on and num.shifting.near_surface == "tangential"
        self.surface_nx = np.zeros(self.n if tangential else 1)  # lind's surface normals
        self.surface_nz = np.zeros(self.n if tangential else 1)
        self.wall_s0 = shifting.wall_proximity_at_half_dp(self.h, s.dp)
        self._buf = {}  # one spare buffer for each dtype of the sorted fields
        for name in self.sorted_fields:
            a = getattr(self, name)
            self._buf.setdefault(a.dtype, np.empty(self.n, a.dtype))
        self.health = np.zeros(4)
        self.n_active = self.n

        self.t = 0.0
        self.steps = 0
        self.info = StepInfo()
        self.reason = ""
        self._evaluate(0.0)
        self.drho_prev[:] = self.out[forces.DRHO]
        self._update_dt()
        self.dt_first = self.info.dt

    # ---- pieces of a step -----------------------------------------------------
    def _sort(self) -> str:
        g = self.grid
        bad = cells.assign_cells(self.x, self.z, self.kind, self.cells, self.cell)
        if bad >= 0:
            return (f"a fluid particle left the domain x in [{self.domain[0]:.4g}, {self.domain[1]:.4g}], "
                    f"z in [{self.domain[2]:.4g}, {self.domain[3]:.4g}] m at "
                    f"({self.x[bad]:.4g}, {self.z[bad]:.4g})")
        cells.counting_sort(self.cell, g.ncells + 1, self.order, self.start)
        cells.sort_cells_by(self.z, self.order, self.start, g.ncells)  # the pair loop's z windows
        bufs, order = self._buf, self.order
        for name in self.sorted_fields:  # each through its dtype's spare buffer, which it then becomes
            arr = getattr(self, name)
            buf = bufs[arr.dtype]
            cells.gather(arr, order, buf)
            setattr(self, name, buf)
            bufs[arr.dtype] = arr
        self.n_active = int(self.start[g.ncells])
        self.drho_prev[self.n_active:] = 0.0
        cells.column_split(self.cells, self.nthreads, self.split)
        return ""

    def wall_velocities(self, t: float) -> np.ndarray:
        return self.vwall_final if t >= self.ramps_end else boundary.wall_velocities(self.scene.walls, t)

    def _evaluate(self, t: float) -> str:
        """Sort, set wall particles, and compute accelerations and drho/dt at time t."""
        reason = self._sort()
        if reason:
            return reason
        s = self.scene
        self._set_walls(t)
        forces.pressure_and_inverse_density(self.rho, self.p, self.irho, self.B, self.rho0)
        fields = forces.PairFields(self.x, self.z, self.u, self.w, self.rho, self.p, self.mass, self.kind,
                                   self.wnx, self.wnz, self.shift_dx, self.shift_dz, self.nu_p,
                                   self.gamma_p, self.cell_volume, self.irho, self.viscous_scale,
                                   self.viscous_cx, self.viscous_cz,
                                   self.sxx, self.sxz, self.szx, self.szz)
        self.pair_loop(fields, self.cells, self.split, self.constants, self.acc, self.vmax_t, *self.pairs)
        if self.implicit and self.pairs.count.max() > self.pairs.i.shape[1]:
            # more pairs than the list holds: widen it and evaluate again
            cap = int(1.25 * self.pairs.count.max())
            self.pairs = forces.pair_list(self.nthreads, cap)
            self.pair_loop(fields, self.cells, self.split, self.constants, self.acc, self.vmax_t, *self.pairs)
        self.amax = forces.reduce_accumulators(self.acc, self.kind, self.split, self.cells,
                                               s.gravity[0], s.gravity[1], self.out, self.n)
        self.vmax = float(self.vmax_t.max())
        if self.viscous_correction:  # the factors of the next evaluation
            forces.viscous_scale_factors(self.out, self.kind, self.n_active, self.slots, self.nu,
                                         self.viscous_scale, self.viscous_cx, self.viscous_cz)
        if self.stress_form:  # the divergence of the last evaluation's transpose stress
            self.amax = max(self.amax, forces.add_stress_transpose(
                self.out, self.kind, self.rho, self.rho0, self.n_active, self.slots))
        if self.variable_viscosity:  # the viscosity of the next evaluation
            fl = s.fluid
            self.nu_max_now = rheology.update_viscosity(
                self.out, self.kind, self.nu_p, self.n_active, self.rho0, fl.yield_stress,
                fl.consistency, fl.index, fl.max_viscosity, fl.papanastasiou or 0.0, self.gamma_p,
                rheology.SMOOTHING_KAPPA * self.h ** 2 if self.strain_correction else 0.0, self.slots)
            self.store_stress_transpose()
        if self.shift_method != "none":
            self._correct_density()
        return ""

    def store_stress_transpose(self) -> None:
        """S = nu (grad u)^T of each fluid particle from this evaluation's gradient and nu_p,
        for the next evaluation's stress form (``forces.store_stress_transpose``); nothing without it."""
        if self.stress_form:
            forces.store_stress_transpose(self.out, self.kind, self.nu_p, self.n_active, self.slots,
                                          self.sxx, self.sxz, self.szx, self.szz)

    def _set_walls(self, t: float):
        """Wall particles' velocity (and, with mDBC, density) from the fluid at time t."""
        if self.mdbc:
            self.mdbc_update(self.x, self.z, self.u, self.w, self.rho, self.mass, self.kind,
                             self.wall, self.gx, self.gz, self.wall_velocities(t), self.cells,
                             self.n_active, self.h, self.rho0, self.scene.dp * self.scene.dp, self.n_lattice)
        else:
            boundary.dbc_velocity(self.kind, self.wall, self.wall_velocities(t), self.u, self.w,
                                  self.n_active)

    def viscous_operator(self) -> tuple:
        """The laminar operator C of the last evaluation (``implicit.operator``)."""
        return implicit.operator(self.pairs, self.cells, self.split, self.out[self.slots.DIAG], self.mass,
                                 self.product_shares)

    def _solve_viscous(self, dt: float) -> str:
        """Replace the evaluation's accelerations by (v^{n+1} - v^n) / dt of backward Euler in
        the laminar term (or, sub-stepped, of its RKC integration over the step); the force
        limit of the next step takes their maximum."""
        o = self.out
        n = self.n_active
        op = self.viscous_operator()
        if self.substeps:  # RKC stages instead of the backward-Euler solve
            self.rkc_stages += implicit.substep(op, self.kind, dt, o[forces.AX], o[forces.AZ], n,
                                                self.solver_work)
            self.amax = float(implicit.largest_fluid_acceleration(o[forces.AX], o[forces.AZ], self.kind, n))
            return ""
        it, res = implicit.solve(op, self.kind, dt, o[forces.AX], o[forces.AZ], self.implicit_cx,
                                 self.implicit_cz, n, implicit.TOLERANCE, implicit.MAX_ITERATIONS,
                                 self.solver_work)
        self.solver_iterations += it
        if not res <= implicit.TOLERANCE:
            return (f"implicit viscous solve: relative residual {res:.3g} after {it} iterations "
                    f"(tolerance {implicit.TOLERANCE:g})")
        self.amax = float(implicit.largest_fluid_acceleration(o[forces.AX], o[forces.AZ], self.kind, n))
        return ""

    def _correct_density(self):
        """rho *= 1 - div(dr) for the last shift dr, with div(dr) summed in this evaluation's
        pair loop, one step after the shift (positions have moved by dt v since, about
        0.01 dp per step on the paper case), limited per step; the shift is then consumed."""
        shifting.limit_correction(self.rho, self.kind, self.out[self.slots.DIVDR], self.n_active,
                                  self.scene.shift_correction_limit)
        self.shift_dx[:] = 0.0
        self.shift_dz[:] = 0.0

    def _relax_volume(self, dt: float):
        """The interior density towards the particles' packing (``packing.relax_density``)."""
        o, sl = self.out, self.slots
        packing.relax_density(self.rho, self.mass, self.kind, o[sl.VOLC], o[sl.GCX], o[sl.GCZ], self.n_active,
                              alpha_2d(self.h), self.h,
                              self.n_lattice, self.volume_relaxation * self.c0 * dt / self.h)

    def _update_dt(self):
        dt, k, lim = integrate.time_step(self.scene.numerics.cfl, self.h, self.amax, self.vmax, self.c0,
                                         self.nu_max_now,
                                         viscous_limit=not self.implicit,
                                         cfl_acoustic=self.cfl_acoustic)
        self.info = StepInfo(dt, k, lim)

    def _shift(self, dt: float):
        if self.shift_method == "none":
            return
        sh = self.scene.numerics.shifting
        A = self.scene.shifting_coefficient
        o, sl = self.out, self.slots
        gcx, gcz, divr = o[sl.GCX], o[sl.GCZ], o[sl.DIVR]
        wnx, wnz = o[sl.WNX], o[sl.WNZ]
        clip = MAX_SHIFT * self.scene.dp
        if self.shift_method == "skillen":
            shifting.skillen_shift(self.kind, self.u, self.w, gcx, gcz, divr, wnx, wnz, self.wall_s0,
                                   self.n_active, A, self.h, dt, SURFACE_THRESHOLD, clip,
                                   sh.min_speed, self.shift_dx, self.shift_dz)
        elif self.shift_method == "lind":
            shifting.free_surface(self.x, self.z, self.kind, gcx, gcz, divr, self.cells,
                                  self.n_active, self.h, SURFACE_THRESHOLD, shifting.SCAN_UPPER,
                                  self.surface_flag)
            D = 0.5 * A * self.h * self.h
            if sh.near_surface == "tangential":  # the near-surface flags with the normals, one pass
                shifting.surface_normals(self.x, self.z, self.kind, self.surface_flag, gcx, gcz, self.cells,
                                         self.n_active, self.h, self.near_flag, self.surface_nx,
                                         self.surface_nz)
                shifting.lind_shift_tangential(self.kind, gcx, gcz, self.near_flag, self.surface_flag, self.surface_nx,
                                               self.surface_nz, wnx, wnz, self.wall_s0, self.n_active, D, clip,
                                               self.shift_dx, self.shift_dz)
            else:
                shifting.near_surface(self.x, self.z, self.kind, self.surface_flag, self.cells,
                                      self.n_active, self.h, self.near_flag)
                shifting.lind_shift(self.kind, gcx, gcz, self.near_flag, wnx, wnz, self.wall_s0,
                                    self.n_active, D, clip, self.shift_dx, self.shift_dz)
        # the density follows the volume change of the shift at the next evaluation
        self.x[:self.n_active] += self.shift_dx[:self.n_active]
        self.z[:self.n_active] += self.shift_dz[:self.n_active]

    def _wrap(self):
        if self.grid.periodic:
            integrate.wrap_periodic(self.x, self.gx, self.grid.x0, self.grid.period)

    # ---- one step -------------------------------------------------------------
    def step(self, dt: float | None = None) -> str:
        """Advance by dt (default: the CFL step). Returns a divergence reason or ''."""
        dt = self.info.dt if dt is None else dt
        s = self.scene
        t = self.t
        vw = self.wall_velocities(t)
        integrate.drift(self.x, self.z, self.u, self.w, self.kind, self.wall, self.gx, self.gz,
                        vw, self.moving, 0.5 * dt, self.n)
        integrate.advance_density(self.rho, self.drho_prev, self.n_active, 0.5 * dt)
        self._wrap()
        reason = self._evaluate(t + 0.5 * dt)
        if not reason and self.implicit:
            reason = self._solve_viscous(dt)
        if reason:
            return self._stop(reason)
        if self.volume_relaxation:
            self._relax_volume(dt)
        o = self.out
        integrate.kick(self.u, self.w, self.rho, self.kind, o[forces.AX], o[forces.AZ], o[forces.DRHO],
                       self.drho_prev, self.n_active, dt, self.rho0, not self.mdbc,
                       bool(s.numerics.no_tension))
        vw = self.wall_velocities(t + dt)
        integrate.drift(self.x, self.z, self.u, self.w, self.kind, self.wall, self.gx, self.gz,
                        vw, self.moving, 0.5 * dt, self.n)
        if self.shift_method != "none":
            self._shift(dt)
        self._wrap()
        self.t = t + dt
        self.steps += 1
        reason = self.health_reason()
        if reason:
            return self._stop(reason)
        self._update_dt()
        reason = guards.check_dt(self.info.dt, self.dt_first, s.guards)
        if reason:
            return self._stop(reason)
        return ""

    def _stop(self, reason: str) -> str:
        self.reason = f"t = {self.t:.6g} s, step {self.steps}: {reason}"
        return self.reason

    def health_reason(self) -> str:
        """The guards' reason to stop (``guards.check``), a density deviation with where its
        largest value lies; '' when the state is sound."""
        reason = guards.check(self.check_health(), self.scene.guards, self.scene.dp)
        if reason.startswith("density deviation"):
            reason += guards.worst_density(self.x, self.z, self.rho, self.kind, self.n_active, self.rho0)
        return reason

    def check_health(self) -> np.ndarray:
        g = self.grid
        guards.fluid_health(self.x, self.z, self.u, self.w, self.rho, self.mass, self.kind, self.n_active,
                            self.rho0, self.walls, g.periodic, g.x0, g.period, self.health)
        return self.health

    # ---- checkpoint -------------------------------------------------------------------
    _STATE = _SORTED + _SHIFTING + _SHIFT + _IMPLICIT + _STRESS + _VISCOUS + (
        "nu_p", "gamma_p", "nu_max_now", "t", "steps", "info", "dt_first", "n_active", "reason")

    def state(self) -> dict:
        """Everything needed to resume exactly where this simulation stands."""
        return {k: (v.copy() if isinstance(v, np.ndarray) else v)
                for k, v in ((k, getattr(self, k)) for k in self._STATE)}

    def restore(self, state: dict) -> None:
        for k in self._STATE:
            v = state[k]
            setattr(self, k, v.copy() if isinstance(v, np.ndarray) else v)

    # ---- for tests and tools -------------------------------------------------------
    def derivatives(self) -> dict[str, np.ndarray]:
        """Evaluate at the current state; ax, az, drho (and gradC_x, gradC_z, div_r with
        shifting on), in original particle order."""
        reason = self._evaluate(self.t)
        if reason:
            raise RuntimeError(reason)
        names = {"ax": "AX", "az": "AZ", "drho": "DRHO", "gradC_x": "GCX", "gradC_z": "GCZ", "div_r": "DIVR",
                 "wall_nx": "WNX", "wall_nz": "WNZ", "div_dr": "DIVDR"}
        inv = self._inverse_order()
        return {k: self.out[getattr(self.slots, q)][inv].copy() for k, q in names.items()
                if getattr(self.slots, q) >= 0}

    def shift_only(self, dt: float) -> None:
        """Apply one shifting displacement (no time integration), as if over a step dt."""
        self._evaluate(self.t)
        self._shift(dt)
        self._wrap()

    def _inverse_order(self) -> np.ndarray:
        inv = np.empty(self.n, dtype=np.int64)
        inv[self.pid] = np.arange(self.n)
        return inv

    # ---- views -----------------------------------------------------------------
    def pressure(self) -> np.ndarray:
        forces.equation_of_state(self.rho, self.p, self.B, self.rho0)
        return self.p

    def snapshot(self) -> dict[str, np.ndarray]:
        """Particle fields in original particle order (fluid first, then walls)."""
        inv = self._inverse_order()
        p = self.pressure()
        fields = dict(x=self.x, z=self.z, u=self.u, w=self.w, rho=self.rho, p=p, kind=self.kind)
        if self.variable_viscosity:  # the effective viscosity: where the fluid has yielded
            fields["mu"] = self.nu_p * self.rho0
        return {k: v[inv].copy() for k, v in fields.items()}
