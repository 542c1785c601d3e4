"""Key translation of ``composite.CameraObjectSampler``: its nested module entries are BlenderProc module
entries too (``module:``/``name:`` with BlenderProc's keys), translated like top-level ones."""
from __future__ import annotations

from typing import Any, Callable

from ...errors import ConfigError
from .common import Note

Translate = Callable[[str, dict[str, Any], Note, dict[str, Any]], list[tuple[str, dict[str, Any]]]]
""":func:`~hybridgen.config.blenderproc.translate.translate_module`'s signature."""

NESTED = {"object_pose_sampler": "object.ObjectPoseSampler", "camera_pose_sampler": "camera.CameraSampler"}
"""The composite's nested entries and the module BlenderProc's documentation names for each."""


def camera_object_sampler(config: dict[str, Any], note: Note, state: dict[str, Any],
                          translate: Translate) -> list[tuple[str, dict[str, Any]]]:
    """Each nested entry translated to exactly one hybridgen module entry ``{module, config}``."""
    cfg = dict(config)
    for key in NESTED:
        entry = cfg.get(key)
        if not isinstance(entry, dict):
            continue  # the module's own check reports it
        name = entry.get("module", entry.get("name"))
        if not isinstance(name, str):
            continue
        inner = entry.get("config", {})
        if not isinstance(inner, dict):
            raise ConfigError("must be a mapping", key=f"{key}.config")

        def nested_note(message: str, inner_key: str, where: str = key) -> None:
            note(message, f"{where}.config.{inner_key}")

        try:
            translated = translate(name, inner, nested_note, state)
        except ConfigError as exc:
            raise ConfigError(exc.detail, key=f"{key}.{exc.key}" if exc.key else key) from None
        if len(translated) != 1:
            raise ConfigError(f"{name} here becomes {len(translated)} hybridgen modules "
                              f"({', '.join(n for n, _ in translated)}); a nested entry must be one module",
                              key=f"{key}.module")
        cfg[key] = {"module": translated[0][0], "config": translated[0][1]}
    return [("composite.CameraObjectSampler", cfg)]
