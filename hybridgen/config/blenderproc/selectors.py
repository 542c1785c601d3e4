"""BlenderProc ``getter.Entity`` selectors and sampler specs in hybridgen's terms."""
from __future__ import annotations

from typing import Any

from ...errors import ConfigError
from .common import Note, as_number


_SELECTOR_KEYS = ("provider", "conditions", "random_samples", "index", "check_empty")


def selector(value: Any, note: Note, key: str = "selector") -> Any:
    """A BlenderProc ``getter.Entity`` selector in hybridgen's terms: ``type: MESH`` always holds."""
    if isinstance(value, dict):
        out = dict(value)
        if not any(k in out for k in _SELECTOR_KEYS):
            out = {"conditions": out}
        out.setdefault("check_empty", False)  # BlenderProc: an empty selection does nothing
        for extra in [k for k in out if k not in _SELECTOR_KEYS]:
            # BlenderProc's getter reads its own keys and skips others (the random_room_constructor example
            # puts SurfaceLighting's emission_strength into the selector: BlenderProc uses the default)
            out.pop(extra)
            note("ignored: BlenderProc's getter.Entity does not read this key (a module key inside the selector "
                 "has no effect there)", f"{key}.{extra}")
        if "conditions" in out:
            out["conditions"] = _conditions(out["conditions"], note, f"{key}.conditions")
        provider = out.get("provider")
        if provider not in (None, "getter.Entity"):
            raise ConfigError(f"provider {provider!r} selects something other than objects; hybridgen "
                              "modules select objects with getter.Entity", key=f"{key}.provider")
        return out
    return value


def _conditions(conditions: Any, note: Note, key: str) -> Any:
    if isinstance(conditions, list):
        return [_conditions(c, note, f"{key}[{i}]") for i, c in enumerate(conditions)]
    if not isinstance(conditions, dict):
        return conditions
    out = {}
    for name, wanted in conditions.items():
        if name == "type":
            if str(wanted).upper() != "MESH":
                raise ConfigError(f"hybridgen scenes select mesh objects only, got type {wanted!r}",
                                  key=f"{key}.type")
            continue  # every hybridgen object is a mesh
        out[name] = as_number(wanted) if name.startswith("cp_") or name == "category_id" else wanted
    return out


_UNIFORM = ("sampler.Uniform3d", "Uniform3dSampler", "sampler.Value", "ValueSampler", "sampler.Color",
            "ColorSampler")


def samplers_as_blenderproc(value: Any, note: Note, key: str) -> Any:
    """Sampler specs drawn as BlenderProc draws them: ``min`` above ``max`` (numpy draws between the two, so
    BlenderProc's examples use it) becomes the same range ordered; PartSphere's ``part_sphere_vector`` is
    hybridgen's ``part_sphere_dir_vector``; a ``parameters`` mapping next to ``provider`` holds provider keys."""
    if isinstance(value, list):
        return [samplers_as_blenderproc(v, note, f"{key}[{i}]") for i, v in enumerate(value)]
    if not isinstance(value, dict):
        return value
    out = {k: samplers_as_blenderproc(v, note, f"{key}.{k}") for k, v in value.items()}
    provider = out.get("provider", out.get("name"))
    if "provider" in out and isinstance(out.get("parameters"), dict):
        # BlenderProc hands a provider its whole mapping and reads no 'parameters' key (the v1.0 form's):
        # empty, it changes nothing; given, its keys are the provider's, as v1.0 meant
        extra = out.pop("parameters")
        clash = sorted(k for k in extra if k in out)
        if clash:
            raise ConfigError(f"{clash[0]!r} is given both here and in 'parameters'", key=f"{key}.parameters")
        out.update(extra)
    if provider == "getter.Entity":  # a selector anywhere (getter.POI's, samplers' ...): type MESH always holds
        out["conditions"] = _conditions(out.get("conditions"), note, f"{key}.conditions")
        if out["conditions"] is None:
            del out["conditions"]
    params = out.get("parameters", out)
    if provider in _UNIFORM and isinstance(params, dict) and "min" in params and "max" in params:
        low, high = params["min"], params["max"]
        if isinstance(low, list) and isinstance(high, list) and len(low) == len(high) and \
                all(isinstance(v, (int, float)) for v in low + high) and any(a > b for a, b in zip(low, high)):
            params["min"], params["max"] = [min(a, b) for a, b in zip(low, high)], \
                [max(a, b) for a, b in zip(low, high)]
        elif isinstance(low, (int, float)) and isinstance(high, (int, float)) and low > high:
            params["min"], params["max"] = high, low
    if provider in ("sampler.UpperRegionSampler", "UpperRegionSampler") and isinstance(params, dict) and \
            "use_ray_trace_check" in params:
        if params.pop("use_ray_trace_check"):
            note("the ray check that nothing blocks the sampled point from the surface is not done; the "
                 "placing module's collision check still applies", f"{key}.use_ray_trace_check")
    if provider in ("sampler.PartSphere", "PartSphereSampler") and isinstance(params, dict) and \
            "part_sphere_vector" in params:
        params["part_sphere_dir_vector"] = params.pop("part_sphere_vector")
    return out
