"""Material -> Mitsuba 3 BSDF dictionary (the principled model with its PBR maps).

The BSDF is built inside out:

- ``diffuse`` when the material has no specular, metal or transmission (Blender 4's principled is Lambertian
  then); else, in the JIT variants, hybridgen's Principled BSDF (:mod:`.principled_bsdf`, Blender 4.2's
  Principled BSDF, two-sided by itself; :mod:`.principled_material` maps the inputs, maps included, and
  ``HYBRIDGEN_PRINCIPLED=mitsuba`` restores the next item); else Mitsuba's ``principled`` (Disney 2015) with
  base color, roughness and metallic each a value or a texture, where a specular map blends principled BSDFs
  of a few specular amounts per texel (:func:`specular_levels`);
- ``normalmap`` around it for a tangent-space normal map (Mitsuba's tangent frame: x = dP/du projected
  into the surface, y = n x x, i.e. +v for a right-handed UV layout, the OpenGL convention; DirectX maps
  get their green channel inverted first) - except in hybridgen's Principled BSDF, which takes the map (and a
  coat's own, ``coat_normal_texture``) itself and follows Cycles' normal-map rules: Blender's coat does not bend
  with the base's map, and Cycles lifts and tests mapped normals differently (:mod:`.principled_frames`);
- ``bumpmap`` for a displacement map: shading normals of the surface displaced by h x scale metres (the
  texture's gradient with respect to UV times ``displacement_scale``; the 0.5 mid level of Blender's node
  does not change a gradient; a color image linked as height, ``displacement_from_color``, is its linear
  luminance, :func:`~hybridgen.render.material_textures.color_height`, times N.x + N.y + N.z, as Cycles dots a
  scalar link with the normal: :mod:`.linked_height`);
- both without Mitsuba's default bump-terminator shadowing (Estevez et al. 2019), so a mapped normal shades
  exactly as the analytic tilted normal (Cycles softens diffuse closures with Chiang et al. 2019's term
  instead: the two differ only where light grazes the geometric surface);
- ``twosided`` for opaque materials (Mitsuba's BSDFs are one-sided; Blender's are not);
- :mod:`.dust_mix`'s dust film over all that for a material with ``dust`` (BlenderProc's ``add_dust``);
- ``mask`` for alpha < 1 or an alpha texture (fractional opacity; CLIP materials get their alpha
  thresholded at 0.5 per texel). Camera and bounce rays pass masked parts; shadow rays of Mitsuba's
  ``path`` integrator do not (no transparent shadows: a cut-out casts a full shadow, unlike Cycles).

Color textures are sRGB encoded (``raw`` false), data maps are linear (``raw`` true), as Blender's
"Non-Color" image nodes in BlenderProc's material loaders.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np

from ...input_paths import not_found, utf8_path
from ...errors import InputError
from ...io.image_check import check_image_file
from ...scene.material import ALPHA_MODES, Material
from .glossy_filter import filtered_roughness
from .lobe_sampling import principled_sampling_rates
from ..material_textures import color_height, data_image
from .linked_height import linked


def rgb(value: Any) -> dict[str, Any]:
    """Mitsuba constant RGB of the first three channels of ``value``."""
    return {"type": "rgb", "value": [float(v) for v in list(value)[:3]]}


def _checked_path(texture: Any, owner: str, slot: str) -> Path:
    path = Path(texture)
    if not path.is_file():
        raise InputError(f"object '{owner}': {slot}: {not_found('texture file', path)}")
    check_image_file(path, f"object '{owner}': {slot} file")  # header pixel budget, truncation
    return path


def color_texture(texture: Any, owner: str, slot: str = "base_color_texture") -> dict[str, Any]:
    """sRGB-encoded color bitmap of a path or an HxWx{3,4} uint8 array."""
    import mitsuba as mi

    if isinstance(texture, (str, Path)):
        return {"type": "bitmap", "filename": utf8_path(_checked_path(texture, owner, slot))}
    array = np.ascontiguousarray(np.asarray(texture)[..., :3])
    if array.dtype != np.uint8 or array.ndim != 3:
        raise InputError(f"object '{owner}': {slot} must be an HxWx3/4 uint8 image")
    return {"type": "bitmap", "bitmap": mi.Bitmap(array, pixel_format=mi.Bitmap.PixelFormat.RGB), "raw": False}


def data_texture(texture: Any, owner: str, slot: str, *, channels: int = 1,
                 invert_green: bool = False, threshold: float | None = None) -> dict[str, Any]:
    """Linear (raw) bitmap of a data map: ``channels`` 1 (gray: the first channel) or 3 (a normal map).

    ``invert_green`` reads a DirectX normal map; ``threshold`` turns values into 0/1 (alpha clip).
    """
    import mitsuba as mi

    if isinstance(texture, (str, Path)) and not invert_green and threshold is None and channels == 3:
        return {"type": "bitmap", "filename": utf8_path(_checked_path(texture, owner, slot)), "raw": True}
    if isinstance(texture, (str, Path)):
        _checked_path(texture, owner, slot)
    values = data_image(texture, owner, slot, channels)  # float32 0..1, rows top-down
    if invert_green:
        values[..., 1] = 1.0 - values[..., 1]
    if threshold is not None:
        values = (values >= threshold).astype(np.float32)
    return {"type": "bitmap", "bitmap": mi.Bitmap(np.ascontiguousarray(values)), "raw": True}


def _scalar_or_map(material: Material, name: str, owner: str) -> Any:
    texture = getattr(material, f"{name}_texture")
    if texture is None:
        return float(getattr(material, name))
    return data_texture(texture, owner, f"{name}_texture")


def check_material(material: Material, owner: str, *, extra_inputs: bool = False) -> None:
    """One-line errors for values no renderer can use; ``extra_inputs``: ``material.extra`` may hold the
    Principled inputs hybridgen's own Principled BSDF reads (:mod:`.principled_material`)."""
    for name in ("roughness", "metallic", "specular", "transmission", "alpha"):
        value = getattr(material, name)
        if not (isinstance(value, (int, float)) and 0.0 <= value <= 1.0):
            raise InputError(f"object '{owner}': material '{material.name}' {name} must be in 0..1, got {value!r}")
    if material.alpha_mode not in ALPHA_MODES:
        raise InputError(f"object '{owner}': material '{material.name}' alpha_mode must be one of {ALPHA_MODES}, "
                         f"got {material.alpha_mode!r}")
    if not np.isfinite(material.displacement_scale):
        raise InputError(f"object '{owner}': material '{material.name}' displacement_scale must be finite")
    if material.extra and not extra_inputs:
        raise InputError(f"object '{owner}': material '{material.name}' has unsupported parameter(s) "
                         f"{sorted(material.extra)} (Principled inputs beyond the scene model's need hybridgen's "
                         f"Principled BSDF: a JIT variant)")


