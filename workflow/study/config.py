"""A campaign file, read and checked before any job starts: its flow's schema and defaults
(study.registry), its file names read relative to the campaign file, and its name (default: the
file's stem), under which it writes (study.layout)."""
from __future__ import annotations

import copy
import os
from pathlib import Path

import yaml

from .registry import flow_of
from .schema import ConfigError

DEFAULT_NAME = "campaign"  # a campaign given as a mapping, not a file, without a name key


def _relative_to(cfg: dict, keys: list[tuple], base: Path) -> dict:
    """``cfg`` with each relative file name at ``keys`` joined to ``base``."""
    cfg = copy.deepcopy(cfg)
    for path in keys:
        node = cfg
        for k in path[:-1]:
            node = node[k]
        value = node[path[-1]]
        if isinstance(value, str) and value and not os.path.isabs(value):
            node[path[-1]] = os.path.normpath(str(base / value))
    return cfg


def validate(config: dict, source=None) -> dict:
    """The campaign with its flow's defaults and its name; ConfigError naming the key of
    anything invalid. ``source``: the campaign file, whose folder its file names are relative
    to and whose stem is its default name."""
    if not isinstance(config, dict):
        raise ConfigError("the campaign file must hold a mapping of keys (docs/conveyor.md, docs/flows.md)")
    flow = flow_of(config)
    cfg = copy.deepcopy(config)
    if source is not None:
        cfg = _relative_to(cfg, flow.file_keys(cfg), Path(source).resolve().parent)
        cfg.setdefault("name", Path(source).stem)
    cfg.setdefault("name", DEFAULT_NAME)
    return flow.validate(cfg)


def load(path) -> dict:
    with open(path) as fh:
        return validate(yaml.safe_load(fh) or {}, source=path)
