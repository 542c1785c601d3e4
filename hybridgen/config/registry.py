"""Registry of config modules by their paper name (``loader.ObjLoader``).

Built-ins register with :func:`register_module`; third-party packages declare modules in the
``hybridgen.modules`` entry-point group (``"mypkg.MyModule" = "mypkg.modules:MyModule"``). A config only
ever names a registered module: nothing in a config is imported as Python.
"""
from __future__ import annotations

import importlib
from typing import Callable, ClassVar, Protocol, TypeVar

from ..errors import ConfigError, closest
from .roles import Role
from .schema import Param


class Module(Protocol):
    """What the registry and the config parser read of a registered class (a
    :class:`hybridgen.modules.base.Module` subclass; a protocol here, so that config/ does not import modules/)."""

    module_name: ClassVar[str]
    role: ClassVar[Role]

    @classmethod
    def param_table(cls) -> dict[str, Param]: ...

ENTRY_POINT_GROUP = "hybridgen.modules"
_BUILTIN_NAMES = {
    "main.Initializer": "hybridgen.modules.main_initializer",
    "loader.ObjLoader": "hybridgen.modules.obj_loader",
    "loader.BlendLoader": "hybridgen.modules.blend_loader",
    "loader.RockEssentialsRockLoader": "hybridgen.modules.rock_essentials_loader",
    "constructor.RockEssentialsGroundConstructor": "hybridgen.modules.rock_essentials_ground",
    "materials.RockEssentialsTextureSampler": "hybridgen.modules.rock_essentials_textures",
    "loader.PrimitiveLoader": "hybridgen.modules.primitive_loader",
    "camera.CameraLoader": "hybridgen.modules.camera_loader",
    "camera.CameraSampler": "hybridgen.modules.camera_sampler",
    "camera.PixelAspect": "hybridgen.modules.pixel_aspect",
    "lighting.LightLoader": "hybridgen.modules.light_loader",
    "lighting.LightSampler": "hybridgen.modules.light_loader",
    "lighting.SurfaceLighting": "hybridgen.modules.surface_lighting",
    "manipulators.EntityManipulator": "hybridgen.modules.manipulators",
    "manipulators.MaterialManipulator": "hybridgen.modules.manipulators",
    "object.ObjectPoseSampler": "hybridgen.modules.object_placement",
    "object.OnSurfaceSampler": "hybridgen.modules.object_placement",
    "object.PhysicsPositioning": "hybridgen.modules.physics_positioning",
    "object.ObjectSwapper": "hybridgen.modules.object_swapper",
    "renderer.SegMapRenderer": "hybridgen.modules.segmap_renderer",
    "renderer.RgbRenderer": "hybridgen.modules.rgb_renderer",
    "writer.Hdf5Writer": "hybridgen.modules.hdf5_writer",
    "writer.CocoAnnotationsWriter": "hybridgen.modules.coco_writer",
    "writer.BopWriter": "hybridgen.modules.bop_writer",
    "object.FloorExtractor": "hybridgen.modules.floor_extractor",
    "manipulators.WorldManipulator": "hybridgen.modules.world_manipulator",
    "writer.CameraStateWriter": "hybridgen.modules.state_writers",
    "writer.LightStateWriter": "hybridgen.modules.state_writers",
    "writer.ObjectStateWriter": "hybridgen.modules.state_writers",
    "loader.BopLoader": "hybridgen.modules.bop_loader",
    "loader.CCMaterialLoader": "hybridgen.modules.material_library",
    "loader.HavenEnvironmentLoader": "hybridgen.modules.haven_loaders",
    "loader.HavenMaterialLoader": "hybridgen.modules.haven_loaders",
    "loader.ShapeNetLoader": "hybridgen.modules.shapenet_loader",
    "loader.Front3DLoader": "hybridgen.modules.front3d_loader",
    "loader.IKEALoader": "hybridgen.modules.object_dataset_loaders",
    "loader.Pix3DLoader": "hybridgen.modules.object_dataset_loaders",
    "loader.ReplicaLoader": "hybridgen.modules.object_dataset_loaders",
    "loader.SceneNetLoader": "hybridgen.modules.scenenet_loader",
    "manipulators.MaterialRandomizer": "hybridgen.modules.material_randomizer",
    "object.Hide": "hybridgen.modules.hide_objects",
    "composite.CameraObjectSampler": "hybridgen.modules.camera_object_sampler",
    "constructor.RandomRoomConstructor": "hybridgen.modules.random_room",
    "camera.Front3DCameraSampler": "hybridgen.modules.room_camera_samplers",
    "camera.ReplicaCameraSampler": "hybridgen.modules.room_camera_samplers",
    "constructor.BasicEmptyInitializer": "hybridgen.modules.empty_initializer",
    "object.CalibrationboardSampler": "hybridgen.modules.calibration_board",
    "loader.TextureLoader": "hybridgen.modules.texture_loader",
    "object.Shading": "hybridgen.modules.shading",
    "loader.AMASSLoader": "hybridgen.modules.amass_loader",
}
"""Built-in module name -> the file registering it: :func:`get_module` imports that file alone (importing all
of them costs ~0.2 s of every run's start); a name missing here, or a plugin's, loads every module first."""

