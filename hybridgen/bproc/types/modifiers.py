"""Blender modifiers on a ``bproc.types.MeshObject`` (BlenderProc's ``add_modifier``, ``add_displace_modifier``):
Subdivision Surface (``SUBSURF``), ``DISPLACE`` and ``SOLIDIFY``, applied to the object's mesh when added, as
Blender's "Apply" would - so renders (labels and color), ray casts, bound boxes and physics all see the result.

Each is evaluated as Blender evaluates it for a render (:mod:`hybridgen.scene.catmull_clark`,
:mod:`hybridgen.scene.displace_modifier`, :mod:`hybridgen.scene.solidify`) on the object's welded polygon mesh
(:mod:`hybridgen.scene.polygon_mesh`): a mesh read from an OBJ with quads or n-gons gets its polygons back from
the triangles (:mod:`hybridgen.scene.polygon_recovery`); one from an all-triangle OBJ, PLY, STL or glTF keeps its
triangles. Consecutive modifiers share the polygon mesh, as a modifier stack does. SUBSURF subdivides
``render_levels`` times (what Blender renders), at most ``bproc.renderer.set_simplify_subdivision_render``'s
limit (BlenderProc 2.8's init sets Blender's "Simplify" to 3); ``subdivision_type`` SIMPLE subdivides without
smoothing. DISPLACE reads a procedural texture (``bproc.material.create_procedural_texture``) or an image texture
(``bproc.loader.load_texture``; :class:`hybridgen.scene.displacement_texture.ImageHeight`, Blender's image
sampling), the same textures v1 configs' ``displace`` reads (:mod:`hybridgen.scene.displacement`).

Differences: the modifier is applied at once, so a later change of the base mesh (a persisted transformation,
``set_shading_mode``) does not re-run it, and setting a modifier's attributes later changes nothing; UVs are
subdivided linearly (Blender's default also smooths them inside UV islands). A modifier type other than these,
or a setting hybridgen does not reproduce, raises one line naming it.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, Callable

import numpy as np

from ...errors import InputError
from ...scene.mesh_object import MeshObject as ScenePart
from .unsupported import fail

if TYPE_CHECKING:
    from ...scene.polygon_mesh import PolygonMesh

SETTINGS: dict[str, dict[str, Any]] = {
    "SUBSURF": {"levels": 1, "render_levels": 2, "subdivision_type": "CATMULL_CLARK", "use_limit_surface": True,
                "quality": 3, "boundary_smooth": "ALL", "uv_smooth": "PRESERVE_BOUNDARIES", "use_creases": True,
                "use_custom_normals": False},
    "DISPLACE": {"texture": None, "mid_level": 0.5, "strength": 1.0, "direction": "NORMAL", "texture_coords": "LOCAL",
                 "space": "LOCAL", "vertex_group": ""},
    "SOLIDIFY": {"thickness": 0.01, "offset": -1.0, "use_rim": True, "use_even_offset": False,
                 "use_flip_normals": False, "solidify_mode": "EXTRUDE", "use_rim_only": False,
                 "use_quality_normals": False, "thickness_clamp": 0.0, "material_offset": 0, "material_offset_rim": 0,
                 "vertex_group": "", "bevel_convex": 0.0, "edge_crease_inner": 0.0, "edge_crease_outer": 0.0,
                 "edge_crease_rim": 0.0},
}
"""Blender 4.2's settings of each supported modifier and their defaults (read with bpy)."""
APPLIED = {"SUBSURF": {"render_levels", "subdivision_type", "use_limit_surface", "levels", "quality", "uv_smooth",
                       "use_creases"},
           "DISPLACE": {"texture", "mid_level", "strength", "direction", "texture_coords"},
           "SOLIDIFY": {"thickness", "offset", "use_rim", "use_even_offset", "use_flip_normals"}}
