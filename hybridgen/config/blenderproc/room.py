"""Key translation of ``constructor.RandomRoomConstructor``: its ``used_loader_config`` entries are BlenderProc
module entries (``module:`` + ``config:``, with ``amount_of_repetitions``), translated like top-level ones."""
from __future__ import annotations

from typing import Any

from ...errors import ConfigError
from .common import Note
from .composite import Translate


def random_room(config: dict[str, Any], note: Note, state: dict[str, Any],
                translate: Translate) -> list[tuple[str, dict[str, Any]]]:
    """Each loader entry translated to exactly one hybridgen module entry, its repetitions kept."""
    cfg = dict(config)
    entries = cfg.get("used_loader_config")
    if not isinstance(entries, list):
        return [("constructor.RandomRoomConstructor", cfg)]  # the module's own check reports it
    translated_entries = []
    for i, entry in enumerate(entries):
        name = entry.get("module", entry.get("name")) if isinstance(entry, dict) else None
        if not isinstance(name, str) or not isinstance(entry.get("config", {}), dict):
            translated_entries.append(entry)
            continue
        where = f"used_loader_config.{i}"

        def nested_note(message: str, inner_key: str, where: str = where) -> None:
            note(message, f"{where}.config.{inner_key}")

        try:
            translated = translate(name, entry.get("config", {}), nested_note, state)
        except ConfigError as exc:
            raise ConfigError(exc.detail, key=f"{where}.{exc.key}" if exc.key else where) from None
        if len(translated) != 1:
            raise ConfigError(f"{name} here becomes {len(translated)} hybridgen modules; a loader entry must be "
                              "one module", key=f"{where}.module")
        out = {"module": translated[0][0], "config": translated[0][1]}
        if "amount_of_repetitions" in entry:
            out["amount_of_repetitions"] = entry["amount_of_repetitions"]
        translated_entries.append(out)
    cfg["used_loader_config"] = translated_entries
    return [("constructor.RandomRoomConstructor", cfg)]
