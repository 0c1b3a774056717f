"""The viscous term with a varying viscosity (``numerics.viscous_form``, docs/numerics.md):
manufactured fields where div(2 mu D) and div(mu grad u) differ, so that only the stress form
gives the exact acceleration. The pair loop is evaluated once on a 40 dp square of fluid with
prescribed velocities and particle viscosities; particles 4h from every edge (2h beyond
the truncated gradients of the edge's own support) are compared with the exact divergence of
the stress."""
import numpy as np
import pytest

from solver import forces
from solver.scene import scene_from_dict
from solver.simulation import Simulation

DP, L, RHO = 1.0e-3, 40e-3, 1000.0
NU0, B = 1.0e-3, 10.0  # nu = nu0 (1 + b x'): +-20 % across the square
TOL = 0.03  # of the acceleration scale a nu0 b: the kernel sums' lattice error at Ch 1.5


def evaluate(form, velocity, viscosity, ch=1.5, update="explicit", dt=1.0e-6):
    """Accelerations (ax, az) of the interior fluid particles and their offsets (x', z') from the
    square's centre, after one pair loop with u, w = velocity(x', z') and nu = viscosity(x', z').
    The stress form's transpose stress S = nu (grad u)^T is the last evaluation's: a first pair
    loop gives grad u, S is stored with the prescribed nu, and the second loop is returned.
    With ``update: implicit`` they are the backward-Euler step's (v^{n+1} - v^n) / dt over ``dt``."""
    sim = Simulation(scene_from_dict({
        "name": "square", "dp": DP, "ch": ch,
        "fluid": {"density": RHO, "rheology": "herschel_bulkley", "yield_stress": 1.0,
                  "consistency": 1.0, "index": 1.0, "max_viscosity": 10.0,
                  "blocks": [{"x": [0.0, L], "z": [0.0, L]}]},
        "gravity": [0.0, 0.0], "sound": {"c0": 10.0},
        "numerics": {"viscous_form": form, "viscous_update": update, "density_diffusion": None,
                     "shifting": {"method": "none"}},
        "time": {"end": 1.0, "output_interval": 1.0}}))
    xc = sim.x - L / 2
    zc = sim.z - L / 2
    sim.u[:], sim.w[:] = velocity(xc, zc)
    sim.nu_p[:] = viscosity(xc, zc)
    sim.rho[:] = RHO
    assert sim._evaluate(0.0) == ""
    xc, zc = sim.x - L / 2, sim.z - L / 2  # sorted by the first loop
    sim.nu_p[:] = viscosity(xc, zc)  # which the rheology replaced
    sim.store_stress_transpose()
    assert sim._evaluate(0.0) == ""
    if update == "implicit":
        assert sim._solve_viscous(dt) == ""
    xc, zc = sim.x - L / 2, sim.z - L / 2
    inner = (sim.kind == 0) & (np.maximum(abs(xc), abs(zc)) < L / 2 - 4 * sim.h)
    return sim.out[forces.AX][inner], sim.out[forces.AZ][inner], xc[inner], zc[inner]


@pytest.mark.parametrize("form", ["laminar", "stress"])
def test_extension_across_a_viscosity_gradient(form):
    """u = (a x', -a z'), nu = nu0 (1 + b x'): div(2 mu D) / rho = (2 a nu0 b, 0), while
    div(mu grad u) / rho = (a nu0 b, 0), half of it: the laminar form misses the extensional
    stress's gradient."""
    a = 1.0
    ax, az, _, _ = evaluate(form, lambda x, z: (a * x, -a * z), lambda x, z: NU0 * (1 + B * x))
    scale = a * NU0 * B
    exact = 2.0 * scale if form == "stress" else scale
    assert np.max(abs(ax - exact)) < TOL * scale, (form, ax.min() / scale, ax.max() / scale)
    assert np.max(abs(az)) < TOL * scale


def test_the_implicit_update_keeps_the_transpose_term_in_its_right_hand_side():
    """With viscous_update: implicit the laminar part is backward Euler and the transpose term
    explicit: over a short step the update's acceleration is the stress form's 2 a nu0 b."""
    a = 1.0
    ax, az, _, _ = evaluate("stress", lambda x, z: (a * x, -a * z), lambda x, z: NU0 * (1 + B * x),
                            update="implicit")
    scale = a * NU0 * B
    assert np.max(abs(ax - 2.0 * scale)) < TOL * scale, (ax.min() / scale, ax.max() / scale)
    assert np.max(abs(az)) < TOL * scale


@pytest.mark.parametrize("form", ["laminar", "stress"])
def test_rigid_rotation_feels_no_viscous_force(form):
    """u = Omega (-z', x'): D = 0, so div(2 mu D) = 0 whatever mu does; the laminar form gives
    grad(mu) . grad u = Omega nu0 (-c, b) for nu = nu0 (1 + b x' + c z'), a torque on a plug."""
    om, c = 1.0, -6.0
    ax, az, _, _ = evaluate(form, lambda x, z: (-om * z, om * x),
                            lambda x, z: NU0 * (1 + B * x + c * z))
    scale = om * NU0 * B
    if form == "stress":
        assert np.max(abs(ax)) < TOL * scale and np.max(abs(az)) < TOL * scale
    else:
        assert np.max(abs(ax - (-om * NU0 * c))) < TOL * scale
        assert np.max(abs(az - om * NU0 * B)) < TOL * scale


def test_plane_shear_is_the_same_in_both_forms():
    """u = (s z'^2, 0), nu = nu0 (1 + b z'): a shear flow with mu = mu(z), where the transpose
    term vanishes: both forms give d/dz(nu du/dz) = 2 s nu0 (1 + 2 b z')."""
    s = 5.0
    for form in ("laminar", "stress"):
        ax, az, _, zc = evaluate(form, lambda x, z: (s * z * z, 0 * z), lambda x, z: NU0 * (1 + B * z))
        exact = 2 * s * NU0 * (1 + 2 * B * zc)
        assert np.max(abs(ax - exact)) < TOL * 2 * s * NU0, form
        assert np.max(abs(az)) < TOL * 2 * s * NU0, form


def test_unknown_form_is_refused_naming_the_key():
    from solver.scene import SceneError
    from tests.conftest import example_dict, merge
    with pytest.raises(SceneError) as exc:
        scene_from_dict(merge(example_dict("bingham"), {"numerics": {"viscous_form": "full"}}))
    assert "numerics.viscous_form" in str(exc.value) and "stress" in str(exc.value)
