"""Pair sums by gathering against the solver's scatter pair loop (tried, not adopted: the
figures are in benchmarks/RESULTS.md). The gather kernel lives here, not in the solver.

The gather: each fluid particle a sums over every particle b within 2h (SPEC section 6, the
terms of ``solver.forces``) and writes only its own row; each pair is evaluated twice, once
from each side, and in exchange the loop over b has no stores but one and no branches, so
that LLVM turns it into vector instructions (checked: vdivpd, vsqrtpd on ymm registers). The
candidates of a are the z window (z_a - 2h, z_a + 2h) of its grid column and of the two beside
it; a candidate beyond 2h contributes exactly zero. Boundary rows are zero (mDBC sets the
walls from their ghosts). The largest h |u_ab . r_ab| / (r^2 + eta^2) is taken as the int64
max of the non-negative floats' bits (a float max does not vectorise). Indices are unsigned
(no negative-index wrap-around) and 1/rho is computed once per particle.

The scatter: ``solver.forces.make_pair_loop`` (each pair once, both rows) plus
``forces.reduce_accumulators``, with its own particle-balanced column split; the gather has a
split balanced on fluid particles. Both are called on the same arrays in turn, --calls times,
the order swapped every call; the first calls' fluid rows are compared (round-off only: the
largest difference over the largest value of each slot, x and z components of one vector
scaled together). One JSON line per configuration.

With --case FILE (a conveyor case, with --set overrides) the arrays are those of that case's
front run after --time seconds of simulated time; otherwise benchmarks/throughput.py's
periodic layer after --warmup steps.

Usage: python benchmarks/gather_sums.py [--ch 1.5 1.8] [--shifting none skillen lind]
           [--threads 2] [--calls 60] [--particles 40000] [--physics KEY=VALUE ...]
       python benchmarks/gather_sums.py --case examples/conveyor_fast.yaml [--set shifting=lind]
           [--time 0.3]
"""
from __future__ import annotations

import argparse
import functools
import json
import math
import sys
import time
from pathlib import Path

import numba
import numba as nb
import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "benchmarks"))
from throughput import layer_scene, set_physics  # noqa: E402

from solver import cells, forces  # noqa: E402
from solver.scene import scene_from_dict  # noqa: E402
from solver.simulation import Simulation  # noqa: E402
from solver.forces import (  # noqa: E402
    AX, AZ, C1, C2, C3, C4, C5, DIVDR, DIVR, DRHO, DUX, DUZ, DWX, DWZ, FASTMATH, GCX, GCZ, SERIES_MAX,
    VDIVR, VGX, VGZ, WNX, WNZ, volume_slot)
from solver.kernel import alpha_2d, grad_coefficient  # noqa: E402


def gather_applies(mdbc: bool, implicit: bool, variable_viscosity: bool, artificial: bool,
                   column_reference: bool, diffusion: bool, k_hyd: float, h: float) -> bool:
    """Whether ``make_gather_loop`` computes this scheme's pair sums: mDBC walls, the
    explicit Newtonian laminar term, no artificial viscosity, and with SPEC's hydrostatic
    reference a series that holds for every pair (|k_hyd| 2h < forces.SERIES_MAX)."""
    spec_reference_ok = not diffusion or column_reference or abs(k_hyd) * 2.0 * h < SERIES_MAX
    return mdbc and not implicit and not variable_viscosity and not artificial and spec_reference_ok


