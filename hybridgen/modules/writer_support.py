"""Shared by the dataset writer modules: which keys the renderers of a config will produce, checked before
anything renders (the writers check again, definitively, when they commit)."""
from __future__ import annotations

from typing import Mapping

from ..config.registry import get_module
from ..config.schema import validate_config
from ..errors import ConfigError, HybridgenError
from ..run.context import RunContext
from .label_params import label_request

# Renderer modules whose outputs follow from their config alone: name -> keys beyond the label passes.
_COLOR_KEYS = {"renderer.RgbRenderer": ("colors",), "renderer.SegMapRenderer": ()}


def planned_keys(context: RunContext, writer_index: int) -> set[str] | None:
    """The keys the renderers listed before module ``writer_index`` will write, or None when unknown (no
    config, or a renderer from a plugin)."""
    config = context.config
    if config is None:
        return None
    keys: set[str] = set()
    for entry in config.modules:
        if entry.index >= writer_index or not entry.name.startswith("renderer."):
            continue
        if entry.name not in _COLOR_KEYS:
            return None
        try:
            values = validate_config(get_module(entry.name).param_table(), entry.config, config.global_all)
            written = {layout.key for layout in label_request(values).layouts(1, 1)}
        except HybridgenError:
            return None  # the renderer reports its own config error when it runs
        written.update(_COLOR_KEYS[entry.name])
        if values.get("output_hdr"):
            written.add("colors_hdr")
        names = values.get("output_keys") or {}  # stored under the names the renderer gives them
        keys.update(names.get(key, key) for key in written)
    return keys


def require_planned(context: RunContext, writer_index: int, needed: Mapping[str, str]) -> None:
    """ConfigError before rendering if a needed key (key -> how to make it) will not be rendered."""
    keys = planned_keys(context, writer_index)
    if keys is None:
        return
    missing = [key for key in needed if key not in keys]
    if missing:
        hints = "; ".join(dict.fromkeys(needed[key] for key in missing))
        raise ConfigError(f"needs {missing}, which no renderer before it writes: {hints}")


def refuse_work_units(context: RunContext, writer: str) -> None:
    """Dataset folders with shared index files cannot be written by several work units of a sharded run at
    once: a clear error instead of units overwriting each other's files."""
    unit = getattr(context, "unit", None)
    if unit is not None:
        raise ConfigError(f"{writer} cannot be used in a sharded run (work unit {unit}): its index files are shared "
                          "by all units; run without --workers/--shard and with one scene, or use writer.Hdf5Writer")
