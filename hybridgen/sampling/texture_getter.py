"""``getter.Texture``: textures of the scene (``loader.TextureLoader``'s) selected by conditions, as BlenderProc
selects Blender textures.

``conditions``: a mapping (all must hold) or a list of mappings (any); keys are ``name``, ``type``,
``use_nodes`` (attributes of the texture; a string value is a regular expression the whole value must match)
or ``cp_<name>`` (a custom property; strings again regular expressions); a key the texture lacks fails the
condition. ``index`` picks one texture, ``random_samples`` draws that many (without replacement, from the run's
generator), ``check_empty`` makes an empty result an error. The value is the list of the textures' image paths;
with ``index`` the one path itself (BlenderProc: a one-element list), so it fits an image slot
(``base_color_texture``, ``displace.texture`` ...).
"""
from __future__ import annotations

import re
from typing import Any

from ..errors import InputError
from .sampler_table import DrawContext, register_sampler

_ATTRIBUTES = ("name", "type", "use_nodes")


def _check(p: dict[str, Any]) -> None:
    if p.get("index") is not None and p.get("random_samples"):
        raise ValueError("define only one of index and random_samples")
    conditions = p.get("conditions", {})
    for group in conditions if isinstance(conditions, list) else [conditions]:
        if not isinstance(group, dict):
            raise ValueError("conditions must be a mapping or a list of mappings")
        for key in group:
            if str(key).startswith("cf_"):
                raise ValueError(f"{key}: custom functions on textures do not exist (as in BlenderProc)")


def _holds(texture: Any, key: str, wanted: Any) -> bool:
    if key.startswith("cp_"):
        if key[3:] not in texture.properties:
            return False
        actual = texture.properties[key[3:]]
    elif key in _ATTRIBUTES:
        actual = getattr(texture, key)
    else:
        return False
    if isinstance(actual, str) and isinstance(wanted, str):
        return re.fullmatch(wanted, actual) is not None
    return actual == wanted


def _matches(texture: Any, conditions: Any) -> bool:
    if isinstance(conditions, list):
        return any(_matches(texture, group) for group in conditions)
    return all(_holds(texture, str(k), v) for k, v in (conditions or {}).items())


@register_sampler("getter.Texture", "Texture", validate=_check)
def texture(ctx: DrawContext, conditions: Any = None, index: int | None = None, random_samples: int = 0,
            check_empty: bool = False) -> Any:
    """The image paths of the scene's textures matching ``conditions`` (see the module doc)."""
    pool = [t for t in getattr(ctx.scene, "textures", []) if _matches(t, conditions)]
    if random_samples:
        picks = sorted(ctx.rng.choice(len(pool), size=min(int(random_samples), len(pool)), replace=False))
        pool = [pool[i] for i in picks]
    if check_empty and not pool:
        raise InputError(f"getter.Texture: no texture matches {conditions!r} (load some with loader.TextureLoader)")
    if index is not None:
        if not -len(pool) <= int(index) < len(pool):
            raise InputError(f"getter.Texture: index {index} of {len(pool)} matching texture(s) ({conditions!r})")
        return pool[int(index)].path
    return [t.path for t in pool]
