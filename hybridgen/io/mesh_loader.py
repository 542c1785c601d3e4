"""Mesh files -> scene objects, read the way Blender's importers (which BlenderProc uses) read them.

``LOADERS`` maps a file suffix to the trimesh file type and the file's native up axis:

- OBJ: +Y up (Blender's importer: ``axis_forward=-Z, axis_up=Y``), turned to hybridgen's +Z up, and split
  by its ``o`` objects (Blender's ``split_mode`` ON). Each object is named as Blender names it: the text
  after ``o`` (faces before any ``o`` take the file's stem); sections that repeat an ``o`` name are one
  object, as in Blender. Each object keeps its own materials, with the Principled values Blender 4.2's importer
  gives their MTL values (:mod:`hybridgen.io.mtl_principled`).
- PLY, STL, OFF: taken as stored (Blender's PLY and STL importers do not turn them).
- glTF/GLB: +Y up by its specification, turned to +Z up as Blender's glTF importer does.

The turn is baked into the vertices and normals (as Blender does), so an object's ``local2world`` is only
the pose given to the loader. ``up_axis`` ("Y" or "Z") overrides the format's native axis.

hybridgen objects carry one material each: an OBJ object whose faces use several materials becomes one
hybridgen object per material, all with the object's Blender name (``attributes["material_part"]`` names
the material) - a name selector picks all of them, as it would pick the one Blender object.
"""
from __future__ import annotations

import io
import os
from pathlib import Path
from typing import Any, Callable

import numpy as np

from ..config.notices import notice
from ..input_paths import not_found
from ..errors import InputError
from ..scene.frames import Y_UP_TO_Z_UP
from ..scene.material import Material
from ..scene.mesh_object import MeshObject
from .image_check import check_image_file
from .blender_names import _SENTINEL, _SENTINEL_RE, blender_name, tag_obj_objects, unique_blender_name
from .mesh_references import is_lenient, referenced_files
from .obj_smoothing import blender_smooth_normals, smooth_objects
from .mtl_principled import apply_mtl_values
from .texture_needs import check_libraries, diffuse_maps_by_material, mark_missing_textures

LOADERS: dict[str, tuple[str, str]] = {
    ".obj": ("obj", "Y"),
    ".ply": ("ply", "Z"),
    ".stl": ("stl", "Z"),
    ".off": ("off", "Z"),
    ".glb": ("glb", "Y"),
    ".gltf": ("gltf", "Y"),
}
"""Suffix -> (trimesh file type, native up axis as Blender's importer reads the format)."""
__all__ = ["LOADERS", "_SENTINEL", "blender_name", "load_objects", "tag_obj_objects", "unique_blender_name"]

Notify = Callable[[str], None]


def vertex_colors_linear(visual: Any) -> np.ndarray | None:
    """(V, 3) linear RGB of per-vertex colors (8-bit sRGB in PLY/OBJ files, decoded as Blender decodes its
    byte color attributes), or None when the visual has none."""
    if getattr(visual, "kind", None) != "vertex":
        return None
    codes = np.asarray(visual.vertex_colors, dtype=np.float64)[:, :3] / 255.0
    return np.where(codes <= 0.04045, codes / 12.92, ((codes + 0.055) / 1.055) ** 2.4)


def _has_loaded_normals(geometry: Any) -> bool:
    # trimesh keeps normals read from the file in its cache; computed ones are only made on access.
    cache = getattr(getattr(geometry, "_cache", None), "cache", {})
    return "vertex_normals" in cache


def _undecodable_match(folder: Path, name: str) -> Path | None:
    """The file below ``folder`` that ``name`` names when ``name`` was decoded from bytes that are not UTF-8
    (each such byte read as U+FFFD, as the OBJ and MTL text is): the one entry per path part whose name reads
    as that part. None when no part holds U+FFFD, or no entry or several match."""
    if "\ufffd" not in name:
        return None
    path = folder
    for part in name.replace("\\", "/").split("/"):
        if part in ("", "."):
            continue
        if part == ".." or not path.is_dir():
            return None
        if "\ufffd" not in part:
            path = path / part
            continue
        try:
            with os.scandir(path) as entries:
                found = [e.name for e in entries if os.fsencode(e.name).decode("utf-8", "replace") == part]
        except OSError:
            return None
        if len(found) != 1:
            return None
        path = path / found[0]
    return path if path.is_file() else None