@functools.cache
def make_gather_loop(diffusion: bool, shifting: bool, shift_correction: bool = False,
                     column_reference: bool = False, viscous_correction: bool = False,
                     volume: bool = False):
    """Compile the gather with the same switches as ``forces.make_pair_loop`` (those of the
    schemes ``gather_applies`` to) and the same output slots."""
    VOLC = volume_slot(shifting, shift_correction, viscous_correction)

    @nb.njit(parallel=True, fastmath=FASTMATH)
    def gather_loop(f, cl, split, k, out, vscratch, irho, gx, gz, amax_t, vmax_t):
        """out[q, a] = the pair sums of every fluid particle a (``PairFields`` f,
        ``cells.CellList`` cl, ``forces.PairConstants`` k), gravity (gx, gz) added to the
        acceleration; zero rows for boundary particles. Thread t takes the columns
        [split[t], split[t + 1]); amax_t[t] = its largest |a|, vmax_t[t] = its largest
        h |u_ab . r_ab| / (r^2 + eta^2). vscratch: (threads, m) with m > the largest column."""
        x, z, u, w, rho, p, mass, kind = f.x, f.z, f.u, f.w, f.rho, f.p, f.mass, f.kind
        start, ncx, ncz, periodic, period = cl.start, cl.ncx, cl.ncz, cl.periodic, cl.period
        h, nu, hc0, rho0 = k.h, k.nu, k.hc0, k.rho0
        nq = out.shape[0]
        nt = split.size - 1
        fac = grad_coefficient(h)
        alpha = alpha_2d(h)
        eta2 = 0.01 * h * h
        four_h2 = 4.0 * h * h
        two_h = 2.0 * h
        inv_h = 1.0 / h
        dfac = 2.0 * k.delta * hc0
        for i in nb.prange(start[ncx * ncz]):
            irho[i] = 1.0 / rho[i]
        for t in nb.prange(nt):
            vbuf = vscratch[t]
            vbits = vbuf.view(np.int64)
            vm = 0
            am = 0.0
            los = np.zeros(3, np.int64)
            his = np.zeros(3, np.int64)
            ends = np.zeros(3, np.int64)
            shifts = np.zeros(3)
            for ix in range(split[t], split[t + 1]):
                for s in range(3):  # the columns ix - 1, ix, ix + 1 and their x shifts
                    jx = ix + s - 1
                    shifts[s] = 0.0
                    los[s] = his[s] = ends[s] = 0
                    if jx < 0 or jx >= ncx:
                        if not periodic:
                            continue
                        shifts[s] = -period if jx < 0 else period
                        jx = jx + ncx if jx < 0 else jx - ncx
                    los[s] = his[s] = start[jx * ncz]
                    ends[s] = start[(jx + 1) * ncz]
                for a in range(start[ix * ncz], start[(ix + 1) * ncz]):
                    if kind[a] != 0:
                        for q in range(nq):
                            out[q, a] = 0.0
                        continue
                    xa, za, ua, wa = x[a], z[a], u[a], w[a]
                    ra, pa = rho[a], p[a]
                    ira = 1.0 / ra
                    sxa = sza = 0.0
                    if shift_correction:
                        sxa, sza = f.sdx[a], f.sdz[a]
                    z_lo, z_hi = za - two_h, za + two_h
                    s_ax = s_az = s_drho = 0.0
                    s_gcx = s_gcz = s_divr = s_wnx = s_wnz = s_divdr = 0.0
                    s_vgx = s_vgz = s_dux = s_duz = s_dwx = s_dwz = s_vdivr = 0.0
                    s_volc = 0.0
                    for s in range(3):
                        # a walks its column upwards: both ends of each window only move up
                        lo, hi, end = los[s], his[s], ends[s]
                        while lo < end and z[lo] <= z_lo:
                            lo += 1
                        hi = max(hi, lo)
                        while hi < end and z[hi] < z_hi:
                            hi += 1
                        los[s], his[s] = lo, hi
                        xs = xa - shifts[s]
                        # unsigned indices: no negative-index wrap-around in the loop, which
                        # then vectorises (and no array views, whose reference counts cost)
                        ulo = np.uint64(lo)
                        for j in range(ulo, np.uint64(hi)):
                            dx = xs - x[j]
                            dz = za - z[j]
                            r2 = dx * dx + dz * dz
                            inside = r2 < four_h2
                            q = math.sqrt(r2) * inv_h
                            sq = max(1.0 - 0.5 * q, 0.0)
                            F = fac * sq * sq * sq if inside else 0.0
                            rb = rho[j]
                            kb = kind[j]
                            mb = mass[j]
                            irb = irho[j]
                            Vb = mb * irb
                            du = ua - u[j]
                            dw = wa - w[j]
                            vdotr = du * dx + dw * dz
                            rdotg = F * r2
                            r2e, rsum = r2 + eta2, ra + rb
                            inv_both = 1.0 / (r2e * rsum)  # one division for two reciprocals
                            inv_r2e = rsum * inv_both
                            inv_rsum = r2e * inv_both
                            s_drho += ra * F * vdotr * Vb
                            psum = pa + p[j]
                            if kb == 1:  # a wall pushes, never pulls
                                psum = max(psum, 0.0)
                            pt = psum * (ira * irb) * F
                            vt = 4.0 * nu * rdotg * inv_rsum * inv_r2e
                            s_ax += mb * (-pt * dx + vt * du)
                            s_az += mb * (-pt * dz + vt * dw)
                            vbuf[j - ulo] = abs(h * vdotr * inv_r2e) if inside else 0.0
                            vm = max(vm, vbits[j - ulo])
                            if diffusion:
                                g = dfac * rdotg * inv_r2e if kb == 0 else 0.0  # fluid pairs only
                                if column_reference:
                                    rm = 2.0 * rho0 * inv_rsum
                                    rm2 = rm * rm
                                    s_drho += g * ((ra - rb) - k.k_col * dz * rm2 * rm2 * rm) * Vb
                                else:
                                    xh = k.k_hyd * dz  # forces.hydrostatic_pair's series
                                    x2 = xh * xh
                                    fa = x2 * (C2 + x2 * C4) + xh * (C1 + x2 * (C3 + x2 * C5))
                                    s_drho += g * ((ra - rb) - rho0 * fa) * Vb
                            if shifting:
                                cb = f.cell[j]
                                s_gcx += cb * F * dx
                                s_gcz += cb * F * dz
                                s_divr -= cb * rdotg
                                fw = F if kb == 1 else 0.0
                                s_wnx -= fw * f.wnx[j]
                                s_wnz -= fw * f.wnz[j]
                            if shift_correction:
                                s_divdr += Vb * F * ((f.sdx[j] - sxa) * dx + (f.sdz[j] - sza) * dz)
                            if viscous_correction:
                                s_vgx += Vb * F * dx
                                s_vgz += Vb * F * dz
                                s_vdivr -= Vb * rdotg
                                s_dux -= Vb * du * F * dx
                                s_duz -= Vb * du * F * dz
                                s_dwx -= Vb * dw * F * dx
                                s_dwz -= Vb * dw * F * dz
                            if volume:  # sum_b V_b W_ab without a's own term
                                s4 = sq * sq * sq * sq if (inside and np.int64(j) != a) else 0.0
                                s_volc += Vb * alpha * s4 * (2.0 * q + 1.0)
                    s_ax += gx
                    s_az += gz
                    out[AX, a] = s_ax
                    out[AZ, a] = s_az
                    out[DRHO, a] = s_drho
                    am = max(am, math.sqrt(s_ax * s_ax + s_az * s_az))
                    if shifting:
                        out[GCX, a] = s_gcx
                        out[GCZ, a] = s_gcz
                        out[DIVR, a] = s_divr
                        out[WNX, a] = s_wnx
                        out[WNZ, a] = s_wnz
                    if shift_correction:
                        out[DIVDR, a] = s_divdr
                    if viscous_correction:
                        out[VGX, a] = s_vgx
                        out[VGZ, a] = s_vgz
                        out[VDIVR, a] = s_vdivr
                        out[DUX, a] = s_dux
                        out[DUZ, a] = s_duz
                        out[DWX, a] = s_dwx
                        out[DWZ, a] = s_dwz
                    if volume:
                        out[VOLC, a] = s_volc
            amax_t[t] = am
            vbits[0] = vm
            vmax_t[t] = vbuf[0]

    return gather_loop


