"""What the ``bproc.loader`` functions share: hybridgen meshes into ``bproc.types`` objects, and hybridgen's own
dataset loaders (the config modules of :mod:`hybridgen.modules`) run for one call.

A hybridgen loader gives one mesh per material of a Blender object (same name, attribute ``material_part``
on every part after the first, one pose); :func:`to_mesh_objects` turns each such run of parts into one
:class:`~hybridgen.bproc.types.MeshObject` with one material slot per part, its pose the parts' pose, its
``category_id`` and attributes as custom properties. Materials shared between parts stay shared.
:func:`run_module` runs a dataset loader module on a scene of its own, drawing from a generator seeded by
Python's ``random`` (which BlenderProc's loaders draw from and ``BLENDER_PROC_RANDOM_SEED`` seeds), and
turns its configuration errors into one line naming the ``bproc.loader`` call and its argument.
"""
from __future__ import annotations

import random
from typing import Any, Mapping, Sequence

import numpy as np

from ..errors import ConfigError, InputError
from ..scene.mesh_object import MeshObject as ScenePart
from .types import Material, MeshObject

HIDDEN_ATTRIBUTES = frozenset({"material_part"})
"""Attributes of hybridgen meshes that are bookkeeping, not a Blender custom property."""


def group_parts(parts: Sequence[ScenePart]) -> list[list[ScenePart]]:
    """Consecutive parts of one Blender object: same name and pose, every later part marked ``material_part``."""
    groups: list[list[ScenePart]] = []
    for part in parts:
        if (groups and groups[-1][0].name == part.name and "material_part" in part.attributes
                and np.array_equal(groups[-1][0].local2world, part.local2world)):
            groups[-1].append(part)
        else:
            groups.append([part])
    return groups


def to_mesh_objects(parts: Sequence[ScenePart], materials: dict[int, Material] | None = None,
                    properties: Mapping[str, Any] | None = None, skipped: Sequence[str] = (),
                    renamed: Mapping[str, str] | None = None) -> list[MeshObject]:
    """One bproc mesh object per Blender object of ``parts`` (see the module doc). ``materials`` maps
    ``id(hybridgen material)`` to its bproc material (shared across calls when given); ``properties`` are
    custom properties every object gets; attributes named in ``skipped`` become none, those in ``renamed``
    the custom property it names (hybridgen's ``source_path`` is BlenderProc's ``model_path``)."""
    own = {} if materials is None else materials
    objects = []
    for group in group_parts(parts):
        slots = []
        for part in group:
            key = id(part.material)
            if key not in own:
                own[key] = Material(part.material.name, part.material)
            slots.append(own[key])
        first = group[0]
        obj = MeshObject(first.name, group, slots, first.local2world)
        if first.category_id is not None:
            obj.set_cp("category_id", int(first.category_id))
        for key, value in first.attributes.items():
            if key not in HIDDEN_ATTRIBUTES and key not in skipped:
                obj.set_cp((renamed or {}).get(key, key), value)
        for key, value in (properties or {}).items():
            obj.set_cp(key, value)
        objects.append(obj)
    return objects


def module_rng() -> np.random.Generator:
    """A generator seeded from Python's ``random`` (so the script's seed decides the loader's draws)."""
    return np.random.default_rng(random.getrandbits(63))


def run_module(module_class: type, config: Mapping[str, Any], call: str,
               arguments: Mapping[str, str] | None = None) -> Any:
    """Run the hybridgen loader module ``module_class`` with ``config`` on a scene of its own; returns its run
    context (``context.scene.objects``: what it loaded). A configuration error becomes one line
    ``<call>: <argument>: <what>``, ``arguments`` mapping module keys to the bproc argument names."""
    from ..config.schema import validate_config
    from ..run.context import RunContext

    names = dict(arguments or {})
    try:
        values = validate_config(module_class.param_table(), dict(config))
        context = RunContext()
        context.rng = module_rng()
        module_class(values, 0).run(context)
    except ConfigError as exc:
        where = f"{names.get(exc.key, exc.key)}: " if exc.key else ""
        raise InputError(f"{call}: {where}{exc.detail}") from None
    return context


def existing_folder(path: Any, call: str, what: str) -> str:
    """``path`` (str) if it is a folder, else one line naming ``call``."""
    import os

    folder = str(path)
    if not os.path.isdir(folder):
        raise InputError(f"{call}: {what} folder not found: '{folder}'")
    return folder