def _bytes_name_resolver(file: Path) -> Any:
    """trimesh's resolver for the files an OBJ names (inside its folder), which also finds MTL and texture
    files whose names are not valid UTF-8 (Latin-1 names from old archives): trimesh reads the names from
    text, where such bytes are U+FFFD. An MTL that is not UTF-8 is handed to trimesh with those bytes as
    U+FFFD too (as the OBJ is), so the texture names it holds are found the same way."""
    import trimesh

    class BytesNameResolver(trimesh.resolvers.FilePathResolver):
        def get(self, name: str) -> bytes:
            try:
                data = super().get(name)
            except FileNotFoundError:
                match = _undecodable_match(Path(self.parent), name.strip())
                if match is None:
                    raise
                data = match.read_bytes()
            if name.strip().lower().endswith(".mtl"):
                try:
                    data.decode("utf-8")
                except UnicodeDecodeError:
                    data = data.decode("utf-8", "replace").encode("utf-8")
            return data

    return BytesNameResolver(str(file))


def check_named_textures(file: Path) -> None:
    """One-line InputError naming the texture when a diffuse texture an OBJ's MTL names (and that exists) is
    damaged, truncated or declares too many pixels (:func:`hybridgen.io.image_check.check_image_file`);
    trimesh would hand the damaged file to PIL, whose error surfaced as a traceback."""
    for library in referenced_files(file):
        if not library.is_file():
            continue
        for texture in dict.fromkeys(t for maps in diffuse_maps_by_material(library).values() for t in maps):
            if texture.is_file():
                try:
                    check_image_file(texture, "texture")
                except InputError as exc:
                    raise InputError(f"mesh '{file}': {exc} (named by '{library.name}')") from None


def _read_scene(file: Path, file_type: str) -> tuple[Any, list[str] | None]:
    """The trimesh scene of ``file``; for OBJ also the Blender object names its parts are tagged with."""
    import trimesh

    if file_type != "obj":
        return trimesh.load(str(file), file_type=file_type, force="scene", process=False), None
    text = file.read_text(encoding="utf-8", errors="replace")
    tagged, names = tag_obj_objects(text, file.stem)
    resolver = _bytes_name_resolver(file)
    scene = trimesh.load(io.BytesIO(tagged.encode("utf-8")), file_type="obj", resolver=resolver, force="scene",
                         process=False, split_objects=True, group_material=True)
    return scene, names


def _part_object_name(node: str, geometry_name: str, obj_names: list[str] | None) -> str:
    if obj_names is None:
        return str(node)
    match = _SENTINEL_RE.search(str(geometry_name)) or _SENTINEL_RE.search(str(node))
    if match is None:  # not expected: every face lies after a marker
        return obj_names[0]
    return obj_names[int(match.group(1))]


def _up_matrix(up: str) -> np.ndarray:
    return Y_UP_TO_Z_UP if up == "Y" else np.eye(4)


