"""``bproc.types.Material``: a Blender material with one Principled BSDF, over hybridgen's
:class:`~hybridgen.scene.material.Material` (BlenderProc's MaterialUtility).

Principled BSDF inputs are named as in Blender 3 or Blender 4 (``"Specular"`` / ``"Specular IOR Level"``,
``"Emission"`` / ``"Emission Color"``, ``"Transmission"`` / ``"Transmission Weight"``); see :data:`INPUTS`.
The inputs hybridgen's material model keeps in ``extra`` (coat, sheen, subsurface, anisotropy, specular tint;
:mod:`hybridgen.scene.principled_inputs`) are taken the same way (``"Sheen Weight"`` / ``"Sheen"``,
``"Subsurface Weight"`` / ``"Subsurface"``, ``"Coat Weight"`` / ``"Clearcoat"`` ...), as numbers or colors.
Colors are linear RGBA in 0..1, as Blender's socket values. An image (``bpy.data.images.load(...)``, anything
with a ``filepath``) linked to an input becomes that input's texture map. Node-level calls (``new_node``,
``link`` ...) have no counterpart in hybridgen's material model and raise one line naming the call.
"""
from __future__ import annotations

import copy
from typing import Any, Callable

import numpy as np

from ...errors import InputError
from ...scene import principled_inputs
from ...scene.material import Material as SceneMaterial
from ...scene.principled_links import COLOR_FIELDS, INPUTS, NORMAL_INPUTS
from ..session import SESSION
from .struct import Struct
from .unsupported import unsupported_method


def _is_image(value: Any) -> bool:
    return hasattr(value, "filepath") and not isinstance(value, (str, bytes))


def _input(input_name: str) -> tuple[str, str | None]:
    if input_name not in INPUTS:
        raise InputError(f"Principled BSDF input '{input_name}' is not supported by hybridgen yet "
                         f"(supported: {', '.join([*INPUTS, *principled_inputs.BY_BLENDER_NAME])})")
    return INPUTS[input_name]


def _set_extra(mat: SceneMaterial, input_name: str, value: Any) -> None:
    """Set an input of :data:`hybridgen.scene.principled_inputs.BY_BLENDER_NAME` in ``mat.extra``."""
    key = principled_inputs.BY_BLENDER_NAME[input_name].key
    if _is_image(value) or hasattr(value, "is_output_socket"):
        raise InputError(f"linking an image or a node socket to Principled BSDF input '{input_name}' is not "
                         "supported by hybridgen yet")
    try:
        mat.extra[key] = principled_inputs.checked(key, list(value) if hasattr(value, "__len__") else value)
    except ValueError as error:
        raise InputError(f"Principled BSDF input '{input_name}' {error}") from None


def _set_normal(mat: SceneMaterial, input_name: str, value: Any) -> None:
    """A value on a normal socket (:data:`NORMAL_INPUTS`): unlinks its map; an image or socket: one line."""
    if _is_image(value):
        raise InputError(f"an image linked straight to Principled BSDF input '{input_name}' is not supported by "
                         "hybridgen (Blender reads its colors as a world-space normal: BlenderProc adds no Normal Map "
                         f"node); a tangent-space normal map is the material's {NORMAL_INPUTS[input_name]}")
    if hasattr(value, "is_output_socket"):
        raise InputError(f"linking a node socket to '{input_name}' is not supported by hybridgen yet")
    try:
        vector = [float(v) for v in value]
    except (TypeError, ValueError):
        vector = []
    if len(vector) != 3:
        raise InputError(f"'{input_name}' takes 3 numbers, got {value!r}")
    setattr(mat, NORMAL_INPUTS[input_name], None)


def _get_extra(mat: SceneMaterial, input_name: str) -> Any:
    """The value of an ``extra`` input (its default when unset), colors as RGBA lists as Blender's sockets."""
    entry = principled_inputs.BY_BLENDER_NAME[input_name]
    value = mat.extra.get(entry.key, entry.default)
    return [*value, 1.0] if entry.kind == "color" else list(value) if entry.kind == "vector" else value


