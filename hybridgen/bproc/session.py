"""The one BlenderProc session of a process: what Blender's ``bpy.context.scene`` and ``bpy.data`` hold for a
script, kept as plain Python state (no renderer code).

BlenderProc's API works on one global Blender scene; :data:`SESSION` is hybridgen's counterpart. It holds the
live entities (mesh objects, lights, empties) and materials in creation order, Blender's name tables (one per
data kind, for the ``.001`` suffixes), the frame range that ``render()`` renders (``frame_start`` inclusive,
``frame_end`` exclusive, as BlenderProc counts it: ``num_frames() = frame_end - frame_start``), the camera's
intrinsics and keyframed poses, the world background and the renderer settings that
``bproc.renderer`` / ``bproc.camera`` / ``bproc.world`` set. :func:`reset` is ``bproc.init()`` /
``bproc.clean_up()``.

Units and frames: metres, radians, world Z up; camera poses are Blender-axes ``cam2world`` matrices (x right,
y up, looking along -z), as BlenderProc's API takes and returns them.
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from ..errors import InputError
from ..io.blender_names import unique_blender_name
from .blender_camera import BlenderCamera

if TYPE_CHECKING:
    from ..scene.camera import Intrinsics

MAX_NAME_LENGTH = 63
"""Blender's longest data-block name (characters)."""


def hold_value(keys: dict[int, Any], frame: int) -> Any:
    """The keyframed value shown at ``frame``: the key at the largest frame <= ``frame`` (frames before the first
    key show the first key). Blender interpolates between keys (Bezier); at keyed frames - the frames
    BlenderProc's scripts render - both agree."""
    frames = sorted(keys)
    chosen = frames[0]
    for key_frame in frames:
        if key_frame <= frame:
            chosen = key_frame
    return keys[chosen]


class Animated:
    """One animatable property: its current value plus optional keyframes ``{frame: value}``.

    ``set(value, frame)`` sets the current value and, with a frame, keys it there (Blender's
    ``keyframe_insert``). ``at(frame)`` is what a render of that frame sees: the keyed value when there are keys,
    else the current value; ``at(None)`` is the current value."""

    __slots__ = ("value", "keys")

    def __init__(self, value: Any) -> None:
        self.value = value
        self.keys: dict[int, Any] = {}

    def set(self, value: Any, frame: int | None = None) -> None:
        self.value = value
        if frame is not None:
            self.keys[int(frame)] = value

    def at(self, frame: int | None = None) -> Any:
        if frame is None or not self.keys:
            return self.value
        return hold_value(self.keys, int(frame))


@dataclass
class RendererSettings:
    """Cycles' settings as BlenderProc 2.8's ``init()`` leaves them (its ``DefaultConfig``), changed by
    ``bproc.renderer.set_*``: at most 1024 samples per pixel, adaptive noise threshold 0.01, Intel's denoiser,
    bounces max 3 / diffuse 3 / glossy 0 / transmission 0, PNG 8-bit color without alpha."""

    samples: int = 1024
    noise_threshold: float = 0.01
    denoiser: str | None = "INTEL"
    max_bounces: int = 3
    diffuse_bounces: int = 3
    glossy_bounces: int = 0
    transmission_bounces: int = 0
    file_format: str = "PNG"
    color_depth: int = 8
    jpg_quality: int = 95
    transparent: bool = False
    view_transform: str = "Filmic"
    simplify_subdivision_render: int = 3
    """Blender's Simplify limit on Subdivision Surface render levels (0: none), read when a modifier is added."""
    outputs: dict[str, dict[str, Any]] = field(default_factory=dict)
    """Enabled label outputs by kind (``depth``, ``distance``, ``normals``, ``segmentation``, ``diffuse``):
    each kind's options (``output_key``, ``antialiasing``, ``map_by``, ``default_values`` ...)."""


