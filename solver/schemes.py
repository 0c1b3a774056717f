"""Named schemes: presets of a conveyor case's numerics, resolved before the case is parsed.

``spec`` is the paper's scheme as docs/scheme.md section 6 writes it (the ``Numerics``
defaults). ``surge`` is the shipped scheme and every case's default: the departures of
docs/numerics.md that let the front settle, at C_CFL 0.6 where h_n holds at least 15 particles
and 0.4 below, started there as the paper starts (a block at rest) and below from the moving
film; for a yield-stress fluid, the implicit laminar term at C = 0.4 with the volume relaxation,
started from the moving film. A case's own keys override its preset's.
"""
from __future__ import annotations

import copy

DEFAULT_SCHEME = "surge"
SKILLEN_MIN_SPEED = 0.5  # surge: Skillen's shifting speed at least this fraction of the belt speed
# surge: C_CFL 0.6 where the normal depth holds at least this many particles (the paper's least
# resolution), 0.4 on coarser grids, where 0.6 held but moved the metrics (docs/numerics.md)
RESOLVED_DEPTH = 15.0
CFL, COARSE_CFL = 0.6, 0.4
# the start: the paper's where h_n holds RESOLVED_DEPTH particles, the moving film below
# (whichever reached the steady state sooner there, docs/numerics.md)
PAPER_START = {"start": "block", "start_velocity": "rest"}
FILM_START = {"start": "lubrication", "start_velocity": "lubrication"}


def _surge(belt_speed: float, newtonian: bool, particles_across: float) -> dict:
    if not newtonian:  # a yield-stress fluid: the viscosity cap would bind an explicit step
        return {
            **FILM_START,
            "numerics": {
                "cfl": 0.4,
                "viscous_update": "implicit",
                "volume_relaxation": 0.1,
                "density_diffusion_reference": "column",
            },
        }
    return {
        **(PAPER_START if particles_across >= RESOLVED_DEPTH else FILM_START),
        "numerics": {
            "cfl": CFL if particles_across >= RESOLVED_DEPTH else COARSE_CFL,
            "cfl_rule": "damping",
            "viscous_update": "substepped",
            "viscous_correction": True,
            "mdbc_velocity": "corrected",
            "volume_relaxation": 0.1,
            "density_diffusion_reference": "column",
            "shifting": {"min_speed": SKILLEN_MIN_SPEED * belt_speed, "near_surface": "tangential"},
        },
    }


SCHEMES = {"spec": lambda belt_speed, newtonian, particles_across: {}, "surge": _surge}


def preset(name: str, belt_speed: float, newtonian: bool = True, particles_across: float = RESOLVED_DEPTH) -> dict:
    """The case keys that scheme ``name`` sets (nested like a case file), for a Newtonian or a
    Herschel-Bulkley fluid; ``belt_speed`` [m/s] scales the speeds it gives in units of u_b, and
    ``particles_across`` (h_n / dp) picks surge's C_CFL."""
    return SCHEMES[name](belt_speed, newtonian, particles_across)


def merge(base: dict, changes: dict) -> dict:
    """``base`` with ``changes`` laid over it, mappings merged key by key."""
    out = copy.deepcopy(base)
    for k, v in changes.items():
        if isinstance(v, dict) and isinstance(out.get(k), dict):
            out[k] = merge(out[k], v)
        else:
            out[k] = copy.deepcopy(v)
    return out
