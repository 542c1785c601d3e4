"""``bproc.loader`` for object and room datasets: ``load_shapenet``, ``load_pix3d``, ``load_ikea``,
``load_AMASS``, ``load_replica``, ``load_scenenet`` and ``load_front3d``.

Each runs hybridgen's own loader of that dataset (:mod:`hybridgen.modules`: the layouts read, the draws and
what is set are documented there, and are BlenderProc's) through :func:`~hybridgen.bproc.loader_support.run_module`
and returns ``bproc.types.MeshObject`` objects with their custom properties (``category_id``,
``used_synset_id``, ``is_scene_net_obj``, ``is_3d_front``, ``room_id`` ...). Random draws (a model of a
category, a texture, an AMASS frame) come from Python's ``random``, which BlenderProc draws from and the
script's seed sets. ``load_shapenet`` returns one object (BlenderProc's return type), the others a list.
Labels: ``load_scenenet`` and ``load_front3d`` take a ``bproc.utility.LabelIdMapping``.
"""
from __future__ import annotations

import csv
import os
import tempfile
from typing import Any

from ..errors import InputError
from .label_id_mapping import as_label_mapping
from .loader_support import run_module, to_mesh_objects
from .types import MeshObject
from .types.unsupported import fail
from .utility import resolve_path


def _objects(context: Any, renamed: dict[str, str] | None = None, skipped: tuple[str, ...] = ()) -> list[MeshObject]:
    """The module's objects; the file a part was read from becomes ``model_path`` (BlenderProc's load_obj)."""
    return to_mesh_objects(list(context.scene.objects), renamed={"source_path": "model_path", **(renamed or {})},
                           skipped=skipped)


def load_shapenet(data_path: str, used_synset_id: str, used_source_id: str = "", move_object_origin: bool = True,
                  validate_meshes: bool = False) -> MeshObject:
    """One ShapeNetCore.v2 model of the synset (``used_source_id``: that model, else a drawn one), its
    rotation baked into the mesh, its origin at the bottom centre unless ``move_object_origin`` is False.
    ``validate_meshes`` (Blender's mesh repair) changes nothing hybridgen renders."""
    from ..modules.shapenet_loader import ShapeNetLoader

    context = run_module(ShapeNetLoader, {"data_path": resolve_path(data_path), "used_synset_id": str(used_synset_id),
                                          "used_source_id": str(used_source_id or ""),
                                          "move_object_origin": bool(move_object_origin)},
                         "bproc.loader.load_shapenet")
    objects = _objects(context)
    if len(objects) != 1:
        raise InputError("bproc.loader.load_shapenet: The ShapeNetLoader expects every .obj file to contain exactly "
                         f"one object, however the chosen file contained {len(objects)} objects.")
    return objects[0]


def load_pix3d(used_category: str, data_path: str = "resources/pix3d") -> list[MeshObject]:
    """One drawn Pix3D model of ``used_category``, its origin at the bottom centre."""
    from ..modules.object_dataset_loaders import Pix3DLoader

    return _objects(run_module(Pix3DLoader, {"used_category": str(used_category), "data_path": resolve_path(data_path)},
                               "bproc.loader.load_pix3d"))


def load_ikea(data_dir: str = "resources/IKEA", obj_categories: list[str] | str | None = None,
              obj_style: str | None = None) -> list[MeshObject]:
    """One IKEA model of the categories and/or style (a drawn one where several fit)."""
    from ..modules.object_dataset_loaders import IKEALoader

    categories = obj_categories if obj_categories is None or isinstance(obj_categories, str) \
        else [str(c) for c in obj_categories]
    return _objects(run_module(IKEALoader, {"data_dir": resolve_path(data_dir), "category": categories,
                                            "style": obj_style}, "bproc.loader.load_ikea",
                               {"category": "obj_categories", "style": "obj_style"}))


def load_AMASS(data_path: str, sub_dataset_id: str, temp_dir: str | None = None,  # noqa: N802 - BlenderProc's name
               body_model_gender: str | None = None, subject_id: str = "", sequence_id: int = -1,
               frame_id: int = -1, num_betas: int = 10, num_dmpls: int = 8) -> list[MeshObject]:
    """One SMPL-H body posed by a frame of an AMASS sequence (``temp_dir``: BlenderProc's scratch folder,
    unused)."""
    from ..modules.amass_loader import NUM_BETAS, NUM_DMPLS, AMASSLoader

    if (int(num_betas), int(num_dmpls)) != (NUM_BETAS, NUM_DMPLS):
        fail(f"bproc.loader.load_AMASS(num_betas={num_betas}, num_dmpls={num_dmpls})",
             f"hybridgen's body model uses {NUM_BETAS} betas and {NUM_DMPLS} DMPL components")
    config = {"data_path": resolve_path(data_path), "sub_dataset_id": str(sub_dataset_id),
              "body_model_gender": body_model_gender, "subject_id": subject_id, "sequence_id": sequence_id,
              "frame_id": frame_id}
    return _objects(run_module(AMASSLoader, config, "bproc.loader.load_AMASS"), skipped=("source_path",))


