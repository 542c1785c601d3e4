"""Blender's Principled BSDF input names -> the fields of hybridgen's :class:`~hybridgen.scene.material.Material` that
hold them: a value and, where hybridgen keeps one, the image that can be linked to the input (BlenderProc 2's
``set_principled_shader_value`` and ``infuse_texture``, v1 configs' material functions). The inputs without a field of
their own live in ``Material.extra`` (:mod:`hybridgen.scene.principled_inputs`)."""
from __future__ import annotations

INPUTS: dict[str, tuple[str, str | None]] = {
    "Base Color": ("base_color", "base_color_texture"),
    "Metallic": ("metallic", "metallic_texture"),
    "Roughness": ("roughness", "roughness_texture"),
    "Specular": ("specular", "specular_texture"),
    "Specular IOR Level": ("specular", "specular_texture"),
    "IOR": ("ior", None),
    "Alpha": ("alpha", "alpha_texture"),
    "Transmission": ("transmission", None),
    "Transmission Weight": ("transmission", None),
    "Emission": ("emission", "emission_texture"),
    "Emission Color": ("emission", "emission_texture"),
    "Emission Strength": ("emission_strength", None),
}
"""Principled BSDF input (Blender 3 and 4 names) -> (hybridgen material field, its texture field or None)."""
COLOR_FIELDS = ("base_color", "emission")
NORMAL_INPUTS = {"Normal": "normal_texture", "Coat Normal": "coat_normal_texture"}
"""Normal sockets -> the tangent-space map hybridgen keeps for them. BlenderProc's ``set_principled_shader_value``
links an image's Color straight into such a socket (no Normal Map node), which Cycles reads as a world-space
normal; hybridgen keeps tangent-space maps only (set by its loaders, config ``material:`` keys or
``blender_obj``). A value (Blender ignores an unlinked normal socket's value: the surface's own normal) unlinks
the map, as BlenderProc does."""