@dataclass
class WorldState:
    """The world background: a linear RGB color times ``strength``, or an HDRI (path, strength, rotation about
    world Z in rad)."""

    color: tuple[float, float, float] = (0.05, 0.05, 0.05)
    strength: float = 1.0
    hdri_path: str | None = None
    hdri_rotation: float = 0.0
    custom_properties: dict[str, Any] = field(default_factory=lambda: {"category_id": 0})


@dataclass
class CameraState:
    """The scene camera: Blender's lens, sensor, resolution and clip range (:mod:`hybridgen.bproc.blender_camera`),
    stereo settings (BlenderProc's defaults: PARALLEL, 0.065 m apart), depth of field and its pose as an
    :class:`Animated` Blender-axes cam2world 4x4 (keyed by
    ``add_camera_pose``)."""

    blender: BlenderCamera = field(default_factory=BlenderCamera)
    pose: Animated = field(default_factory=lambda: Animated(np.eye(4)))
    stereo: bool = False
    interocular_distance: float = 0.065
    convergence_mode: str = "PARALLEL"
    convergence_distance: float = 1e-5
    depth_of_field: dict[str, Any] | None = None
    """``add_depth_of_field``'s settings: ``fstop``, and ``focus`` (an entity whose origin is focused, per frame)
    or ``distance`` (m along the view axis)."""


@dataclass
class Session:
    """See the module documentation."""

    initialized: bool = False
    entities: list[Any] = field(default_factory=list)
    """Live :class:`hybridgen.bproc.types.Entity` objects (meshes, lights, empties) in creation order."""
    materials: list[Any] = field(default_factory=list)
    """Live :class:`hybridgen.bproc.types.Material` objects in creation order."""
    names: dict[str, set[str]] = field(default_factory=dict)
    frame_start: int = 0
    frame_end: int = 0
    camera: CameraState = field(default_factory=CameraState)
    world: WorldState = field(default_factory=WorldState)
    renderer: RendererSettings = field(default_factory=RendererSettings)

    def claim_name(self, kind: str, wanted: str, current: str | None = None) -> str:
        """A name for a data block of ``kind`` (``object``, ``material``, ...), unique as Blender makes it: the
        wanted name if free, else its base (a ``.NNN`` suffix stripped) with the lowest free ``.001``, ``.002``
        ... suffix. ``current``: the block's own name now (released first: renaming to itself keeps it)."""
        taken = self.names.setdefault(kind, set())
        if current is not None:
            taken.discard(current)
        name = unique_blender_name(str(wanted)[:MAX_NAME_LENGTH], taken)
        taken.add(name)
        return name

    def release_name(self, kind: str, name: str) -> None:
        """Free ``name`` of ``kind`` (its block was deleted)."""
        self.names.get(kind, set()).discard(name)

    def require_init(self, call: str) -> None:
        """BlenderProc needs ``bproc.init()`` before scene calls; the same one line here."""
        if not self.initialized:
            raise InputError(f"{call}: call bproc.init() first (as in BlenderProc)")


SESSION = Session()
"""The process's session (BlenderProc's global Blender scene)."""


def current_intrinsics() -> "Intrinsics":
    """The camera's intrinsics (BlenderProc's defaults until a call changes them: 512 x 512, fov 0.691111 rad,
    clip 0.1..1000 m)."""
    return SESSION.camera.blender.intrinsics()


def reset(keep_initialized: bool = True) -> Session:
    """Empty the session in place (``bproc.clean_up``: every object, material, camera pose and the world go;
    renderer settings are reset by ``init()`` only). Returns the session."""
    fresh = Session(initialized=keep_initialized, renderer=SESSION.renderer)
    fresh.camera.blender = SESSION.camera.blender
    for name in ("stereo", "interocular_distance", "convergence_mode", "convergence_distance"):
        setattr(fresh.camera, name, getattr(SESSION.camera, name))  # scene and camera settings Blender keeps
    SESSION.__dict__.update(fresh.__dict__)
    return SESSION
