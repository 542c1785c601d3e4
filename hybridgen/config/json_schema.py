"""A JSON Schema (draft 2020-12) of the config format, built from the modules' declared parameters.

``hybridgen modules --schema`` writes it, so editors (the YAML language server, VS Code, PyCharm) can
complete and check configs: module names, each module's keys with their types, units, defaults and
allowed choices (docs/conventions.md sections 5 and 6). What the schema cannot know is checked when the
config is loaded. It accepts, wherever a value goes:

- ``<args:N>`` / ``<env:NAME>`` placeholders (strings; their value is checked at load);
- samplers (``{provider: ...}`` or the paper's ``{name: ..., parameters: {...}}``) for sampleable keys;
- any key given through ``global.all`` (so no module key is required in the schema).

Module names only BlenderProc configs use (hybridgen translates them) are accepted with their config
unchecked; keys only BlenderProc's form of a hybridgen module takes are not in the schema (the loader
still accepts them).
"""
from __future__ import annotations

import inspect
from typing import Any

from .schema import Param

SCHEMA_ID = "https://github.com/hybridgen/hybridgen/config.schema.json"

_PLACEHOLDER = {"type": "string", "pattern": "<(args:[0-9]+|env:[A-Za-z_][A-Za-z0-9_]*)>",
                "description": "a command-line value (<args:N>) or an environment variable (<env:NAME>)"}
_SAMPLER = {
    "type": "object",
    "description": "a sampler, drawn afresh each time the value is read",
    "anyOf": [{"required": ["provider"], "properties": {"provider": {"$ref": "#/$defs/sampler_name"}}},
              {"required": ["name", "parameters"], "properties": {"name": {"$ref": "#/$defs/sampler_name"},
                                                                  "parameters": {"type": "object"}}}],
}
_TYPES: dict[str, dict[str, Any]] = {
    "any": {},
    "bool": {"type": "boolean"},
    "int": {"type": "integer"},
    "float": {"type": "number"},
    "str": {"type": "string"},
    "path": {"type": "string", "minLength": 1},
    "list": {"type": "array"},
    "dict": {"type": "object"},
    "vec3": {"type": "array", "items": {"type": "number"}, "minItems": 3, "maxItems": 3},
    "null": {"type": "null"},
}


def _json_value(value: Any) -> Any:
    """``value`` as plain JSON (tuples to lists; numbers and strings kept; anything else as text)."""
    if isinstance(value, (list, tuple)):
        return [_json_value(v) for v in value]
    if isinstance(value, dict):
        return {str(k): _json_value(v) for k, v in value.items()}
    if value is None or isinstance(value, (bool, int, float, str)):
        return value
    return str(value)


def param_schema(param: Param) -> dict[str, Any]:
    """The schema of one module parameter: its type(s), choices, default, description."""
    kinds = [dict(_TYPES[t]) for t in param.type.split("|")]
    if param.choices:
        choices = [_json_value(c) for c in param.choices]
        for kind in kinds:
            if kind.get("type") == "array":
                kind["items"] = {"enum": choices}
            elif kind.get("type") != "null":
                kind["enum"] = choices
    alternatives = kinds + [_PLACEHOLDER] + ([{"$ref": "#/$defs/sampler"}] if param.sampleable else [])
    out: dict[str, Any] = {"anyOf": alternatives}
    unit = f" [{param.unit}]" if param.unit else ""
    sampled = " (sampleable)" if param.sampleable else ""
    out["description"] = f"{param.type}{unit}{sampled}: {param.doc}".strip()
    if not param.required:
        out["default"] = _json_value(param.default)
    return out


def module_schema(name: str, cls: Any) -> dict[str, Any]:
    """``if name == <name> then config follows the module's parameters`` (unknown keys refused)."""
    config: dict[str, Any] = {"type": "object", "properties": {p.name: param_schema(p) for p in cls.params},
                              "additionalProperties": False}
    doc = inspect.getdoc(cls) or ""
    return {"if": {"properties": {"name": {"const": name}, "module": {"const": name}},
                   "anyOf": [{"required": ["name"]}, {"required": ["module"]}]},
            "then": {"properties": {"config": config}, "description": doc}}


def config_schema() -> dict[str, Any]:
    """The whole config format: ``setup``, ``global``, ``modules`` (and BlenderProc's ``version``)."""
    from ..sampling.registry import ALIASES, SAMPLERS
    from .registry import all_modules

    modules = all_modules()
    translated = _blenderproc_names()
    names = sorted(modules)
    foreign = sorted(n for n in translated if n not in modules)
    module_name = {"anyOf": [{"enum": names, "description": "a hybridgen module (`hybridgen modules`)"}]
                   + ([{"enum": foreign, "description": "a BlenderProc module hybridgen translates"}]
                      if foreign else [])}
    entry = {
        "type": "object",
        "properties": {"name": module_name, "module": module_name,
                       "config": {"type": "object", "description": "the module's parameters"}},
        "additionalProperties": False,
        "anyOf": [{"required": ["name"]}, {"required": ["module"]}],
        "allOf": [module_schema(n, cls) for n, cls in modules.items()],
    }
    return {
        "$schema": "https://json-schema.org/draft/2020-12/schema",
        "$id": SCHEMA_ID,
        "title": "hybridgen config",
        "description": "setup / global / modules, as in the BlenderProc paper (docs/conventions.md section 5)",
        "type": "object",
        "properties": {
            "version": {"type": "integer", "enum": [1, 2, 3], "description": "BlenderProc 1.x format version"},
            "setup": {"type": "object", "properties": {
                "pip": {"type": "array", "items": {"type": "string"},
                        "description": "requirements (PEP 508) the config needs: checked, never installed"}}},
            "global": {"type": "object", "properties": {
                "all": {"type": "object", "description": "values every module that declares the key gets"}}},
            "modules": {"type": "array", "minItems": 1, "items": entry, "description": "run in this order"},
        },
        "required": ["modules"],
        "additionalProperties": False,
        "$defs": {"sampler": _SAMPLER,
                  "sampler_name": {"enum": sorted([*SAMPLERS, *ALIASES])}},
    }


def _blenderproc_names() -> set[str]:
    """Module names of BlenderProc configs that hybridgen translates (their keys differ from ours)."""
    try:
        from . import blenderproc
    except ImportError:  # pragma: no cover - the translation layer is optional
        return set()
    names: set[str] = set()
    for table in ("ALIASES", "TRANSLATORS", "WRITERS"):
        names.update(getattr(blenderproc, table, {}))
    return names
