"""BlenderProc 2.8's internal module paths (``blenderproc.python.<package>.<Module>``) as hybridgen modules.

BlenderProc's public API (``bproc.<area>``) re-exports functions and classes defined in modules under
``blenderproc.python``; scripts sometimes import those directly (``from blenderproc.python.utility.Utility import
Utility``). :data:`INTERNAL_MODULES` maps each such module path to the ``hybridgen.bproc`` areas that hold its
names; :func:`internal_module` builds the module a script imports:

- a name one of those areas has is that area's object (``blenderproc.python.camera.CameraUtility.add_camera_pose``
  is ``bproc.camera.add_camera_pose``);
- any other name (BlenderProc's helper classes ``Utility``, ``SetupUtility``, ...) imports as a stand-in that raises
  one line naming it when it is called or one of its attributes is read - except attributes the areas have
  (``Utility.resolve_path`` is ``bproc.utility.resolve_path``, as BlenderProc's static method).

The packages on the way (``blenderproc.python``, ``blenderproc.python.utility``, ...) are empty packages. A module
path not in the table is not importable (one line, :mod:`hybridgen.bproc.script`).
"""
from __future__ import annotations

import importlib
from types import ModuleType
from typing import Any, NoReturn

from .types.unsupported import fail

ROOT = "blenderproc.python"
_AREAS_OF_PACKAGE = {"camera": ("camera",), "constructor": ("constructor",), "filter": ("filter",),
                     "lighting": ("lighting",), "loader": ("loader", "world"), "material": ("material",),
                     "object": ("object",), "postprocessing": ("postprocessing",), "renderer": ("renderer",),
                     "sampler": ("sampler",), "writer": ("writer",)}
_MODULES_OF_PACKAGE = {
    "camera": ("CameraUtility", "CameraValidation", "CameraProjection", "LensDistortionUtility"),
    "constructor": ("RandomRoomConstructor",),
    "filter": ("Filter",),
    "lighting": ("SuncgLighting", "SurfaceLighting", "IntersectingSpotLight"),
    "loader": ("AMASSLoader", "BlendLoader", "BopLoader", "CCMaterialLoader", "Front3DLoader",
               "HavenMaterialLoader", "HavenEnvironmentLoader", "IKEALoader", "Matterport3DLoader", "ObjectLoader",
               "Pix3DLoader", "ReplicaLoader", "SceneNetLoader", "ShapeNetLoader", "SuncgLoader", "TextureLoader",
               "URDFLoader"),
    "material": ("MaterialLoaderUtility", "Dust"),
    "object": ("FaceSlicer", "ObjectPoseSampler", "ObjectMerging", "ObjectReplacer", "OnSurfaceSampler",
               "PhysicsSimulation"),
    "postprocessing": ("PostProcessingUtility", "StereoGlobalMatching"),
    "renderer": ("RendererUtility", "SegMapRendererUtility", "FlowRendererUtility", "NOCSRendererUtility"),
    "sampler": ("Disk", "PartSphere", "Shell", "Sphere", "UniformSO3", "UpperRegionSampler", "RandomWalk",
                "Front3DPointInRoomSampler", "ReplicaPointInRoomSampler", "SuncgPointInRoomSampler"),
    "writer": ("GifWriterUtility", "BopWriterUtility", "CocoWriterUtility", "WriterUtility"),
}
INTERNAL_MODULES: dict[str, tuple[str, ...]] = {
    **{f"{ROOT}.{package}.{module}": _AREAS_OF_PACKAGE[package]
       for package, modules in _MODULES_OF_PACKAGE.items() for module in modules},
    # bproc.camera re-exports apply_lens_distortion's module through postprocessing
    f"{ROOT}.camera.LensDistortionUtility": ("camera", "postprocessing"),
    f"{ROOT}.types.StructUtility": ("types",),
    f"{ROOT}.types.EntityUtility": ("types", "object"),
    f"{ROOT}.types.MeshObjectUtility": ("types", "object"),
    f"{ROOT}.types.LightUtility": ("types",),
    f"{ROOT}.types.MaterialUtility": ("types",),
    f"{ROOT}.types.ArmatureUtility": ("types",),
    f"{ROOT}.types.URDFUtility": ("types",),
    f"{ROOT}.types.BoneUtility": ("types",),
    f"{ROOT}.types.LinkUtility": ("types",),
    f"{ROOT}.types.InertialUtility": ("types",),
    f"{ROOT}.utility.Utility": ("utility",),
    f"{ROOT}.utility.LabelIdMapping": ("utility",),
    f"{ROOT}.utility.PatternUtility": ("utility",),
    f"{ROOT}.utility.MathUtility": ("math",),
    f"{ROOT}.utility.SetupUtility": (),
    f"{ROOT}.utility.Initializer": ("",),
}
"""BlenderProc 2.8 module path -> the ``hybridgen.bproc`` areas holding its names (``""``: ``hybridgen.bproc``
itself, for ``init``/``clean_up``)."""
PACKAGES = frozenset(path.rsplit(".", i)[0] for path in INTERNAL_MODULES for i in (1, 2))
"""``blenderproc.python`` and its sub-packages (importable, empty)."""


class MissingName:
    """A name of a BlenderProc module hybridgen lacks: importing it works, calling it or reading an attribute
    raises one line naming it (an attribute the module's areas have is that area's object)."""

    def __init__(self, qualified: str, areas: tuple[ModuleType, ...]) -> None:
        self._qualified = qualified
        self._areas = areas

    def __call__(self, *_args: Any, **_kwargs: Any) -> NoReturn:
        fail(self._qualified)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        found = _lookup(self._areas, name)
        if found is not None:
            return found
        fail(f"{self._qualified}.{name}")

    def __repr__(self) -> str:
        return f"<{self._qualified}: not supported by hybridgen yet>"


def _lookup(areas: tuple[ModuleType, ...], name: str) -> Any:
    """``name`` from the first area that has it, else None (an area's unsupported stand-ins count as having it)."""
    for area in areas:
        try:
            return getattr(area, name)
        except AttributeError:
            continue
    return None


def _areas(names: tuple[str, ...], package: str) -> tuple[ModuleType, ...]:
    return tuple(importlib.import_module(package + (f".{name}" if name else "")) for name in names)


def internal_module(fullname: str, package: str) -> ModuleType:
    """The module a script gets for BlenderProc's ``fullname`` (a key of :data:`INTERNAL_MODULES` or one of
    :data:`PACKAGES`); ``package`` is ``hybridgen.bproc``. See the module documentation."""
    module = ModuleType(fullname, f"BlenderProc's {fullname} over hybridgen.bproc")
    if fullname in PACKAGES:
        module.__path__ = []  # a package: its sub-modules are found through the meta-path finder
        return module
    areas = _areas(INTERNAL_MODULES[fullname], package)

    def __getattr__(name: str) -> Any:  # noqa: N807 - a module's __getattr__
        if name.startswith("__"):
            raise AttributeError(f"module {fullname!r} has no attribute {name!r}")
        found = _lookup(areas, name)
        return MissingName(f"{fullname}.{name}", areas) if found is None else found

    module.__getattr__ = __getattr__  # type: ignore[method-assign]
    return module