SPECULAR_LEVELS = 4
"""Principled BSDFs a specular map is interpolated between (see :func:`specular_levels`)."""


def specular_levels(material: Material, owner: str) -> tuple[list[float], list[np.ndarray]]:
    """Specular amounts s_0 < s_1 < ... and the blend weight maps a_k = clamp((s - s_(k-1)) / (s_k - s_(k-1)))
    (k >= 1) that interpolate ``principled(s_k)`` piecewise linearly per texel.

    Mitsuba's principled BSDF takes specular as one number per BSDF. Its diffuse lobe does not depend on it
    and its Fresnel reflectance at normal incidence is 0.08 x specular, linear in it, so a chain of
    ``blendbsdf`` s (``B_k = blend(a_k, B_(k-1), principled(s_k))``) reflects at each texel as the
    interpolation between the two levels around its value. A map of at most :data:`SPECULAR_LEVELS`
    distinct values uses them as the levels (exact at every texel); other maps use that many levels spaced
    evenly in sqrt(specular) between their lowest and highest value: exact at normal incidence, and towards
    grazing angles, where Fresnel is not linear in specular (steepest near 0), off by at most 0.005 (60
    degrees) and 0.05 (75 degrees) in reflectance for a map spanning 0..1 (less for narrower ranges).
    A value (no map) gives ([specular], []).
    """
    texture = material.specular_texture
    if texture is None:
        return [float(material.specular)], []
    if isinstance(texture, (str, Path)):
        _checked_path(texture, owner, "specular_texture")
    values = data_image(texture, owner, "specular_texture")[..., 0].astype(np.float64)
    distinct = np.unique(values)
    if len(distinct) <= SPECULAR_LEVELS:
        levels = distinct
    else:
        roots = np.linspace(math.sqrt(distinct[0]), math.sqrt(distinct[-1]), SPECULAR_LEVELS)
        levels = roots ** 2
        levels[0], levels[-1] = distinct[0], distinct[-1]
    weights = [np.clip((values - levels[k - 1]) / (levels[k] - levels[k - 1]), 0.0, 1.0).astype(np.float32)
               for k in range(1, len(levels))]
    return [float(level) for level in levels], weights