def load_objects(path: str | Path, *, name: str | None = None, category_id: int | None = None,
                 local2world: np.ndarray | None = None, up_axis: str = "auto",
                 attributes: dict[str, Any] | None = None, notify: Notify | None = None) -> list[MeshObject]:
    """Read a mesh file into one :class:`MeshObject` per object (per material of it, see the module doc).

    ``local2world`` (metres) poses every object; the file's own node transforms (glTF) are kept under it.
    Without ``name`` objects are named as Blender names them (OBJ ``o`` names, glTF node names, else the
    file stem); with ``name`` a single object is ``name`` and several are ``<name>.<Blender name>``.
    ``notify`` receives one line for what Blender would do differently (an object with several materials).
    """
    file = Path(path)
    suffix = file.suffix.lower()
    if suffix not in LOADERS:
        raise InputError(f"mesh '{file}': unsupported format '{suffix}'; supported: {', '.join(LOADERS)}")
    if not file.is_file():
        raise InputError(not_found("mesh file", file))
    file_type, native_up = LOADERS[suffix]
    up = native_up if up_axis == "auto" else str(up_axis).upper()
    if up not in ("Y", "Z"):
        raise InputError(f"up_axis must be 'auto', 'Y' or 'Z', got {up_axis!r}")
    problem = check_libraries(file) if file_type == "obj" else None  # missing textures: texture_needs
    if problem is not None:
        if not is_lenient():
            raise InputError(f"{problem} (hybridgen run --lenient renders it anyway)")
        (notify or notice)(problem)
    if file_type == "obj":
        check_named_textures(file)
    try:
        loaded, obj_names = _read_scene(file, file_type)
    except Exception as exc:
        raise InputError(f"cannot read mesh '{file}': {type(exc).__name__}: {exc}") from None
    import trimesh

    base = np.eye(4) if local2world is None else np.asarray(local2world, dtype=np.float64)
    turn = _up_matrix(up)
    parts: list[tuple[str, Any, np.ndarray]] = []
    for node in loaded.graph.nodes_geometry:
        transform, geometry_name = loaded.graph[node]
        geometry = loaded.geometry[geometry_name]
        if not isinstance(geometry, trimesh.Trimesh) or len(geometry.faces) == 0:
            continue
        part_name = _part_object_name(node, geometry_name, obj_names)
        parts.append((part_name, geometry, np.asarray(transform, dtype=np.float64)))
    if not parts:
        raise InputError(f"mesh '{file}' contains no triangles")
    if obj_names is not None:  # keep the file's object order (trimesh lists them last-first)
        order = {n: i for i, n in enumerate(obj_names)}
        parts.sort(key=lambda part: order[part[0]])
    smoothing: dict[str | None, bool | None] | None = None if file_type == "obj" else {}  # read when first needed
    distinct = list(dict.fromkeys(p[0] for p in parts))
    counts = {n: sum(1 for p in parts if p[0] == n) for n in distinct}
    split = [n for n in distinct if counts[n] > 1]
    if split and notify is not None:
        notify(f"mesh '{file}': object(s) {', '.join(repr(n) for n in split[:5])} use several materials; "
               "hybridgen objects carry one material each, so each becomes one object per material with the "
               "same name (attribute 'material_part')")
    objects = []
    for part_name, geometry, transform in parts:
        if name is None:
            obj_name = part_name if (obj_names is not None or len(distinct) > 1) else file.stem
        else:
            obj_name = name if len(distinct) == 1 else f"{name}.{part_name}"
        uv = getattr(geometry.visual, "uv", None)
        # Blender bakes the axis turn into the vertices; node transforms are conjugated into the new axes.
        rotation = turn[:3, :3]
        with np.errstate(invalid="ignore", over="ignore"):  # NaN/inf input is reported by MeshObject below
            vertices = np.asarray(geometry.vertices, dtype=np.float64) @ rotation.T
            normals = (np.asarray(geometry.vertex_normals, dtype=np.float64) @ rotation.T
                       if _has_loaded_normals(geometry) else None)
            if normals is None and smoothing is None:  # only OBJ objects without normals need the s lines
                smoothing = smooth_objects(file)
            shading = False if smoothing is None else smoothing.get(part_name if obj_names is not None else None, False)
            if normals is None and shading:  # s 1 without vn: Blender shades smooth (io/obj_smoothing)
                normals = blender_smooth_normals(vertices, np.asarray(geometry.faces), weld=uv is not None)
            elif normals is None and shading is None and notify is not None:
                notify(f"mesh '{file}': object '{part_name}' has faces in and out of smoothing groups and no "
                       "normals; hybridgen shades all of them flat (Blender shades the grouped ones smooth)")
        extra = {"material_part": _material_name(geometry)} if counts[part_name] > 1 else {}
        colors = vertex_colors_linear(geometry.visual)
        try:
            material = Material.from_trimesh_visual(geometry.visual, fallback_name=obj_name)
        except (OSError, SyntaxError, ValueError) as exc:  # PIL decodes an embedded or named texture here
            raise InputError(f"mesh '{file}': a texture of object '{obj_name}' is damaged or not an image "
                             f"({str(exc).splitlines()[0][:120] if str(exc) else type(exc).__name__})") from None
        material.base_color_from_vertices = colors is not None
        try:
            obj = MeshObject(
                name=obj_name,
                vertices=vertices,
                faces=np.asarray(geometry.faces),
                vertex_normals=normals,
                uvs=None if uv is None else np.asarray(uv, dtype=np.float64),
                material=material,
                category_id=category_id,
                attributes={"source_path": str(file), **extra, **(attributes or {})},
                local2world=base @ turn @ transform @ turn.T,
                vertex_colors=colors,
            )
        except InputError as exc:
            raise InputError(f"mesh '{file}': {exc}") from None
        objects.append(obj)
    if file_type == "obj":
        mark_missing_textures(objects, file)  # checked when an output shows base color
        apply_mtl_values(objects, file)  # Ns, Ks, Ka, illum, Ni, d ... as Blender 4.2's importer maps them
    return objects


def _material_name(geometry: Any) -> str:
    material = getattr(geometry.visual, "material", None)
    return str(getattr(material, "name", None) or "")
