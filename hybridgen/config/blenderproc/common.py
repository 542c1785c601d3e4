"""What every BlenderProc key translation shares: the notice callback, dropping a key with a notice, custom
properties (``cp_*``/``add_properties``) as hybridgen attributes, and the Blender shading/mode keys."""
from __future__ import annotations

from typing import Any, Callable

from ...errors import ConfigError

Note = Callable[[str, str], None]
"""``note(message, key)``: report one difference (a notice line, or an error in strict mode)."""


def pop_ignored(config: dict[str, Any], key: str, note: Note, why: str) -> Any:
    """Remove ``key`` and report it as ignored (when present)."""
    if key not in config:
        return None
    value = config.pop(key)
    note(f"ignored: {why}", key)
    return value


def as_number(value: Any) -> Any:
    """BlenderProc stores custom properties given as strings ("1"): numeric strings become numbers."""
    if isinstance(value, str):
        try:
            return int(value)
        except ValueError:
            try:
                return float(value)
            except ValueError:
                return value
    return value


def custom_properties(values: dict[str, Any], config: dict[str, Any]) -> None:
    """``cp_<name>: value`` -> attribute ``<name>`` (``cp_category_id`` -> ``category_id``) into ``config``."""
    for key, value in values.items():
        name = key[3:] if key.startswith("cp_") else key
        if name == "category_id":
            config["category_id"] = as_number(value)
        else:
            config.setdefault("attributes", {})[name] = as_number(value)


def take_shading(cfg: dict[str, Any]) -> dict[str, Any] | None:
    """``cf_set_shading`` (and its auto-smooth angle) taken out of ``cfg`` as object.Shading's keys, or None."""
    if "cf_set_shading" not in cfg:
        cfg.pop("cf_shading_auto_smooth_angle_in_deg", None)  # BlenderProc reads it only with a mode
        return None
    mode = cfg.pop("cf_set_shading")
    if not isinstance(mode, str) or mode.upper() not in ("FLAT", "SMOOTH", "AUTO"):
        raise ConfigError(f"must be FLAT, SMOOTH or AUTO, got {mode!r}", key="cf_set_shading")
    return {"mode": mode.upper(), "auto_smooth_angle": cfg.pop("cf_shading_auto_smooth_angle_in_deg", 30.0)}


def shaded(entries: list[tuple[str, dict[str, Any]]], shading: dict[str, Any] | None) -> \
        list[tuple[str, dict[str, Any]]]:
    """Loader entries wrapped in object.Shading when the BlenderProc loader set ``cf_set_shading``."""
    if shading is None:
        return entries
    return [("object.Shading", {**shading, "loader": {"module": name, "config": cfg}}) for name, cfg in entries]


def pop_mode(cfg: dict[str, Any], note: Note) -> None:
    mode = cfg.pop("mode", None)
    if mode not in (None, "once_for_each"):
        note(f"mode {mode!r}: hybridgen draws sampled values once for each selected object", "mode")
