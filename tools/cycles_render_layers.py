"""tools/cycles_render.py's Cycles worker with what its scene build leaves out: normal maps on the Principled BSDF's
Normal and Coat Normal inputs, emission through the BSDF's own Emission inputs (under its coat and sheen), and the
size of AREA lights.

tools/cycles_render.py builds an emissive material as its BSDF plus an Emission shader (the same light for a
material without coat or sheen), links no normal map and leaves an AREA light at Blender's default size; its code
is part of the color benchmark's Cycles reference digests (tools/reference_cache.py), so these additions live
here, for the scenes that need them (:func:`needs_layers`), and the benchmark's exports and references stay as
they were.

- hybridgen side (the project's venv): :func:`export_layers` adds to an export of tools/cycles_export.py the
  arrays ``nrm<i>`` / ``cnrm<i>`` (uint8 H x W x 3 tangent-space maps, OpenGL convention: a DirectX map's green
  inverted, rows top-down) with ``uv<i>``, and ``"principled_emission": true`` on objects whose emission lies
  under a coat or sheen (tools/cycles_export.py already writes an AREA light's ``size``); :class:`LayersWorker`
  runs this file as the worker.
- bpy side (run as a script in ``.venv-bpy``, same protocol as tools/cycles_render.py)::

      .venv-bpy/bin/python tools/cycles_render_layers.py SCENE.npz

  builds the scene with tools/cycles_render.py's ``build``, then links each map through an Image Texture node
  (Non-Color, linear interpolation) and a Normal Map node (tangent space, the mesh's ``uv`` map, strength 1) to
  the Principled BSDF's Normal / Coat Normal, moves an emission into the BSDF's Emission Color / Strength, and
  makes each AREA light a square of the exported edge (m) with spread 180 degrees (a Lambertian emitter, one-sided:
  its local -z side, as hybridgen's rectangle of radiance P / (size^2 pi)).
"""
from __future__ import annotations

import json
import os
import sys
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent


def _layered_emission(material: Any) -> bool:
    return any(isinstance(material.extra.get(k, 0.0), (int, float)) and material.extra.get(k, 0.0) > 0
               for k in ("coat_weight", "sheen_weight")) and material.emission_strength > 0 and \
        max(material.emission) > 0


def needs_layers(scene: Any) -> bool:
    """Whether a hybridgen scene has what tools/cycles_render.py does not build: a normal map, a coat normal
    map, emission under a coat or sheen, or an AREA light."""
    return any(o.material.normal_texture is not None or o.material.coat_normal_texture is not None
               or _layered_emission(o.material) for o in scene.objects) \
        or any(light.type == "AREA" for light in scene.lights)


def _map(texture: Any, y_down: bool) -> np.ndarray:
    if isinstance(texture, (str, Path)):
        from PIL import Image

        texture = np.asarray(Image.open(texture).convert("RGB"))
    array = np.ascontiguousarray(np.asarray(texture)[..., :3], dtype=np.uint8).copy()
    if y_down:
        array[..., 1] = 255 - array[..., 1]
    return array


def export_layers(scene: Any, npz: Path) -> None:
    """Add the normal maps, UVs and Principled-emission flags of ``scene``'s objects to its export ``npz``."""
    data = dict(np.load(npz, allow_pickle=False))
    meta = json.loads(str(data["meta"]))
    for i, obj in enumerate(scene.objects):
        material = obj.material
        for key, texture in (("nrm", material.normal_texture), ("cnrm", material.coat_normal_texture)):
            if texture is not None and obj.uvs is not None:
                data[f"{key}{i}"] = _map(texture, material.normal_y_down != bool(os.environ.get("FLIPG")))
                data[f"uv{i}"] = np.asarray(obj.uvs, dtype=np.float32)
        if _layered_emission(material):
            meta["objects"][i]["principled_emission"] = True
    data["meta"] = np.array(json.dumps(meta))
    np.savez(npz, **data)


