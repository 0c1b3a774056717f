"""A campaign file against a JSON schema: its scalars read as the schema types them, the
schema's defaults filled in, and every error named by its key."""
from __future__ import annotations

import copy
import re
from pathlib import Path

import yaml

COMMON = Path(__file__).resolve().parent / "common.schema.yaml"


class ConfigError(ValueError):
    """The campaign configuration is invalid; the message names the key."""


def _merged(common: dict, own: dict) -> dict:
    """``own`` over ``common``: mappings merged key by key, anything else ``own``'s."""
    out = copy.deepcopy(common)
    for k, v in own.items():
        out[k] = _merged(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) else copy.deepcopy(v)
    return out


def load_schema(path) -> dict:
    """A flow's schema with the keys every flow takes (common.schema.yaml) merged in."""
    with open(COMMON) as fh:
        common = yaml.safe_load(fh)
    with open(path) as fh:
        return _merged(common, yaml.safe_load(fh))


def key_path(err) -> str:
    """The key path of a schema error, e.g. ``grid.dp.0``."""
    p = ".".join(str(x) for x in err.absolute_path)
    return p or "(top level)"


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
_INTEGER = re.compile(r"[-+]?\d+")
_BOOLEAN = {"true": True, "false": False}


def coerce_scalars(value, schema: dict):
    """``value`` with every string that the schema types as a number, an integer or a boolean
    read as one: YAML 1.1 (PyYAML, Snakemake's loader) reads ``3e-3`` as a string, YAML 1.2 and
    users as 3e-3; ``snakemake --config 'ensemble={realisations: 4}'`` passes every nested value
    as a string."""
    types = schema.get("type")
    types = [types] if isinstance(types, str) else (types or [])
    if isinstance(value, str):
        text = value.strip()
        if "integer" in types and _INTEGER.fullmatch(text):
            return int(text)
        if "number" in types and _NUMBER.fullmatch(text):
            return float(text)
        if "boolean" in types and text.lower() in _BOOLEAN:
            return _BOOLEAN[text.lower()]
    if isinstance(value, dict):
        props = schema.get("properties", {})
        return {k: coerce_scalars(v, props[k]) if k in props else v for k, v in value.items()}
    if isinstance(value, list) and isinstance(schema.get("items"), dict):
        return [coerce_scalars(v, schema["items"]) for v in value]
    return value


def with_defaults(config: dict, schema: dict):
    """(a copy of ``config`` with its scalars read as the schema types them and the schema's
    defaults filled in, the schema's errors sorted by key path)."""
    import jsonschema
    cfg = coerce_scalars(copy.deepcopy(config), schema)
    validator_cls = jsonschema.validators.validator_for(schema)

    def set_defaults(validator, properties, instance, schema):  # fill defaults while validating
        for name, sub in properties.items():
            if isinstance(instance, dict) and "default" in sub and name not in instance:
                instance[name] = copy.deepcopy(sub["default"])
        yield from validator_cls.VALIDATORS["properties"](validator, properties, instance, schema)

    Defaulting = jsonschema.validators.extend(validator_cls, {"properties": set_defaults})
    return cfg, sorted(Defaulting(schema).iter_errors(cfg), key=lambda e: list(e.absolute_path))


def checked(config: dict, schema_path, message=lambda err: err.message) -> dict:
    """``with_defaults`` against the schema file; ConfigError listing every error, each naming
    its key (``message(err)`` words it)."""
    cfg, errors = with_defaults(config, load_schema(schema_path))
    if errors:
        raise ConfigError("; ".join(f"config key {key_path(e)}: {message(e)}" for e in errors))
    return cfg