class Material(Struct):
    """A material: ``blender_obj`` is the hybridgen material every mesh slot holding this one renders with."""

    KIND = "material"
    ATTRIBUTES = ("name", "users")

    def __init__(self, name: str, scene_material: SceneMaterial | None = None) -> None:
        super().__init__(name)
        self.blender_obj = scene_material if scene_material is not None else SceneMaterial(name=self.get_name())
        self.blender_obj.name = self.get_name()
        SESSION.materials.append(self)

    def set_name(self, name: str) -> None:
        super().set_name(name)
        self.blender_obj.name = self.get_name()

    def get_users(self) -> int:
        """How many mesh material slots hold this material."""
        return sum(1 for e in SESSION.entities for m in getattr(e, "_slots", ()) if m is self)

    def duplicate(self) -> "Material":
        """An independent copy named ``<name>.001``."""
        from dataclasses import replace

        return Material(self.get_name(), replace(self.blender_obj, extra=dict(self.blender_obj.extra)))

    def set_principled_shader_value(self, input_name: str, value: Any) -> None:
        """Set a Principled BSDF input to a number, a color (3 or 4 values; alpha 1 when 3) or an image."""
        if input_name in principled_inputs.BY_BLENDER_NAME:
            _set_extra(self.blender_obj, input_name, value)
            return
        if input_name in NORMAL_INPUTS:
            _set_normal(self.blender_obj, input_name, value)
            return
        field, texture = _input(input_name)
        mat = self.blender_obj
        if field == "base_color":  # an image or a value replaces whatever was linked (BlenderProc unlinks it)
            mat.base_color_layers, mat.base_color_from_vertices = (), False
            mat.missing_files = ()  # the mesh's own (missing) base-color files are no longer used
        if _is_image(value):
            if texture is None:
                raise InputError(f"an image on Principled BSDF input '{input_name}' is not supported by hybridgen yet")
            setattr(mat, texture, str(value.filepath))
            return
        if hasattr(value, "is_output_socket"):
            raise InputError(f"linking a node socket to '{input_name}' is not supported by hybridgen yet")
        if texture is not None:
            setattr(mat, texture, None)  # a value replaces the linked image, as BlenderProc unlinks it
        if field in COLOR_FIELDS:
            rgba = np.asarray(value, dtype=np.float64).reshape(-1)
            if rgba.size not in (3, 4) or not np.all(np.isfinite(rgba)):
                raise InputError(f"'{input_name}' takes 3 or 4 finite numbers, got {rgba.tolist()}")
            rgba = np.append(rgba, 1.0) if rgba.size == 3 else rgba
            setattr(mat, field, tuple(float(c) for c in rgba[: 4 if field == "base_color" else 3]))
        else:
            setattr(mat, field, float(value))

    def get_principled_shader_value(self, input_name: str) -> Any:
        """The input's value (colors as RGBA lists), or the linked image (an object with ``filepath``; a normal
        socket's tangent-space map)."""
        if input_name in principled_inputs.BY_BLENDER_NAME:
            return _get_extra(self.blender_obj, input_name)
        mat = self.blender_obj
        if input_name in NORMAL_INPUTS:
            field, texture = "", NORMAL_INPUTS[input_name]
            if getattr(mat, texture) is None:
                return [0.0, 0.0, 0.0]  # the socket's (unused) default value
        else:
            field, texture = _input(input_name)
        if texture is not None and getattr(mat, texture) is not None:
            from ..bpy_standin import Image

            linked = getattr(mat, texture)
            return Image(linked if isinstance(linked, str) else "<array>")
        value = getattr(mat, field)
        return list(value) + ([1.0] if field == "emission" else []) if field in COLOR_FIELDS else value

    def make_emissive(self, emission_strength: float, replace: bool = False,
                      emission_color: list[float] | None = None, non_emissive_color_socket: Any = None) -> None:
        """Emit ``emission_strength`` x color (default: the base color or its image). Not ``replace``: camera
        rays see the surface as before and every other ray sees the emission (BlenderProc's "Is Camera Ray"
        mix); ``replace``: the surface is the emission alone."""
        if non_emissive_color_socket is not None:
            raise InputError("make_emissive(non_emissive_color_socket=...) is not supported by hybridgen yet")
        mat = self.blender_obj
        if emission_color is None and mat.base_color_layers:
            raise InputError("make_emissive of a base color with an infused texture (infuse_texture) is not supported "
                             "by hybridgen yet; pass emission_color")
        if emission_color is None:
            mat.emission, mat.emission_texture = tuple(mat.base_color[:3]), mat.base_color_texture  # type: ignore[assignment]
        else:
            mat.emission = tuple(float(c) for c in list(emission_color)[:3])  # type: ignore[assignment]
            mat.emission_texture = None
        mat.emission_strength = float(emission_strength)
        mat.emission_hidden_from_camera = not replace
        if replace:
            mat.base_color, mat.base_color_texture = (0.0, 0.0, 0.0, mat.base_color[3]), None
            mat.specular, mat.metallic = 0.0, 0.0

    def remove_emissive(self) -> None:
        """Undo :meth:`make_emissive`'s emission."""
        mat = self.blender_obj
        mat.emission_strength, mat.emission_texture, mat.emission_hidden_from_camera = 0.0, None, False

    def set_displacement_from_principled_shader_value(self, input_name: str, multiply_factor: float) -> None:
        """The image linked to ``input_name`` times ``multiply_factor`` (m) becomes the displacement (Blender's
        default "Bump Only": shading normals change, geometry and labels do not). The height is what Blender's
        Math node takes from a linked color: the luminance of the image's linear color (``displacement_from_color``);
        the image linked now, as in BlenderProc, whatever is linked to ``input_name`` later."""
        _, texture = _input(input_name)
        if texture == "base_color_texture" and self.blender_obj.base_color_layers:
            raise InputError(f"set_displacement_from_principled_shader_value('{input_name}') of a base color with an "
                             "infused texture (infuse_texture) is not supported by hybridgen yet")
        linked = getattr(self.blender_obj, texture) if texture is not None else None
        if linked is None:
            raise InputError(f"material '{self.get_name()}': the input {input_name} of the principled shader does "
                             "not have any incoming connection (as in BlenderProc)")
        self.blender_obj.displacement_texture = linked
        self.blender_obj.displacement_scale = float(multiply_factor)
        self.blender_obj.displacement_from_color = True

    def infuse_texture(self, texture: Any, mode: str = "overlay", connection: str = "Base Color",
                       texture_scale: float = 0.05, strength: float = 0.5, invert_texture: bool = False) -> None:
        """Blend ``texture`` (``bproc.loader.load_texture``'s) into the input ``connection``: ``set`` links it,
        ``overlay`` / ``mix`` blend it over what is linked there (nothing without a link), at factor ``strength``,
        read at UV / ``texture_scale``; BlenderProc's semantics, quirks included (:mod:`hybridgen.scene.infused_texture`)."""
        from ..material_infuse import infuse

        infuse(self.blender_obj, texture, mode, connection, texture_scale, strength, invert_texture)

    def infuse_material(self, material: "Material", mode: str = "mix", mix_strength: float = 0.5) -> None:
        """Mix ``material`` (as it is now) into this one's surface: ``mix`` keeps ``1 - mix_strength`` of it and adds
        ``mix_strength`` of the other; ``add`` - as BlenderProc's code runs - leaves the other at half strength alone
        (:mod:`hybridgen.scene.material_mix`)."""
        from ...scene.material_mix import MODES, MaterialMix, unsupported_in_mix

        used_mode = str(mode).lower()
        if used_mode not in MODES:
            raise InputError(f'bproc.types.Material.infuse_material: This mode is unknown here: {used_mode}, only '
                             '["mix", "add"]!')
        if not isinstance(material, Material):
            raise InputError(f"bproc.types.Material.infuse_material: material must be a bproc material, got "
                             f"{type(material).__name__}")
        for part in (self.blender_obj, material.blender_obj):
            reason = unsupported_in_mix(part)
            if reason is not None:
                raise InputError(f"bproc.types.Material.infuse_material: material '{part.name}' has {reason}; mixing "
                                 "that is not supported by hybridgen yet")
        snapshot = copy.deepcopy(material.blender_obj)  # BlenderProc copies the node tree: later changes stay out
        self.blender_obj.mixes = (*self.blender_obj.mixes, MaterialMix.of_mode(snapshot, used_mode, mix_strength))

    def map_vertex_color(self, layer_name: str = "Col", active_shading: bool = True) -> None:
        """The mesh's vertex colors become the base color (Blender's color attribute linked to Base Color, in place
        of what was linked there: an image, infused images)."""
        mat = self.blender_obj
        mat.base_color_from_vertices, mat.base_color_texture, mat.base_color_layers = True, None, ()
        mat.missing_files = ()

    def _attribute(self, attr_name: str) -> Any:
        return self.get_users() if attr_name == "users" else self.get_name()

    get_the_one_node_with_type: Callable[..., Any] = unsupported_method("Material", "get_the_one_node_with_type")
    get_nodes_with_type: Callable[..., Any] = unsupported_method("Material", "get_nodes_with_type")
    get_nodes_created_in_func: Callable[..., Any] = unsupported_method("Material", "get_nodes_created_in_func")
    new_node: Callable[..., Any] = unsupported_method("Material", "new_node")
    remove_node: Callable[..., Any] = unsupported_method("Material", "remove_node")
    insert_node_instead_existing_link: Callable[..., Any] = unsupported_method(
        "Material", "insert_node_instead_existing_link")
    link: Callable[..., Any] = unsupported_method("Material", "link")
    unlink: Callable[..., Any] = unsupported_method("Material", "unlink")
    get_node_connected_to_the_output_and_unlink_it: Callable[..., Any] = unsupported_method(
        "Material", "get_node_connected_to_the_output_and_unlink_it")