def _specular_bsdf(material: Material, owner: str, base: dict[str, Any],
                   levels: list[float], weights: list[np.ndarray]) -> dict[str, Any]:
    """The principled BSDF of ``material``: a chain of blends over ``levels`` (:func:`specular_levels`);
    the levels' BSDFs share one loaded copy of each texture."""
    inputs: dict[str, Any] = {"base_color": base,
                              "roughness": filtered_roughness(_scalar_or_map(material, "roughness", owner)),
                              "metallic": _scalar_or_map(material, "metallic", owner)}
    if material.transmission > 0:  # defined by its IOR; specular does not apply (Blender likewise)
        levels, weights = levels[:1], []
    if weights:
        import mitsuba as mi

        inputs = {key: mi.load_dict(value) if isinstance(value, dict) else value for key, value in inputs.items()}
    bsdf = _principled(material, inputs, levels[0])
    for level, weight in zip(levels[1:], weights):
        bsdf = {"type": "blendbsdf", "weight": data_texture(weight, owner, "specular_texture"),
                "bsdf_0": bsdf, "bsdf_1": _principled(material, inputs, level)}
    return bsdf


def _principled(material: Material, inputs: dict[str, Any], specular: float) -> dict[str, Any]:
    """Mitsuba's principled BSDF of ``material`` with ``inputs`` (base_color, roughness, metallic) and the
    specular amount ``specular``."""
    bsdf = {"type": "principled", **inputs, "spec_trans": float(material.transmission)}
    # Mitsuba's principled BSDF takes either the specular amount or the IOR: transmissive materials are
    # defined by their IOR, opaque ones by their specular amount (as in Blender's UI).
    if material.transmission > 0:
        bsdf["eta"] = float(material.ior)
    else:
        bsdf["specular"] = float(specular)
    bsdf.update(principled_sampling_rates(material, specular))  # lobes sampled by albedo (render/pathtrace/lobe_sampling.py)
    return bsdf


VERTEX_COLOR_ATTRIBUTE = "vertex_color"
"""Name of the mesh attribute holding per-vertex linear RGB (``vertex_`` prefix: interpolated over faces)."""


