"""Shared by the dataset writer modules whose index files cannot be split into work units."""
from __future__ import annotations

from ..errors import ConfigError
from ..run.context import RunContext


def refuse_work_units(context: RunContext, writer: str) -> None:
    """Dataset folders with shared index files cannot be written by several work units of a sharded run at
    once: a clear error instead of units overwriting each other's files."""
    unit = getattr(context, "unit", None)
    if unit is not None:
        raise ConfigError(f"{writer} cannot be used in a sharded run (work unit {unit}): its index files are shared "
                          "by all units; run without --workers/--shard and with one scene, or use writer.Hdf5Writer")
