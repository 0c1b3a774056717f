"""The flows a campaign can run, by the name its ``flow`` key gives (docs/flows.md). The rules
and the CLI ask the flow found here for everything a flow decides (study.flows.base.Flow)."""
from __future__ import annotations

from .flows import conveyor, film, slump, user
from .flows.base import Flow
from .schema import ConfigError

FLOWS: dict[str, Flow] = {f.name: f for f in (conveyor.FLOW, slump.FLOW, film.FLOW, user.FLOW)}
DEFAULT = conveyor.FLOW.name


def flow_of(config: dict) -> Flow:
    """The flow of a campaign config (its ``flow`` key; the conveyor where it has none)."""
    name = config.get("flow", DEFAULT) if isinstance(config, dict) else DEFAULT
    if name not in FLOWS:
        raise ConfigError(f"config key flow: {name!r} is not one of {', '.join(FLOWS)}")
    return FLOWS[name]
