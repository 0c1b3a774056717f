"""``--set KEY=VALUE``: a case or scene file's keys changed from the command line."""
from __future__ import annotations


def apply_overrides(data: dict, items) -> dict:
    """--set a.b=VALUE: VALUE is read as YAML (numbers, lists, null). A named case changed by
    overrides is renamed to say so, 'NAME [a.b=VALUE, ...]', unless ``name`` is set too."""
    import yaml
    items = list(items)
    keys = [item.partition("=")[0] for item in items]
    if items and "name" in data and "name" not in keys:
        data["name"] = f"{data['name']} [{', '.join(items)}]"
    for item in items:
        key, sep, value = item.partition("=")
        if not sep or not key:
            raise ValueError(f"--set {item!r}: expected KEY=VALUE")
        node = data
        parts = key.split(".")
        for p in parts[:-1]:
            node = node.setdefault(p, {})
            if not isinstance(node, dict):
                raise ValueError(f"--set {item!r}: {p} is not a mapping")
        node[parts[-1]] = yaml.safe_load(value)
    return data
