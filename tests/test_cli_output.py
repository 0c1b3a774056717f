"""CLI and NetCDF output: variables, units, status, atomic write."""
import subprocess
import sys

import numpy as np
import pytest
import xarray as xr

from solver.output import write_atomic


def run_cli(*args):
    return subprocess.run([sys.executable, "-m", "solver", *args], capture_output=True, text=True)


@pytest.mark.slow
def test_cli_writes_complete_netcdf(tmp_path, examples_dir):
    out = tmp_path / "sub" / "couette.nc"
    p = run_cli("run", str(examples_dir / "couette.yaml"), "-o", str(out), "--threads", "1", "--quiet")
    assert p.returncode == 0, p.stderr
    ds = xr.open_dataset(out)
    assert ds.attrs["status"] == "completed" and ds.attrs["reason"] == ""
    assert ds.attrs["threads"] == 1 and ds.attrs["steps"] > 0 and ds.attrs["wall_time_s"] > 0
    assert "name: couette" in ds.attrs["scene_yaml"]
    assert ds.attrs["version_numba"]
    for v in ("dt", "dt_limit", "dt_force", "dt_acoustic", "dt_viscous", "kinetic_energy",
              "max_density_deviation", "n_fluid"):
        assert v in ds and ds[v].dims == ("time",) and "units" in ds[v].attrs
    for v in ("x", "z", "u", "w", "rho", "p", "kind"):
        assert ds[v].dims == ("snapshot", "particle")
    np.testing.assert_allclose(ds.snapshot_time, np.arange(11) * 0.0225, atol=1e-12)
    # viscous limit dt3 = h^2/nu governs this scene
    assert set(np.unique(ds.dt_limit.values)) == {2}
    assert list(tmp_path.joinpath("sub").iterdir()) == [out]  # no temporary left


@pytest.mark.slow
def test_cli_diverged_run_exit_code_and_file(tmp_path, examples_dir):
    out = tmp_path / "u.nc"
    p = run_cli("run", str(examples_dir / "unstable.yaml"), "-o", str(out), "--quiet")
    assert p.returncode == 3
    ds = xr.open_dataset(out)
    assert ds.attrs["status"] == "diverged" and "density" in ds.attrs["reason"]
    assert np.isfinite(ds.x).all() and np.isfinite(ds.rho).all()


@pytest.mark.slow
def test_cli_bad_thread_count(tmp_path, examples_dir):
    p = run_cli("run", str(examples_dir / "couette.yaml"), "-o", str(tmp_path / "c.nc"), "--threads", "0")
    assert p.returncode == 2 and "--threads" in p.stderr


def test_write_atomic_keeps_old_file_on_failure(tmp_path):
    path = tmp_path / "r.nc"
    write_atomic(xr.Dataset({"a": ("t", [1.0])}), path)

    class Boom(xr.Dataset):
        __slots__ = ()

        def to_netcdf(self, *a, **k):
            raise KeyboardInterrupt

    try:
        write_atomic(Boom({"a": ("t", [2.0])}), path)
    except KeyboardInterrupt:
        pass
    assert xr.open_dataset(path)["a"].values.tolist() == [1.0]
    assert [p.name for p in tmp_path.iterdir()] == ["r.nc"]


def test_overrides_rename_a_named_case():
    """--set shifting=skillen on a case named '...-lind' must not leave the lind title."""
    from solver.overrides import apply_overrides
    from solver.conveyor import case_from_dict
    data = apply_overrides({"name": "paper-dp1-ch1.8-lind", "dp": 1e-3, "shifting": "lind"},
                           ["shifting=skillen", "steady.max_time=5"])
    case = case_from_dict(data)
    assert case.shifting == "skillen" and case.steady.max_time == 5.0
    assert case.name == "paper-dp1-ch1.8-lind [shifting=skillen, steady.max_time=5]"
    named = apply_overrides({"name": "a", "dp": 1e-3}, ["shifting=skillen", "name=b"])
    assert named["name"] == "b"  # an explicit name wins
    assert apply_overrides({"name": "a", "dp": 1e-3}, [])["name"] == "a"


