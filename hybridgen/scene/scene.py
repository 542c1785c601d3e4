"""The renderer-agnostic scene: objects, lights, world background and one camera."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterator

from ..errors import InputError
from .camera import Camera
from .empty import Empty
from .image_texture import ImageTexture
from .light import Light
from .mesh_object import MeshObject
from .object_keyframes import ObjectKeyframes


@dataclass
class World:
    """Background lighting: a constant color (linear RGB) times ``strength``, or an HDRI file."""

    color: tuple[float, float, float] = (0.05, 0.05, 0.05)
    strength: float = 1.0
    hdri_path: str | None = None
    hdri_rotation: float = 0.0  # rad about world +Z


@dataclass
class Scene:
    """Everything a renderer needs. Knows nothing about OpenGL or Mitsuba.

    Objects get instance ids 1..N in the order they are added; ids are never reused within a scene. The
    scene owns the ids: change ``objects`` through :meth:`add`, :meth:`remove` and :meth:`replace` (a
    replacement takes the replaced object's slot and id, a removed object's id stays unused).
    """

    objects: list[MeshObject] = field(default_factory=list)
    lights: list[Light] = field(default_factory=list)
    camera: Camera = field(default_factory=Camera)
    world: World = field(default_factory=World)
    _next_id: int = 1
    object_keyframes: ObjectKeyframes | None = None
    """Object poses per keypoint when they change between keypoints (composite.CameraObjectSampler); None:
    every keypoint shows the objects' ``local2world``."""
    empties: list[Empty] = field(default_factory=list)
    """Named poses without geometry (never drawn, no instance id; :mod:`hybridgen.scene.empty`)."""
    textures: list[ImageTexture] = field(default_factory=list)
    """Images loaded for later use (``loader.TextureLoader``), selected with ``getter.Texture``; never drawn."""

    def add(self, obj: MeshObject) -> MeshObject:
        """Add ``obj``, assigning its stable instance id; returns it."""
        obj.instance_id = self._next_id
        self._next_id += 1
        self.objects.append(obj)
        return obj

    def remove(self, *objects: MeshObject) -> None:
        """Take ``objects`` out of the scene (by identity); the others keep their ids and order, and the
        removed ids are not given to later objects. An object that is not in the scene is an error."""
        gone = {id(obj) for obj in objects}
        present = {id(obj) for obj in self.objects}
        for obj in objects:
            if id(obj) not in present:
                raise InputError(f"object '{obj.name}' is not in the scene")
        self.objects[:] = [obj for obj in self.objects if id(obj) not in gone]

    def replace(self, old: MeshObject, new: MeshObject) -> MeshObject:
        """Put ``new`` in ``old``'s place: same position in ``objects`` and same instance id; returns ``new``."""
        position = self._position(old)
        new.instance_id = old.instance_id
        self.objects[position] = new
        return new

    def _position(self, obj: MeshObject) -> int:
        for position, candidate in enumerate(self.objects):
            if candidate is obj:
                return position
        raise InputError(f"object '{obj.name}' is not in the scene")

    def add_light(self, light: Light) -> Light:
        """Add a light; returns it."""
        self.lights.append(light)
        return light

    def __iter__(self) -> Iterator[MeshObject]:
        return iter(self.objects)

    def by_name(self, name: str) -> MeshObject:
        """The object called ``name``."""
        for obj in self.objects:
            if obj.name == name:
                return obj
        raise KeyError(name)

    def require_category_ids(self, default: int | None = None) -> None:
        """Give objects without ``category_id`` the default, or fail naming them (docs/conventions.md section 3)."""
        missing = [o for o in self.objects if o.category_id is None]
        if not missing:
            return
        if default is None:
            names = ", ".join(repr(o.name) for o in missing[:10]) + (" ..." if len(missing) > 10 else "")
            raise InputError(f"{len(missing)} object(s) have no category_id: {names}; set category_id on "
                             "their loader or a default (main.Initializer default_category_id)")
        for obj in missing:
            obj.category_id = int(default)

    @property
    def triangle_count(self) -> int:
        """Total number of triangles over all objects."""
        return sum(len(o.faces) for o in self.objects)