def scratch_width(start: np.ndarray, ncx: int, ncz: int) -> int:
    """More than the most particles in one grid column (a window's length is at most that)."""
    cols = start[np.arange(ncx + 1) * ncz]
    return int(np.diff(cols).max(initial=0)) + 1


@nb.njit
def fluid_column_split(kind, cl, nthreads, split):
    """Columns [split[t], split[t+1]) for thread t, balancing fluid particle counts (the
    gather's work: boundary rows cost nothing)."""
    start, ncx, ncz = cl.start, cl.ncx, cl.ncz
    counts = np.zeros(ncx + 1, np.int64)
    for ix in range(ncx):
        c = 0
        for i in range(start[ix * ncz], start[(ix + 1) * ncz]):
            c += kind[i] == 0
        counts[ix + 1] = counts[ix] + c
    total = counts[ncx]
    split[0] = 0
    t = 1
    for ix in range(ncx):
        if t >= nthreads:
            break
        if counts[ix + 1] >= total * t / nthreads:
            split[t] = ix + 1
            t += 1
    while t <= nthreads:
        split[t] = ncx
        t += 1


PAIRS = [(forces.AX, forces.AZ), (forces.GCX, forces.GCZ), (forces.WNX, forces.WNZ),
         (forces.VGX, forces.VGZ), (forces.DUX, forces.DUZ), (forces.DWX, forces.DWZ)]


def slot_differences(ref: np.ndarray, new: np.ndarray) -> np.ndarray:
    """Per slot: max |new - ref| / max |ref|, a vector's components over their joint scale."""
    scale = np.abs(ref).max(axis=1)
    for i, j in PAIRS:
        if j < ref.shape[0]:
            scale[i] = scale[j] = max(scale[i], scale[j])
    return np.abs(new - ref).max(axis=1) / np.where(scale > 0, scale, 1.0)


def layer_state(ch, shifting, warmup, particles, physics) -> Simulation:
    sim = Simulation(scene_from_dict(set_physics(layer_scene(ch, shifting, particles), physics)))
    for _ in range(warmup):
        sim.step()
    return sim


