"""The consistent laminar term (physics.viscous_correction): first-order exact on disorder,
unchanged on a lattice."""
import numpy as np

from solver.build import build_particles
from solver.simulation import Simulation
from tests.conftest import example_scene
import pytest

pytestmark = pytest.mark.slow  # runs the solver or Snakemake


def linear_shear_residual(correction: bool, jitter: float) -> tuple[np.ndarray, float]:
    """Couette channel at rest pressure (rho = rho0) with u = U0 z / L on fluid particles
    moved by up to ``jitter`` dp: its exact viscous acceleration is zero. Returns a_x of the
    interior (2.5 h from the walls) and the first-order error scale nu U0 / (L dp)."""
    sc = example_scene("couette", physics={"viscous_correction": correction, "density_diffusion": None})
    p = build_particles(sc)
    fl = p.kind == 0
    L, U0 = 1.0e-3, sc.walls[1].velocity[0]
    rng = np.random.default_rng(0)
    p.x[fl] += rng.uniform(-jitter, jitter, fl.sum()) * sc.dp
    p.z[fl] += rng.uniform(-jitter, jitter, fl.sum()) * sc.dp
    p.u[fl] = U0 * p.z[fl] / L
    p.rho[:] = sc.fluid.density
    sim = Simulation(sc, p)
    d = sim.derivatives()
    s = sim.snapshot()
    f = s["kind"] == 0
    z = s["z"][f]
    inner = (z > 2.5 * sc.h) & (z < L - 2.5 * sc.h)
    return d["ax"][f][inner], sc.nu * U0 / (L * sc.dp)


def test_correction_removes_the_first_order_error_of_a_linear_shear_on_disorder():
    """Measured with +-0.15 dp jitter: RMS 0.077 nu U0/(L dp) plain, 0.016 corrected (what
    is left is second order, (1 - M) G . grad u)."""
    plain, scale = linear_shear_residual(False, 0.15)
    corrected, _ = linear_shear_residual(True, 0.15)
    rms = lambda a: float(np.sqrt(np.mean((a / scale) ** 2)))  # noqa: E731
    assert rms(plain) > 0.05  # the error exists on this arrangement
    assert rms(corrected) < 0.3 * rms(plain)


def test_correction_changes_nothing_on_a_lattice():
    plain, scale = linear_shear_residual(False, 0.0)
    corrected, _ = linear_shear_residual(True, 0.0)
    assert np.abs(corrected - plain).max() < 1e-9 * scale