_BUILTIN_PACKAGES = tuple(dict.fromkeys(_BUILTIN_NAMES.values()))
"""Every file registering built-in modules, in a fixed order (what :func:`all_modules` imports): derived from
:data:`_BUILTIN_NAMES`, so a module added there is listed by ``hybridgen modules`` too."""

MODULES: dict[str, type["Module"]] = {}
_loaded = False

M = TypeVar("M", bound=type["Module"])


def register_module(name: str) -> Callable[[M], M]:
    """Class decorator: register a Module subclass under ``name`` (``family.Name``)."""

    def decorate(cls: M) -> M:
        if "." not in name:
            raise ValueError(f"module names look like 'family.Name', got {name!r}")
        existing = MODULES.get(name)
        if existing is not None and existing is not cls:
            raise ValueError(f"module name {name!r} registered twice ({existing.__module__}, {cls.__module__})")
        cls.module_name = name
        MODULES[name] = cls
        return cls

    return decorate


def _load_all() -> None:
    global _loaded
    if _loaded:
        return
    _loaded = True
    for package in _BUILTIN_PACKAGES:
        importlib.import_module(package)
    from importlib import metadata  # here: a run that names its modules never scans the installed packages

    for entry in metadata.entry_points(group=ENTRY_POINT_GROUP):
        if entry.name not in MODULES:
            cls = entry.load()
            register_module(entry.name)(cls)


def module_aliases() -> dict[str, str]:
    """BlenderProc module names hybridgen reads as one of its own modules: alias -> module name."""
    from .blenderproc.names import ALIASES

    return dict(sorted(ALIASES.items()))


def all_modules() -> dict[str, type["Module"]]:
    """Every registered module, built-ins and plugins, by name."""
    _load_all()
    return dict(sorted(MODULES.items()))


def unavailable_reason(name: str) -> str | None:
    """Why the BlenderProc module ``name`` is not available in hybridgen, or None: a registered module of that
    name (a loader added since, a plugin) wins over its ``UNAVAILABLE`` entry."""
    from .blenderproc.names import UNAVAILABLE

    if name not in UNAVAILABLE:
        return None
    return None if name in all_modules() else UNAVAILABLE[name]


def get_module(name: object) -> type["Module"]:
    """The module class registered as ``name``; a ConfigError with the closest names otherwise."""
    if not isinstance(name, str) or not name:
        raise ConfigError(f"module 'name' must be a non-empty string, got {name!r}", key="name")
    from .blenderproc.names import ALIASES, UNAVAILABLE

    target = ALIASES.get(name, name)
    if name not in UNAVAILABLE and target in _BUILTIN_NAMES:
        importlib.import_module(_BUILTIN_NAMES[target])
        if target in MODULES:
            return MODULES[target]
    _load_all()
    reason = unavailable_reason(name)
    if reason is not None:
        raise ConfigError(f"not available in hybridgen: {reason}", key="name")
    name = ALIASES.get(name, name)
    if name not in MODULES:
        raise ConfigError(f"unknown module '{name}'{closest(name, MODULES)}; `hybridgen modules` lists them",
                          key="name")
    return MODULES[name]