def worker(python: Path, npz: Path) -> Any:
    """A tools/cycles_worker.CyclesWorker running this file on ``npz``."""
    import subprocess

    sys.path.insert(0, str(HERE))
    from cycles_worker import CyclesWorker

    class LayersWorker(CyclesWorker):
        def __init__(self) -> None:
            self.log = npz.with_suffix(".log")
            with open(self.log, "w") as log:
                self.process = subprocess.Popen([str(python), str(HERE / "cycles_render_layers.py"), str(npz)],
                                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=log,
                                                text=True, bufsize=1)
            self.hello = self._answer()
            self.peak_rss_mib = None

    return LayersWorker()


def _normal_map(material: Any, pixels: np.ndarray, socket: str) -> None:
    """Link ``pixels`` (uint8 H x W x 3, rows top-down) through a tangent-space Normal Map node to ``socket``."""
    import bpy

    nodes, links = material.node_tree.nodes, material.node_tree.links
    principled = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    image = bpy.data.images.new(f"{material.name}_{socket}", pixels.shape[1], pixels.shape[0], alpha=True)
    image.colorspace_settings.name = "Non-Color"
    rgba = np.concatenate([pixels[::-1] / 255.0, np.ones(pixels.shape[:2] + (1,))], axis=-1)
    image.pixels.foreach_set(rgba.astype(np.float32).ravel())
    texture = nodes.new("ShaderNodeTexImage")
    texture.image, texture.interpolation = image, "Linear"
    normal_map = nodes.new("ShaderNodeNormalMap")
    normal_map.space, normal_map.uv_map = "TANGENT", "uv"
    links.new(texture.outputs["Color"], normal_map.inputs["Color"])
    links.new(normal_map.outputs["Normal"], principled.inputs[socket])


def _principled_emission(material: Any) -> None:
    """Move the Emission shader tools/cycles_render.py added beside the BSDF into the BSDF's own inputs."""
    nodes, links = material.node_tree.nodes, material.node_tree.links
    principled = next(n for n in nodes if n.type == "BSDF_PRINCIPLED")
    emission = next(n for n in nodes if n.type == "EMISSION")
    add = next(n for n in nodes if n.type == "ADD_SHADER")
    output = next(n for n in nodes if n.type == "OUTPUT_MATERIAL")
    principled.inputs["Emission Color"].default_value = emission.inputs["Color"].default_value
    principled.inputs["Emission Strength"].default_value = emission.inputs["Strength"].default_value
    nodes.remove(add)
    nodes.remove(emission)
    links.new(principled.outputs["BSDF"], output.inputs["Surface"])


def add_layers(path: str) -> None:
    """Link the export's normal maps, move its flagged emissions and size its AREA lights (the scene
    tools/cycles_render.py built)."""
    import bpy

    data = np.load(path, allow_pickle=False)
    meta = json.loads(str(data["meta"]))
    for index, spec in enumerate(meta.get("lights", [])):  # tools/cycles_render.py names them light<index>
        if spec["type"] == "AREA":
            light = bpy.data.lights[f"light{index}"]
            light.shape, light.size, light.spread = "SQUARE", spec["size"], np.pi
    for i, spec in enumerate(meta["objects"]):
        material = bpy.data.objects[spec["name"]].data.materials[0]
        for key, socket in (("nrm", "Normal"), ("cnrm", "Coat Normal")):
            if f"{key}{i}" in data:
                _normal_map(material, data[f"{key}{i}"], socket)
        if spec.get("principled_emission"):
            _principled_emission(material)


if __name__ == "__main__":
    sys.path.insert(0, str(HERE))
    import cycles_render  # noqa: E402  (the bpy venv: tools/ is not a package)

    original_build = cycles_render.build

    def build_with_layers(path: str) -> Any:
        built = original_build(path)
        add_layers(path)
        return built

    cycles_render.build = build_with_layers  # main() looks build up in its module when it runs
    cycles_render.main(sys.argv[1])