def bsdf_dict(material: Material, owner: str, *, vertex_colors: bool = False, uvs: bool = True) -> dict[str, Any]:
    """Mitsuba BSDF of ``material`` (see the module docstring for the nesting); with ``vertex_colors`` (the
    mesh carries :data:`VERTEX_COLOR_ATTRIBUTE`) and the material's ``base_color_from_vertices``, the base
    color is that attribute (a base-color texture still wins, as a linked image in Blender). ``uvs``: the mesh
    has texture coordinates (dust patterns and infused images read them, :mod:`.dust_mix`, :mod:`.color_layers`)."""
    from . import principled_material

    if material.mixes:  # other materials mixed in (render/pathtrace/material_mixes.py)
        from .material_mixes import mixed_bsdf

        return mixed_bsdf(material, owner, lambda part: bsdf_dict(part, owner, vertex_colors=vertex_colors, uvs=uvs))
    blender = principled_material.enabled()  # hybridgen's Principled BSDF (JIT variants)
    check_material(material, owner, extra_inputs=blender)
    if material.base_color_texture is not None:
        base = color_texture(material.base_color_texture, owner)
    elif vertex_colors and material.base_color_from_vertices:
        base = {"type": "mesh_attribute", "name": VERTEX_COLOR_ATTRIBUTE}
    else:
        base = rgb(material.base_color)
    if material.base_color_layers:  # infused images over it (render/pathtrace/color_layers.py)
        from .color_layers import layered

        base = layered(base, material, owner, uvs=uvs)
    bsdf: dict[str, Any]
    levels, weights = specular_levels(material, owner)
    plain = levels[-1] == 0 and material.metallic == 0 and material.metallic_texture is None
    if plain and material.transmission == 0 and not material.extra:
        # A principled material without specular, metal or transmission is Lambertian (as Blender 4's).
        bsdf = {"type": "diffuse", "reflectance": base}
    elif blender:
        specular = float(material.specular) if material.specular_texture is None else \
            data_texture(material.specular_texture, owner, "specular_texture")
        bsdf = principled_material.plugin_dict(
            material, owner, base, filtered_roughness(_scalar_or_map(material, "roughness", owner)),
            _scalar_or_map(material, "metallic", owner), specular)
    else:
        bsdf = _specular_bsdf(material, owner, base, levels, weights)
    if blender and bsdf.get("type") != "diffuse" and principled_material.layer_normals(material):
        coated = principled_material.has_coat(material)  # uncoated: the Coat Normal map changes nothing
        for key, slot in (("normal_map", "normal_texture"), ("coat_normal_map", "coat_normal_texture")):
            if getattr(material, slot) is not None and (coated or key == "normal_map"):  # a frame per layer
                bsdf[key] = data_texture(getattr(material, slot), owner, slot, channels=3,
                                         invert_green=material.normal_y_down)
    elif material.normal_texture is not None:
        bsdf = {"type": "normalmap", "bsdf": bsdf, "use_shadowing_function": False,
                "normalmap": data_texture(material.normal_texture, owner, "normal_texture", channels=3,
                                          invert_green=material.normal_y_down)}
    if material.displacement_texture is not None and material.displacement_scale != 0:
        height = material.displacement_texture
        if material.displacement_from_color:  # a color (scalar) linked straight to the output: Cycles' N-dot
            height = linked(data_texture(color_height(height, owner, "displacement_texture"), owner,
                                         "displacement_texture"))
        else:
            height = data_texture(height, owner, "displacement_texture")
        bsdf = {"type": "bumpmap", "bsdf": bsdf, "scale": float(material.displacement_scale),
                "use_shadowing_function": False, "arbitrary": height}
    if material.transmission == 0 and not (blender and bsdf_is_plugin(bsdf)):
        # Mitsuba's opaque BSDFs are one-sided; Blender (and real meshes with mixed windings) need both sides.
        bsdf = {"type": "twosided", "material": bsdf}
    if material.dust:  # dust films over the two-sided BSDF, under alpha
        from .dust_mix import wrap

        bsdf = wrap(bsdf, material, owner, uvs=uvs)
    clip = 0.5 if material.alpha_mode == "CLIP" else None
    if material.alpha_texture is not None:
        opacity: Any = data_texture(material.alpha_texture, owner, "alpha_texture", threshold=clip)
        bsdf = {"type": "mask", "opacity": opacity, "material": bsdf}
    elif material.alpha < 1.0:
        alpha = float(material.alpha) if clip is None else float(material.alpha >= clip)
        if alpha < 1.0:
            bsdf = {"type": "mask", "opacity": alpha, "material": bsdf}
    return bsdf


def bsdf_is_plugin(bsdf: dict[str, Any]) -> bool:
    """Whether ``bsdf`` (possibly inside normal / bump map wrappers) is hybridgen's two-sided Principled BSDF."""
    from .principled_bsdf import PLUGIN_NAME

    while bsdf.get("type") in ("normalmap", "bumpmap"):
        bsdf = bsdf["bsdf"]
    return bsdf.get("type") == PLUGIN_NAME