"""Settings hybridgen reproduces (or that change nothing here); any other must keep its default."""
class MeshModifiers:
    """Mixin of :class:`~hybridgen.bproc.types.MeshObject`: needs ``parts``, ``part_slots``, ``get_name``,
    ``get_cp`` / ``has_cp`` and ``get_local2world_mat``."""

    parts: list[ScenePart]
    part_slots: list[int]
    get_name: Callable[[], str]
    get_cp: Callable[..., Any]
    has_cp: Callable[[str], bool]
    get_local2world_mat: Callable[[], np.ndarray]

    def _stack_mesh(self) -> "PolygonMesh":
        """The welded polygon mesh of the current parts (the one the last modifier left, while the parts are its)."""
        from ...scene.polygon_mesh import from_parts, source_has_polygons

        cached = self.__dict__.get("_modifier_mesh")
        if cached is not None and len(cached[0]) == len(self.parts) and all(
                a is p.vertices and b is p.faces for (a, b), p in zip(cached[0], self.parts)):
            return cached[1]
        if not self.parts:
            fail(f"bproc.types.MeshObject.add_modifier on '{self.get_name()}'", "its mesh has no faces")
        path = self.get_cp("model_path") if self.has_cp("model_path") else None
        return from_parts(self.parts, polygons=source_has_polygons(path))

    def _set_stack_mesh(self, mesh: "PolygonMesh") -> None:
        parts = mesh.to_parts(self.parts)
        kept = [index for index, part in enumerate(parts) if part is not None]
        self.parts = [parts[i] for i in kept]  # type: ignore[misc]
        self.part_slots = [self.part_slots[i] for i in kept]
        self.__dict__["_modifier_mesh"] = ([(p.vertices, p.faces) for p in self.parts], mesh)

    def base_vertex_count(self) -> int:
        """Blender's vertex count of the mesh before any modifier (positions welded)."""
        if "_base_vertex_count" not in self.__dict__:
            vertices = np.concatenate([p.vertices for p in self.parts]) if self.parts else np.zeros((0, 3))
            self.__dict__["_base_vertex_count"] = len(np.unique(vertices, axis=0))
        return int(self.__dict__["_base_vertex_count"])

    def add_modifier(self, name: str, **kwargs: Any) -> None:
        """Add (and apply) a ``SUBSURF``, ``DISPLACE`` or ``SOLIDIFY`` modifier with Blender's attribute names
        (module doc)."""
        call = f"bproc.types.MeshObject.add_modifier('{name}')"
        if name not in SETTINGS:
            fail(call, "SUBSURF, DISPLACE and SOLIDIFY are")
        settings = dict(SETTINGS[name])
        for key, value in kwargs.items():
            if key not in settings:
                raise InputError(f"{call}: a {name} modifier has no attribute '{key}'")
            if key not in APPLIED[name] and value != settings[key]:
                fail(f"{call} with {key}={value!r}")
            settings[key] = value
        self.base_vertex_count()
        mesh = self._stack_mesh()
        self._set_stack_mesh({"SUBSURF": _subsurf, "DISPLACE": _displace, "SOLIDIFY": _solidify}[name](
            self, mesh, settings, call))

    def add_displace_modifier(self, texture: Any, mid_level: float = 0.5, strength: float = 0.1,
                              min_vertices_for_subdiv: int = 10000, subdiv_level: int = 2) -> None:
        """BlenderProc's: a Subdivision Surface of ``subdiv_level`` render levels first when the mesh has at most
        ``min_vertices_for_subdiv`` vertices, then a Displace modifier with the texture."""
        if not self.base_vertex_count() > min_vertices_for_subdiv:
            self.add_modifier("SUBSURF", render_levels=subdiv_level)
        self.add_modifier("DISPLACE", texture=texture, mid_level=mid_level, strength=strength)


def _subsurf(obj: MeshModifiers, mesh: "PolygonMesh", s: dict[str, Any], call: str) -> "PolygonMesh":
    from ...scene.catmull_clark import subdivide

    if s["subdivision_type"] not in ("CATMULL_CLARK", "SIMPLE"):
        raise InputError(f"{call}: subdivision_type must be CATMULL_CLARK or SIMPLE, got {s['subdivision_type']!r}")
    levels = int(s["render_levels"])
    if levels < 0:
        raise InputError(f"{call}: render_levels must be at least 0, got {levels}")
    from ..session import SESSION

    smooth = s["subdivision_type"] == "CATMULL_CLARK"
    limit = SESSION.renderer.simplify_subdivision_render
    return subdivide(mesh, min(levels, limit) if limit > 0 else levels, limit=bool(s["use_limit_surface"]) and smooth,
                     smooth=smooth)


def _displace(obj: MeshModifiers, mesh: "PolygonMesh", s: dict[str, Any], call: str) -> "PolygonMesh":
    from ...scene.displace_modifier import displace

    from ...scene.displacement_texture import ImageHeight

    texture = s["texture"]
    values: Callable[[np.ndarray], np.ndarray] | None = None  # no texture: every vertex reads 1
    if hasattr(texture, "displacement"):
        values = texture.displacement
    elif getattr(texture, "type", None) == "IMAGE" and hasattr(getattr(texture, "image", None), "filepath"):
        values = ImageHeight(texture.image.filepath, getattr(texture, "colorspace", None), obj.get_name())
    elif texture is not None:
        fail(f"{call} with a {getattr(texture, 'type', type(texture).__name__)} texture",
             "procedural textures of bproc.material.create_procedural_texture and image textures of "
             "bproc.loader.load_texture are")
    for key in ("mid_level", "strength"):
        if not np.isfinite(float(s[key])):
            raise InputError(f"{call}: {key} must be finite, got {s[key]}")
    return displace(mesh, values, float(s["strength"]), float(s["mid_level"]), str(s["direction"]),
                    str(s["texture_coords"]), obj.get_local2world_mat())


def _solidify(obj: MeshModifiers, mesh: "PolygonMesh", s: dict[str, Any], call: str) -> "PolygonMesh":
    from ...scene.solidify import solidify

    thickness, offset = float(s["thickness"]), float(s["offset"])
    if not (np.isfinite(thickness) and np.isfinite(offset)):
        raise InputError(f"{call}: thickness and offset must be finite")
    return solidify(mesh, thickness, offset, bool(s["use_rim"]), bool(s["use_even_offset"]),
                    bool(s["use_flip_normals"]))