def case_state(case_file: Path, overrides: list[str], sim_time: float) -> Simulation:
    """The simulation of a conveyor case's front run, stopped after ``sim_time`` seconds."""
    from solver import front
    from solver.cli import apply_overrides
    from solver.conveyor import case_from_dict
    from solver.scene import read_yaml

    d = apply_overrides(read_yaml(case_file), overrides)
    d.setdefault("steady", {})["max_time"] = sim_time
    made = []
    init = Simulation.__init__

    def keep(self, *args, **kwargs):
        init(self, *args, **kwargs)
        made.append(self)

    Simulation.__init__ = keep
    try:
        front.run_front(case_from_dict(d))
    finally:
        Simulation.__init__ = init
    return made[-1]


def measure(sim: Simulation, calls: int) -> dict:
    s = sim
    o = s.pair_options
    if o["viscous_scale"] or not gather_applies(s.mdbc, s.implicit, s.variable_viscosity, o["artificial"],
                                                 o["column_reference"], s.diffusion, s.constants.k_hyd, s.h):
        raise SystemExit(f"the gather does not apply to this scheme: {o}")
    loop = make_gather_loop(s.diffusion, o["shifting"], o["shift_correction"], o["column_reference"],
                            o["viscous_correction"], o["volume"])
    g = s.scene.gravity
    forces.pressure_and_inverse_density(s.rho, s.p, s.irho, s.B, s.rho0)
    fields = forces.PairFields(s.x, s.z, s.u, s.w, s.rho, s.p, s.mass, s.kind, s.wnx, s.wnz, s.shift_dx,
                               s.shift_dz, s.nu_p, s.gamma_p, s.cell_volume, s.irho, s.viscous_scale)
    acc = np.zeros((s.nthreads, s.n, s.nq))
    out = np.zeros((s.nq, s.n))
    vmax = np.zeros(s.nthreads)
    split = np.zeros_like(s.split)  # the pair loop's own: particle counts balanced
    cells.column_split(s.cells, s.nthreads, split)
    gout = np.zeros((s.nq, s.n))
    gsplit = np.zeros_like(s.split)  # the gather's: fluid counts balanced
    fluid_column_split(s.kind, s.cells, s.nthreads, gsplit)
    vscratch = np.zeros((s.nthreads, scratch_width(s.start, s.cells.ncx, s.cells.ncz)))
    irho = np.zeros(s.n)
    amax_t, gvmax = np.zeros(s.nthreads), np.zeros(s.nthreads)

    def scatter():
        s.pair_loop(fields, s.cells, split, s.constants, acc, vmax, *s.pairs)
        return forces.reduce_accumulators(acc, s.kind, split, s.cells, g[0], g[1], out, s.n)

    def gathered():
        loop(fields, s.cells, gsplit, s.constants, gout, vscratch, irho, g[0], g[1], amax_t, gvmax)
        return amax_t.max()

    a_ref, a_new = scatter(), gathered()
    fluid = s.kind[:s.n_active] == 0
    diff = slot_differences(out[:, :s.n_active][:, fluid], gout[:, :s.n_active][:, fluid])
    times = {"scatter": [], "gather": []}
    for c in range(calls):
        for name in (("scatter", "gather") if c % 2 == 0 else ("gather", "scatter")):
            tic = time.perf_counter()
            scatter() if name == "scatter" else gathered()
            times[name].append(time.perf_counter() - tic)
    med = {k: float(np.median(v)) * 1e3 for k, v in times.items()}
    return {"ch": s.scene.ch, "shifting": s.shift_method, "threads": s.nthreads, "particles": s.n,
            "fluid": s.n_fluid, "scatter_ms": round(med["scatter"], 3), "gather_ms": round(med["gather"], 3),
            "speedup": round(med["scatter"] / med["gather"], 3),
            "max_slot_difference": float(diff.max()), "amax_rel_difference": abs(a_new - a_ref) / a_ref,
            "vmax_rel_difference": abs(gvmax.max() - vmax.max()) / vmax.max()}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--ch", type=float, nargs="+", default=[1.5, 1.8])
    ap.add_argument("--shifting", nargs="+", default=["none", "skillen", "lind"])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--calls", type=int, default=60)
    ap.add_argument("--warmup", type=int, default=20)
    ap.add_argument("--particles", type=int, default=40000)
    ap.add_argument("--physics", nargs="*", default=[])
    ap.add_argument("--case", type=Path)
    ap.add_argument("--set", action="append", default=[])
    ap.add_argument("--time", type=float, default=0.5)
    a = ap.parse_args(argv)
    numba.set_num_threads(a.threads)
    if a.case:
        row = measure(case_state(a.case, a.set, a.time), a.calls)
        print(json.dumps(dict(row, case=str(a.case), set=a.set, time=a.time)), flush=True)
        return
    for ch in a.ch:
        for shifting in a.shifting:
            row = measure(layer_state(ch, shifting, a.warmup, a.particles, a.physics), a.calls)
            print(json.dumps(dict(row, physics=a.physics)), flush=True)


if __name__ == "__main__":
    main()