def test_check_reads_a_conveyor_case_file_and_run_points_to_front(tmp_path, examples_dir):
    """`check` validates a conveyor case file as such (h_n = 18.76 mm for the paper's fluid at
    dp = 1 mm: 18.8 particles deep); `run` refuses it naming `front`; a typo in a case file is
    reported against the case's keys, not the scene's."""
    from solver.cli import main
    case = examples_dir / "conveyor_fast.yaml"
    p = run_cli("check", str(case))
    assert p.returncode == 0 and "conveyor case" in p.stdout and "h_n = 18.76 mm" in p.stdout, p.stderr
    assert "h_n / dp = 18.8" in p.stdout
    out = tmp_path / "x.nc"
    assert main(["run", str(case), "-o", str(out)]) == 2 and not out.exists()
    typo = tmp_path / "typo.yaml"
    typo.write_text(case.read_text().replace("slope_deg", "slope_degs"))
    p = run_cli("check", str(typo))
    assert p.returncode == 2 and "case: unknown key(s) slope_degs" in p.stderr
    assert "read as a conveyor case file" in p.stderr


@pytest.mark.slow
def test_a_killed_scene_run_resumes_from_its_checkpoint_bit_for_bit(tmp_path):
    """python -m solver run, as a campaign runs a slump case, killed with SIGKILL once it has
    written a checkpoint, then run again: the result equals an uninterrupted run's, array by
    array, and the checkpoint is gone once the result is written."""
    from pathlib import Path

    import yaml

    from study.config import load
    from study.registry import flow_of
    from tests.conftest import kill_after_first_checkpoint
    cfg = load(Path(__file__).resolve().parent.parent / "config" / "slump.yaml")
    flow = flow_of(cfg)
    case = next(c for c in flow.cases(cfg) if c.fluid == "newtonian" and c.scheme == "surge")
    scene = flow.case_dict(cfg, case)
    scene.update(dp=5e-3, time={"end": 0.4, "output_interval": 0.05})
    path = tmp_path / "scene.yaml"
    path.write_text(yaml.safe_dump(scene))
    cmd = [sys.executable, "-m", "solver", "run", str(path), "--quiet", "--threads", "1"]
    ref, out, ckpt = tmp_path / "ref.nc", tmp_path / "out.nc", tmp_path / "out.nc.ckpt"
    assert subprocess.run(cmd + ["-o", str(ref), "--no-checkpoint"]).returncode == 0
    kill_after_first_checkpoint(cmd + ["-o", str(out)], ckpt)
    assert ckpt.exists() and not out.exists()  # nothing that looks finished
    assert subprocess.run(cmd + ["-o", str(out)]).returncode == 0
    assert not ckpt.exists()
    a, b = xr.load_dataset(ref), xr.load_dataset(out)
    assert b.attrs["resumed_from_checkpoint"] == 1 and a.attrs["resumed_from_checkpoint"] == 0
    assert a.attrs["steps"] == b.attrs["steps"] and a.sizes == b.sizes
    for v in a.data_vars:
        np.testing.assert_array_equal(a[v].values, b[v].values, err_msg=v)


@pytest.mark.slow
def test_warm_compiles_from_a_list_of_cases_and_scenes(tmp_path, examples_dir):
    """``solver warm`` takes a file holding a list of case and scene dicts (a campaign's
    kernel_cases.yaml): it runs each case as a run would, at its coarse dp, a warm-started one
    from the first run's file, and steps each scene."""
    import yaml
    cases = [{"dp": 0.004, "ch": 1.5, "shifting": "lind", "start": "warm", "warm_from": "absent.nc"},
             yaml.safe_load((examples_dir / "couette.yaml").read_text())]
    listed = tmp_path / "kernel_cases.yaml"
    listed.write_text(yaml.safe_dump(cases))
    p = run_cli("warm", str(listed), "--touch", str(tmp_path / "done"))
    assert p.returncode == 0, p.stderr
    assert "numba kernels compiled and cached" in p.stderr and (tmp_path / "done").exists()
