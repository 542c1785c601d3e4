"""``bproc.loader`` for materials, textures and HDRIs: ``load_ccmaterials`` (ambientCG), ``load_haven_mat``
(Poly Haven), ``load_texture`` and ``get_random_world_background_hdr_img_path_from_haven``.

Materials are read by :mod:`hybridgen.io.texture_sets` (which maps feed which Principled input, BlenderProc's
values) into ``bproc.types.Material`` objects named after the asset folder, with BlenderProc's custom
properties ``is_cc_texture`` (both loaders, as BlenderProc sets it) and ``asset_name``, plus the ``cp_*`` ones
given. Assets are visited in sorted order (BlenderProc: ``os.listdir`` order for ambientCG).

BlenderProc's two-phase loading (``preload=True`` makes empty materials, ``fill_used_empty_materials=True``
later fills the used ones) exists to save Blender memory; hybridgen reads images when rendering, so a preload
gives complete materials and a fill call returns the used ones of them (as BlenderProc's second call
returns them, filled). A fill call without a preload before loads nothing.
"""
from __future__ import annotations

import glob
import os
import random
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

from ..errors import InputError
from ..io.texture_sets import cc_material, haven_material
from ..scene.material import Material as SceneMaterial
from .session import SESSION
from .types import Material, MeshObject
from .utility import resolve_path

PROBABLY_USEFUL_CC_TEXTURES = (
    "paving stones", "tiles", "wood", "fabric", "bricks", "metal", "wood floor", "ground", "rock", "concrete",
    "leather", "planks", "rocks", "gravel", "asphalt", "painted metal", "painted plaster", "marble", "carpet",
    "plastic", "roofing tiles", "bark", "metal plates", "wood siding", "terrazzo", "plaster", "paint",
    "corrugated steel", "painted wood", "lava cardboard", "clay", "diamond plate", "ice", "moss", "pipe", "candy",
    "chipboard", "rope", "sponge", "tactile paving", "paper", "cork", "wood chips")
"""The ambientCG asset name starts BlenderProc loads by default (unless ``use_all_materials``)."""
TEXTURE_COLORSPACES = ("Filmic Log", "Linear", "Linear ACES", "Non-Color", "Raw", "sRGB", "XYZ")


def _custom_properties(given: dict[str, Any] | None, call: str) -> dict[str, Any]:
    properties = {}
    for key, value in (given or {}).items():
        if not str(key).startswith("cp_"):
            raise InputError(f"{call}: All cp have to start with cp_ (got {key!r})")
        properties[str(key)[3:]] = value
    return properties


def _is_used(material: Material) -> bool:
    return any(material in obj.get_materials() for obj in SESSION.entities if isinstance(obj, MeshObject))


def _find(asset: str, properties: dict[str, Any]) -> Material | None:
    """The session's material of ``asset`` with ``properties`` (BlenderProc's find_cc_material_by_name)."""
    wanted = {"is_cc_texture": True, "asset_name": asset, **properties}
    found = [m for m in SESSION.materials if m.is_valid()
             and all(m.has_cp(k) and m.get_cp(k) == v for k, v in wanted.items())]
    if len(found) > 1:
        raise InputError(f"There was more than one material found! (asset '{asset}')")
    return found[0] if found else None


def _material(asset: str, scene_material: SceneMaterial, properties: dict[str, Any]) -> Material:
    material = Material(asset, scene_material)
    material.set_cp("is_cc_texture", True)
    material.set_cp("asset_name", asset)
    for key, value in properties.items():
        material.set_cp(key, value)
    return material


def _assets(folder: Path, names: list[str], read: Callable[[Path], SceneMaterial | None],
            properties: dict[str, Any], preload: bool, fill: bool, call: str) -> list[Material]:
    if preload and fill:
        raise InputError(f"{call}: Preload and fill used empty materials can not be done at the same time, check "
                         "config!")
    materials = []
    for asset in names:
        if fill:
            found = _find(asset, properties)
            if found is not None and _is_used(found):
                materials.append(found)
            continue
        scene_material = read(folder / asset)
        if scene_material is not None:
            materials.append(_material(asset, scene_material, properties))
    return materials


def load_ccmaterials(folder_path: str = "resources/cctextures", used_assets: list[str] | None = None,
                     preload: bool = False, fill_used_empty_materials: bool = False,
                     add_custom_properties: dict[str, Any] | None = None, use_all_materials: bool = False,
                     skip_transparent_materials: bool = True) -> list[Material]:
    """One material per ambientCG asset folder ``<asset>/<asset>_2K_Color.jpg`` (or ``_2K-JPG_Color.jpg``)
    whose lower-cased name starts with one of ``used_assets`` (spaces removed; default: BlenderProc's list of
    probably useful kinds, all with ``use_all_materials``); assets with an opacity map are skipped unless
    ``skip_transparent_materials`` is False."""
    call = "bproc.loader.load_ccmaterials"
    folder = Path(resolve_path(folder_path))
    if not folder.is_dir():
        raise InputError(f"{call}: The folder path does not exist: {folder}")
    if used_assets is None:
        wanted = [] if use_all_materials else list(PROBABLY_USEFUL_CC_TEXTURES)
    else:
        wanted = [str(a).lower() for a in used_assets]
    names = []
    for asset in sorted(os.listdir(folder)):
        if wanted and not any(asset.lower().startswith(w.replace(" ", "")) for w in wanted):
            continue
        base = next((folder / asset / f"{asset}{suffix}" for suffix in ("_2K_Color.jpg", "_2K-JPG_Color.jpg")
                     if (folder / asset / f"{asset}{suffix}").is_file()), None)
        if base is None:
            continue
        if skip_transparent_materials and Path(str(base).replace("Color", "Opacity")).exists():
            continue
        names.append(asset)
    return _assets(folder, names, cc_material, _custom_properties(add_custom_properties, call), preload,
                   fill_used_empty_materials, call)


