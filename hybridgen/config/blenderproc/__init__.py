"""BlenderProc 1.x configs (v1.0 ``name:`` form and v1.12 ``module:`` form) read as hybridgen's.

:func:`translate_module` turns one BlenderProc module entry into hybridgen module entries: module names
BlenderProc used (``loader.ObjectLoader``, v1.0's ``renderer.NormalRenderer`` ...) become the hybridgen
module that does the same; keys are renamed and values converted (``add_properties``/``cp_*`` custom
properties become attributes, ``cf_set_*`` material functions become principled values, ``collision_shape:
CONVEX_HULL`` becomes ``convex_hull`` ...). What hybridgen does differently (Cycles-only options, Blender
modifiers) is reported through ``note`` as one line naming the key; nothing is dropped silently. Modules
that need Blender or a withdrawn dataset raise one ConfigError that says why and what to do instead.

This package holds no BlenderProc code or configs: it maps names and meanings, described from BlenderProc's
documentation, to hybridgen's own modules.
"""
from __future__ import annotations

from ..registry import unavailable_reason
from .common import Note, custom_properties
from .names import ALIASES, UNAVAILABLE
from .selectors import samplers_as_blenderproc, selector
from .setup_keys import BLENDER_PYTHON_PACKAGES, BLENDER_SETUP_KEYS, FAMILY_READ, GLOBAL_IGNORED
from .translate import KEYS_ONLY_BLENDERPROC, TRANSLATORS, WRITERS, translate_module
from .writers import finish

__all__ = ["ALIASES", "BLENDER_PYTHON_PACKAGES", "BLENDER_SETUP_KEYS", "FAMILY_READ", "GLOBAL_IGNORED",
           "KEYS_ONLY_BLENDERPROC", "Note", "TRANSLATORS", "UNAVAILABLE", "WRITERS", "custom_properties", "finish",
           "samplers_as_blenderproc", "selector", "translate_module", "unavailable_reason"]