def load_replica(data_path: str, data_set_name: str, use_smooth_shading: bool = False) -> list[MeshObject]:
    """``<data_path>/<data_set_name>/mesh.ply`` as :func:`load_obj` reads a PLY (vertex colors as base color), its
    file normals cleared (``clear_custom_splitnormals``), smooth shaded with ``use_smooth_shading``."""
    from .loader_object import load_obj

    path = os.path.join(resolve_path(data_path), str(data_set_name), "mesh.ply")
    if not os.path.isfile(path):
        raise InputError(f"bproc.loader.load_replica: the Replica mesh does not exist: '{path}'")
    objects = load_obj(path)
    for obj in objects:  # Replica's file normals are wrong: BlenderProc clears them
        obj.clear_custom_splitnormals()
    if use_smooth_shading:
        for obj in objects:
            obj.set_shading_mode("SMOOTH")
    return objects


def _mapping_file(label_mapping: Any, call: str, folder: str) -> str:
    """``label_mapping`` written as a CSV (``id,name``) into ``folder``; returns its path."""
    mapping = as_label_mapping(label_mapping, call)
    path = os.path.join(folder, "label_mapping.csv")
    with open(path, "w", encoding="utf-8", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["id", "name"])
        for label, id_value in mapping:
            writer.writerow([id_value, label])
    return path


def load_scenenet(file_path: str, texture_folder: str, label_mapping: Any,
                  unknown_texture_folder: str | None = None) -> list[MeshObject]:
    """A SceneNet room: its objects sorted by name, a drawn texture per object, ``category_id`` from
    ``label_mapping`` (NYU labels), custom property ``is_scene_net_obj``."""
    from ..modules.scenenet_loader import SceneNetLoader

    call = "bproc.loader.load_scenenet"
    with tempfile.TemporaryDirectory(prefix="hybridgen-labels-") as folder:
        config = {"file_path": resolve_path(file_path), "texture_folder": resolve_path(texture_folder),
                  "unknown_texture_folder": None if unknown_texture_folder is None
                  else resolve_path(unknown_texture_folder),
                  "mapping_file": _mapping_file(label_mapping, call, folder)}
        context = run_module(SceneNetLoader, config, call, {"mapping_file": "label_mapping"})
    return _objects(context)


def load_front3d(json_path: str, future_model_path: str, front_3D_texture_path: str,  # noqa: N803
                 label_mapping: Any, ceiling_light_strength: float = 0.8,
                 lamp_light_strength: float = 7.0) -> list[MeshObject]:
    """A 3D-FRONT house: its room meshes (ceilings emitting ``ceiling_light_strength``) and its placed 3D-FUTURE
    furniture (lamps emitting ``lamp_light_strength``), ``category_id`` from ``label_mapping``, custom property
    ``is_3d_front``."""
    from ..modules.front3d_loader import Front3DLoader

    call = "bproc.loader.load_front3d"
    json_file, models = resolve_path(json_path), resolve_path(future_model_path)
    if not os.path.exists(json_file):
        raise InputError(f"{call}: The given path does not exists: {json_file}")
    if not json_file.endswith(".json"):
        raise InputError(f"{call}: The given path does not point to a .json file: {json_file}")
    if not os.path.exists(models):
        raise InputError(f"{call}: The 3D future model path does not exist: {models}")
    with tempfile.TemporaryDirectory(prefix="hybridgen-labels-") as folder:
        config = {"json_path": json_file, "3D_future_model_path": models,
                  "3D_front_texture_path": resolve_path(front_3D_texture_path),
                  "mapping_file": _mapping_file(label_mapping, call, folder),
                  "ceiling_light_strength": float(ceiling_light_strength),
                  "lamp_light_strength": float(lamp_light_strength)}
        context = run_module(Front3DLoader, config, call, {
            "mapping_file": "label_mapping", "3D_future_model_path": "future_model_path"})
    for part in context.scene.objects:  # BlenderProc 2's properties: placed furniture vs. the room meshes
        if "type" in part.attributes:
            part.attributes["is_used"] = True
        else:
            part.attributes.pop("uid", None)
    return _objects(context, renamed={"type": "3D_future_type"})


