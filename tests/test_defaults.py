"""Each default is written once: the solver's case dataclasses hold the case defaults, the
campaign schema holds the campaign's own. What repeats them must agree:
- the schema's defaults of the keys every solver case also takes (study.flows.conveyor.SOLVER_KEYS);
- the table of case keys in docs/conveyor.md (every key documented, every default as coded);
- config/config.yaml and config/stability.yaml set only what differs from a default;
- config/paper.yaml pins the paper's physical case, which must be the solver's default case,
  and runs examples/conveyor_fast.yaml's scheme.
"""
import dataclasses
import re
from pathlib import Path

import pytest
import yaml

from solver.conveyor import case_from_dict
import study.config as cfgmod
from study.flows import conveyor
from study.flows.conveyor import SCHEMA, SOLVER_KEYS
from study.schema import load_schema

ROOT = Path(__file__).resolve().parent.parent
DEFAULT_CASE = case_from_dict({"dp": 0.001})


def _attr(obj, path):
    for key in path:
        obj = getattr(obj, key)
    return obj


def _plain(v):
    return list(v) if isinstance(v, tuple) else v


def _schema_default(path):
    node = load_schema(SCHEMA)
    for key in path:
        node = node["properties"][key]
    return node["default"]


@pytest.mark.parametrize("cfg_path, case_path", list(SOLVER_KEYS.items()), ids=".".join)
def test_schema_defaults_are_the_solver_defaults(cfg_path, case_path):
    assert _schema_default(cfg_path) == _plain(_attr(DEFAULT_CASE, case_path))


def _case_fields(obj=DEFAULT_CASE, prefix=""):
    """Dotted names of every case key, nested dataclasses flattened."""
    names = []
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if dataclasses.is_dataclass(value):
            names += _case_fields(value, f"{prefix}{f.name}.")
        elif prefix + f.name != "numerics.shifting.method":  # the case's shifting key
            names.append(prefix + f.name)
    return names


def _docs_table() -> dict:
    """{dotted key: default as written} from the case-key table of docs/conveyor.md."""
    rows = {}
    text = (ROOT / "docs" / "conveyor.md").read_text()
    section = text.split("## Case keys", 1)[1].split("\n## ", 1)[0]
    for line in section.splitlines():
        m = re.match(r"^\| (`[^|]+`) \| ([^|]+) \|", line)
        if not m:
            continue
        keys = re.findall(r"`([^`]+)`", m.group(1))
        cell = m.group(2).strip()
        values = [cell] if cell.startswith("[") else [v.strip() for v in cell.split(", ")]
        assert len(values) == len(keys), line
        for k, v in zip(keys, values):
            rows[k] = v
    return rows


def test_docs_table_lists_every_case_key_with_its_default():
    table = _docs_table()
    fields = _case_fields()
    assert sorted(set(fields) - set(table)) == [], "case keys missing from docs/conveyor.md"
    assert sorted(set(table) - set(fields)) == [], "docs/conveyor.md lists keys the case does not have"
    for key in fields:
        written = table[key]
        if written == "required":
            continue
        assert yaml.safe_load(written.strip("`")) == _plain(_attr(DEFAULT_CASE, key.split("."))), key


def _flatten(d, prefix=()):
    for k, v in d.items():
        if isinstance(v, dict):
            yield from _flatten(v, prefix + (k,))
        else:
            yield prefix + (k,), v


@pytest.mark.parametrize("name", ["config.yaml", "stability.yaml"])
def test_campaign_configs_set_only_what_differs_from_a_default(name):
    cfg = yaml.safe_load((ROOT / "config" / name).read_text())
    restated = [".".join(p) for p, v in _flatten(cfg.get("case", {}))
                if _plain(_attr(DEFAULT_CASE, p)) == v]
    for section in ("reference", "metrics", "figures", "resources"):
        for p, v in _flatten(cfg.get(section, {}), (section,)):
            try:
                if _schema_default(p) == v:
                    restated.append(".".join(p))
            except KeyError:
                pass
    assert restated == []


# what the scheme sets: the numerics block and the start (solver/schemes.py)
SCHEME_KEYS = ("numerics", "start", "start_velocity", "scheme")


def test_paper_config_pins_the_default_case():
    cfg = yaml.safe_load((ROOT / "config" / "paper.yaml").read_text())
    physical = {p: v for p, v in _flatten(cfg["case"])
                if p[0] not in ("steady", "checkpoint_interval") and p[0] not in SCHEME_KEYS}
    assert physical, "paper.yaml pins no physical key"
    for p, v in physical.items():
        assert _plain(_attr(DEFAULT_CASE, p)) == v, ".".join(p)


@pytest.mark.parametrize("path", ["config/config.yaml", "config/paper.yaml", "config/accuracy.yaml",
                                  "examples/conveyor_fast.yaml"])
def test_shipped_conveyor_files_take_the_scheme_from_the_default_preset(path):
    """No shipped file restates the shipped scheme: every one runs the surge preset."""
    d = yaml.safe_load((ROOT / path).read_text())
    case = d.get("case", d)
    overrides = [entry.get("case", {}) for entry in d.get("case_overrides") or []]
    for block in [case] + overrides:
        assert not set(block) & set(SCHEME_KEYS), path


def test_a_campaign_with_an_empty_case_runs_the_default_campaigns_scheme():
    """case: {} with config/config.yaml's grid and warm start gives every case file the same
    scheme and numerics as config/config.yaml's; they differ only in the keys config.yaml sets
    outside the scheme (the steady window, and the warm start's source under each campaign's name)."""
    cfg = cfgmod.load(ROOT / "config" / "config.yaml")
    raw = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    bare = cfgmod.validate({"case": {}, "grid": raw["grid"], "warm_start": raw["warm_start"]})
    assert [c.id for c in conveyor.cases(bare)] == [c.id for c in conveyor.cases(cfg)]
    for case in conveyor.cases(cfg):
        ours = case_from_dict(conveyor.case_dict(cfg, case)).to_dict()
        theirs = case_from_dict(conveyor.case_dict(bare, case)).to_dict()
        differ = {k for k in ours.keys() | theirs.keys() if ours.get(k) != theirs.get(k)}
        assert differ <= {"steady", "warm_from"}, (case.id, differ)
        assert ours["scheme"] == "surge" and ours["numerics"] == theirs["numerics"]
