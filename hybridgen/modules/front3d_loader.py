"""``loader.Front3DLoader``: a 3D-FRONT house (JSON) with its 3D-FUTURE furniture, as BlenderProc loads it
(see :mod:`hybridgen.io.front3d_house` for what is read and how)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from ..config.notices import notice
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.front3d_house import (FURNITURE_FILE, TEXTURE_FILE, category_of, furniture_name, furniture_pose,
                                house_meshes, label_mapping, mean_linear_color, placed_copy)
from ..io.mesh_cache import load_objects_cached
from ..run.context import RunContext
from ..scene.mesh_object import MeshObject
from .base import Module, Role
from .dataset_support import ADD_PROPERTIES, add_properties, dataset_folder, nonnegative, read_json
from .obj_loader import add_with_blender_names


@register_module("loader.Front3DLoader")
class Front3DLoader(Module):
    """Loads the rooms of one 3D-FRONT house JSON and places its 3D-FUTURE furniture."""

    role = Role.LOADER

    params = (
        Param("json_path", "path", doc="the house's .json file"),
        Param("3D_future_model_path", "path", doc="3D-FUTURE-model folder (<jid>/raw_model.obj, texture.png)"),
        Param("3D_front_texture_path", "path", doc="3D-FRONT-texture folder (<hash>/texture.png)"),
        Param("mapping_file", "path", "resources/front_3D/3D_front_mapping.csv",
              doc="label mapping CSV (id,name): category_id of each object name"),
        Param("ceiling_light_strength", "float", 0.8, doc="emission strength of ceilings"),
        Param("lamp_light_strength", "float", 7.0, doc="emission strength of lamps"),
        ADD_PROPERTIES,
    )

    def run(self, context: RunContext) -> None:
        cfg = self.config
        json_path = Path(cfg["json_path"])
        if json_path.suffix.lower() != ".json":
            raise ConfigError(f"'{json_path}' is not a .json file", key="json_path")
        data = read_json(json_path, "json_path", "3D-FRONT house file")
        if not isinstance(data, dict) or not isinstance(data.get("scene"), dict):
            raise ConfigError(f"'{json_path}' has no 'scene' (not a 3D-FRONT house file)", key="json_path")
        models = dataset_folder(cfg["3D_future_model_path"], "3D_future_model_path", "3D-FUTURE model")
        textures = Path(cfg["3D_front_texture_path"])
        mapping_path = Path(cfg["mapping_file"])
        mapping = label_mapping(mapping_path)

        def category(name: str) -> int:
            return category_of(mapping, name, mapping_path)

        def notify(line: str) -> None:
            notice(line, module=self.module_name, index=self.index)

        objects = house_meshes(data, json_path, textures, nonnegative(cfg["ceiling_light_strength"],
                                                                      "ceiling_light_strength"), category, notify)
        placements = self._furniture(data, models, category, notify)
        for obj in objects + [part for group in placements for part in group]:
            obj.attributes["is_3d_front"] = True
            add_properties([obj], cfg["add_properties"])
        for obj in objects:  # one Blender object per mesh entry: a second 'Floor' becomes 'Floor.001'
            add_with_blender_names(context, [obj], renamed=True)
        for group in placements:  # the parts of one placement share a name; another placement gets .001 ...
            add_with_blender_names(context, group, renamed=True)

    def _furniture(self, data: dict[str, Any], models: Path, category: Any, notify: Any) -> list[list[MeshObject]]:
        """The parts of every placement of every furniture model; each model file parsed once."""
        lamp_strength = nonnegative(self.config["lamp_light_strength"], "lamp_light_strength")
        loaded: dict[str, list[MeshObject]] = {}
        missing: set[str] = set()
        entries = {str(e.get("uid")): e for e in data.get("furniture", []) if isinstance(e, dict)}
        placed = []
        rooms = data["scene"].get("room", [])
        for room_id, room in enumerate(rooms if isinstance(rooms, list) else []):
            for child in room.get("children", []):
                entry = entries.get(str(child.get("ref")))
                if entry is None or "furniture" not in str(child.get("instanceid", "")):
                    continue
                uid = str(entry.get("uid"))
                if uid not in loaded and uid not in missing:
                    parts = self._model(entry, models, category, lamp_strength)
                    if parts is None:
                        missing.add(uid)
                    else:
                        loaded[uid] = parts
                if uid in missing:
                    continue
                pose = furniture_pose(child)
                placed.append([placed_copy(part, pose, {"room_id": room_id, "type": "Object"})
                               for part in loaded[uid]])
        if missing:
            notify(f"{len(missing)} furniture model(s) without {FURNITURE_FILE} in '{models}' skipped (as "
                   f"BlenderProc), e.g. jid '{entries[sorted(missing)[0]].get('jid')}'")
        return placed

    def _model(self, entry: dict[str, Any], models: Path, category: Any, lamp_strength: float
               ) -> list[MeshObject] | None:
        folder = models / str(entry.get("jid", ""))
        if not (folder / FURNITURE_FILE).is_file():
            return None
        name = furniture_name(entry)
        texture = folder / TEXTURE_FILE
        # the file's own axes: the room child's pose (with its Rx(-90 deg)) replaces Blender's import turn
        parts = load_objects_cached(folder / FURNITURE_FILE, up_axis="Z")
        label = category(name)
        for part in parts:
            part.name = name
            part.category_id = label
            part.attributes.update({"uid": str(entry.get("uid")), "is_3D_future": True,
                                    "coarse_grained_class": label})
            material = part.material
            material.emission, material.emission_strength = (0.0, 0.0, 0.0), 0.0  # BlenderProc zeroes it
            if texture.is_file():
                material.base_color_texture = str(texture)
            if "bed" in name.lower() or "sofa" in name.lower():
                material.roughness = 0.5
            if "lamp" in name.lower():  # BlenderProc's make_emissive: the base color (its texture) emits
                material.emission = mean_linear_color(str(texture)) if texture.is_file() \
                    else tuple(material.base_color[:3])
                material.emission_texture = str(texture) if texture.is_file() else None
                material.emission_strength = lamp_strength
                material.emission_hidden_from_camera = True  # lights the room; the camera sees the lamp's surface
        return parts