def _upward_cluster(heights: Any, areas: Any, bandwidth: float = 0.005) -> Any:
    """Mask of the faces in the height cluster of largest area: heights sorted and split where two neighbours are
    more than ``bandwidth`` apart (BlenderProc clusters with a mean shift of that bandwidth)."""
    import numpy as np

    order = np.argsort(heights)
    breaks = np.flatnonzero(np.diff(heights[order]) > bandwidth) + 1
    labels = np.empty(len(heights), dtype=np.int64)
    labels[order] = np.searchsorted(breaks, np.arange(len(heights)), side="right")
    totals = np.bincount(labels, weights=areas)
    return labels == int(np.argmax(totals))


def load_matterport3d(data_folder: str, used_house_id: str | None = None,
                      compare_floor_angle_in_degrees: float = 15.0) -> tuple[MeshObject, MeshObject]:
    """A Matterport3D house (an ``.obj`` anywhere under ``data_folder``, the one naming ``used_house_id`` or a
    drawn one), read Z up as stored, its materials showing their texture unlit (BlenderProc links the image to a
    Background shader), and its floor split off: the faces whose normal is within
    ``compare_floor_angle_in_degrees`` of world +Z, at the height (5 mm clusters) of largest such area, become
    the object ``Surface``. Returns ``(house, floor)``."""
    from pathlib import Path

    import numpy as np

    from ..io.mesh_loader import load_objects
    from ..scene.mesh_object import MeshObject as ScenePart

    call = "bproc.loader.load_matterport3d"
    folder = Path(resolve_path(str(data_folder)))
    if not folder.exists():
        raise InputError(f"{call}: The Matterport3D data folder must exist! ('{folder}')")
    files = sorted(p for p in folder.glob("**/*.obj") if "aayBHfsNo7d" not in str(p))
    if used_house_id is not None:
        files = [p for p in files if str(used_house_id) in str(p)]
        if len(files) != 1:
            raise InputError(f"{call}: The used house id: {used_house_id} does "
                             + ("not appear in" if not files else "appear more than once in")
                             + " the downloaded .obj files!")
        chosen = files[0]
    elif not files:
        raise InputError(f"{call}: no .obj file under '{folder}'")
    else:
        import random

        chosen = random.choice(files)
    parts = load_objects(chosen, up_axis="Z")
    if len({p.name for p in parts}) != 1:
        raise InputError(f"{call}: At this point only one object should be loaded, not more or less: "
                         f"{len({p.name for p in parts})}")
    cos_limit = np.cos(np.deg2rad(float(compare_floor_angle_in_degrees)))
    records = []
    for part in parts:
        world = part.vertices @ part.local2world[:3, :3].T + part.local2world[:3, 3]
        corners = world[part.faces]
        cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        length = np.linalg.norm(cross, axis=1)
        up = np.divide(cross[:, 2], length, out=np.zeros(len(length)), where=length > 0) >= cos_limit
        records.append((part, up, np.median(corners[:, :, 2], axis=1), 0.5 * length))
    heights = np.concatenate([r[2][r[1]] for r in records])
    if not len(heights):
        raise InputError(f"{call}: No surface object was constructed! (no upward face in '{chosen}')")
    floor_mask = _upward_cluster(heights, np.concatenate([r[3][r[1]] for r in records]))
    house_parts, floor_parts, offset = [], [], 0
    for part, up, _, _ in records:
        chosen_faces = np.zeros(len(part.faces), dtype=bool)
        chosen_faces[np.flatnonzero(up)] = floor_mask[offset:offset + int(up.sum())]
        offset += int(up.sum())
        for keep, into, name in ((~chosen_faces, house_parts, part.name), (chosen_faces, floor_parts, "Surface")):
            if keep.any():
                used, faces = np.unique(part.faces[keep], return_inverse=True)  # only the vertices they use

                def subset(values: Any) -> Any:
                    return None if values is None else values[used]

                into.append(ScenePart(name=name, vertices=part.vertices[used], faces=faces.reshape(-1, 3),
                                      vertex_normals=subset(part.vertex_normals), uvs=subset(part.uvs),
                                      material=part.material, local2world=part.local2world,
                                      attributes={**part.attributes, "source_path": str(chosen)},
                                      vertex_colors=subset(part.vertex_colors)))
    materials: dict[int, Any] = {}
    house = to_mesh_objects(house_parts, materials, renamed={"source_path": "model_path"})[0]
    floor = to_mesh_objects(floor_parts, materials, renamed={"source_path": "model_path"})[0]
    for material in {id(m): m for m in house.get_materials() + floor.get_materials()}.values():
        material.make_emissive(1.0, replace=True)  # the texture, unlit (BlenderProc's Background shader)
    return house, floor
