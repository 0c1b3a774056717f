"""A user's scene (docs/flow-user.md): any scene file run at the grid's dp and Ch, against the
user's front, depth or velocity data in CSV files."""
from __future__ import annotations

import html

import xarray as xr

from ..grid import Case
from ..references import user as reference
from ..schema import ConfigError
from . import measure, scores
from .scene import REQUIRED, SceneFlow, newtonian, numerics, positive

KINDS = ("front", "depth", "velocity")
READERS = {"front": reference.read_front, "depth": reference.read_depth_profiles,
           "velocity": reference.read_velocity_profiles}


def read_references(scene: dict) -> dict:
    """{kind: DataArray} of the reference files (study.references.user readers); ConfigError
    naming the key of a file that cannot be read, with its line."""
    out = {}
    for kind, path in scene["reference"].items():
        try:
            out[kind] = READERS[kind](path)
        except (OSError, ValueError) as exc:
            raise ConfigError(f"config key scene.reference.{kind}: {exc}") from None
    return out


class User(SceneFlow):
    name = "user"
    title = "a user's scene against the user's reference data"
    scene_keys = {
        "file": (REQUIRED, lambda v: isinstance(v, str), "the scene YAML file"),
        "speed": (REQUIRED, positive, "the flow's velocity scale, m/s (surge's shifting floor is half of it)"),
        "reference": (REQUIRED, lambda v: isinstance(v, dict) and bool(v), "CSV files: front, depth, velocity"),
        "front_from": (0.0, lambda v: isinstance(v, (int, float)) and v >= 0,
                       "the front is compared from this time, s"),
        "symmetric": (False, lambda v: isinstance(v, bool), "a two-sided release about x = 0"),
    }

    def file_keys(self, cfg: dict) -> list[tuple]:
        scene = cfg.get("scene") or {}
        keys = [("scene", "file")] if isinstance(scene.get("file"), str) else []
        ref = scene.get("reference")
        return keys + ([("scene", "reference", k) for k, v in ref.items() if isinstance(v, str)]
                       if isinstance(ref, dict) else [])

    def check(self, cfg: dict) -> None:
        for k in cfg["scene"]["reference"]:
            if k not in KINDS:
                raise ConfigError(f"config key scene.reference.{k}: not a kind of reference; "
                                  f"allowed: {', '.join(KINDS)}")
        read_references(cfg["scene"])  # a malformed file is refused now, with its line
        if cfg.get("fluids"):
            raise ConfigError("config key fluids: flow user takes its fluid from its scene file (scene.file)")

    def scene(self, cfg: dict, case: Case) -> dict:
        from solver.scene import read_yaml
        s = cfg["scene"]
        d = read_yaml(s["file"]) or {}
        if not isinstance(d, dict):
            raise ConfigError(f"config key scene.file: {s['file']} does not hold a scene mapping")
        fl = d.get("fluid", {})
        depth = (d.get("sound") or {}).get("depth") or 15.0 * case.dp
        d.update(name=case.id, dp=case.dp, ch=case.ch)
        d["numerics"] = numerics(case.scheme, s["speed"], newtonian(fl), depth / case.dp, case.shifting,
                                 own=d.get("numerics"))
        return d

    def errors_of(self, cfg: dict, fluid: dict | None) -> tuple[str, ...]:
        kinds = cfg["scene"]["reference"]
        return tuple(f"{k}_error" for k in KINDS if k in kinds)

    def measure(self, cfg: dict, case: Case, run: xr.Dataset):
        s = cfg["scene"]
        values = scores.user_scores(run, read_references(s), s["front_from"], s["symmetric"])
        series = measure.front(run, symmetric=s["symmetric"]) if "front" in s["reference"] else None
        return values, series

    def reference_text(self, cfg: dict, ds: xr.Dataset) -> str:
        s = cfg["scene"]
        refs = ", ".join(f"{k}: {html.escape(str(v))}" for k, v in s["reference"].items())
        return (f"<p>Scene {html.escape(s['file'])}; reference files {refs} (docs/flow-user.md gives their "
                f"format). Front error: RMS of x_N / x_ref - 1 over the reference times from {s['front_from']:g} s; "
                "a depth profile at its time, a velocity profile at its station at the run's last snapshot, each "
                "as the RMS of the difference over the reference's largest value; a kind's error is the RMS over "
                "its profiles.</p>")

    def front_figure(self, cfg: dict) -> str | None:
        if "front" in cfg["scene"]["reference"]:
            return "x_N(t) of every run against the reference front (points)."
        return None

    def front_reference(self, ax, cfg: dict, fluid: dict, ds: xr.Dataset, name: str) -> None:
        ref = read_references(cfg["scene"])["front"]
        ax.plot(ref["t"], 1000 * ref, "ko", ms=4, label="reference (CSV)")


FLOW = User()