def load_haven_mat(folder_path: str = "resources/haven", used_assets: list[str] | None = None,
                   preload: bool = False, fill_used_empty_materials: bool = False,
                   add_cp: dict[str, Any] | None = None, return_random_element: bool = False) -> Any:
    """One material per Poly Haven texture folder (``<folder>/textures/<asset>/<asset>_diff_<res>.<ext>`` +
    maps; ``textures`` is added when ``folder_path`` is its parent) whose name starts with one of
    ``used_assets``; with ``return_random_element`` one drawn folder's material (Python's ``random``)."""
    call = "bproc.loader.load_haven_mat"
    folder = Path(resolve_path(str(folder_path)))
    if not folder.exists():
        raise InputError(f"{call}: The given haven folder does not exist: {folder}")
    if folder.name != "textures" and (folder / "textures").exists():
        folder = folder / "textures"
    names = sorted(os.listdir(folder))
    if not names:
        raise InputError(f"{call}: No texture folders found in {folder}.")
    if used_assets:
        names = [n for n in names if any(n.startswith(str(asset)) for asset in used_assets)]
        if not names:
            raise InputError(f"{call}: No texture folders found in {folder} for which used_assets can be meet: "
                             f"{list(used_assets)}.")
    if return_random_element:
        names = [random.choice(names)]
    names = [n for n in names if (folder / n).is_dir()]
    materials = _assets(folder, names, haven_material, _custom_properties(add_cp, call), preload,
                        fill_used_empty_materials, call)
    if return_random_element:
        if len(materials) != 1:
            raise InputError(f"{call}: the drawn texture folder '{names[0] if names else ''}' holds no Poly Haven "
                             "material (<asset>_diff_<res> image)")
        return materials[0]
    return materials


def get_random_world_background_hdr_img_path_from_haven(data_path: str) -> str:
    """A drawn (Python's ``random``, over the sorted list) ``<data_path>/hdris/*/*.hdr``; set it with
    ``bproc.world.set_world_background_hdr_img``."""
    call = "bproc.loader.get_random_world_background_hdr_img_path_from_haven"
    if not os.path.exists(data_path):
        raise InputError(f"{call}: The data path does not exists: {data_path}")
    hdris = os.path.join(data_path, "hdris")
    if not os.path.exists(hdris):
        raise InputError(f"{call}: The folder: {hdris} does not contain a folder name hdfris. Please use the "
                         "download script.")
    files = sorted(glob.glob(os.path.join(hdris, "*", "*.hdr")))
    if not files:
        raise InputError(f"{call}: no .hdr file in the sub-folders of '{hdris}'")
    return random.choice(files)


@dataclass
class Texture:
    """An image texture (Blender's ``bpy.types.ImageTexture``): ``name`` ``ct_<image name>``, its ``image``
    (an object with ``filepath``, as ``bpy.data.images.load`` gives) and the image's color space."""

    name: str
    image: Any
    colorspace: str = "sRGB"
    type: str = field(default="IMAGE", init=False)


_LOADED_IMAGES: dict[int, set[str]] = {}
"""Image paths ``load_texture`` loaded, per session (``bproc.clean_up`` gives the session new lists)."""


def load_texture(path: str, colorspace: str = "sRGB") -> list[Texture]:
    """A texture per image: the file ``path``, or every file in the folder ``path``. An image loaded before (in
    this session) is skipped, as BlenderProc skips it."""
    from .bpy_standin import Image

    if colorspace not in TEXTURE_COLORSPACES:
        raise InputError(f"bproc.loader.load_texture: colorspace {colorspace!r} is not one of "
                         f"{', '.join(TEXTURE_COLORSPACES)}")
    resolved = resolve_path(path)
    if not os.path.exists(resolved):
        raise InputError(f"bproc.loader.load_texture: Invalid path: {resolved}")
    paths = sorted(glob.glob(os.path.join(resolved, "*"))) if os.path.isdir(resolved) else [resolved]
    loaded = _LOADED_IMAGES.setdefault(id(SESSION.materials), set())
    textures = []
    for image_path in paths:
        if image_path in loaded:
            continue
        loaded.add(image_path)
        image = Image(image_path)
        textures.append(Texture(f"ct_{image.name}", image, colorspace))
    return textures
