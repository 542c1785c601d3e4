"""Materials mixed into a material (hybridgen.scene.material_mix; BlenderProc's infuse_material): the surface is the
weighted sum of the materials - ``mix`` keeps 1 - f of the surface and adds f of the other, ``add`` leaves half of
the other alone, nested mixes multiply out. Checked in the raster albedo at pixel centres (a textured component
included; an unmixed object beside and a mixed object in front keep their own colors exactly) and in the path
tracer, whose render of a mix equals the weighted sum of the renders of its materials (a Principled BSDF with a
specular layer and an emitting material among them) within noise; what cannot mix is one line."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import hybridgen as hg
from hybridgen.errors import InputError
from hybridgen.render.raster.albedo_pass import AlbedoPass
from hybridgen.render.tonemap import srgb_decode
from hybridgen.scene.material import Material
from hybridgen.scene.material_mix import MaterialMix, components

RED, BLUE, GREEN = (0.8, 0.1, 0.1, 1.0), (0.1, 0.2, 0.9, 1.0), (0.2, 0.7, 0.3, 1.0)


def test_components_multiply_out() -> None:
    inner = Material(name="inner", base_color=GREEN, mixes=(MaterialMix.of_mode(Material(name="x"), "mix", 0.5),))
    outer = Material(name="outer", base_color=RED, mixes=(MaterialMix.of_mode(inner, "mix", 0.3),
                                                           MaterialMix.of_mode(Material(name="b"), "mix", 1.7)))
    assert [(m.name, round(w, 9)) for m, w in components(outer)] == [("outer", 0.0), ("inner", 0.0), ("x", 0.0),
                                                                     ("b", 1.0)]  # a factor above 1 is 1
    outer.mixes = outer.mixes[:1] + (MaterialMix.of_mode(Material(name="b"), "add", 0.9),)
    assert [(m.name, w) for m, w in components(outer)] == [("outer", 0.0), ("inner", 0.0), ("x", 0.0), ("b", 0.5)]
    assert all(not m.mixes for m, _ in components(outer))


def _scene(*objects: hg.MeshObject) -> hg.Scene:
    scene = hg.Scene()
    for obj in objects:
        scene.add(obj)
    scene.camera.intrinsics = hg.Intrinsics.from_fov(1.2, 96, 64, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([1.0, -0.2, 4.0], [1.0, 0.0, 0.0]))
    return scene


def _square(name: str, x: float, z: float, material: Material) -> hg.MeshObject:
    vertices = np.array([[-1.0, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]]) * [0.9, 0.9, 1] + [x, 0, z]
    return hg.MeshObject(name=name, vertices=vertices, faces=np.array([[0, 1, 2], [0, 2, 3]]), material=material,
                         uvs=np.array([[0.0, 0], [1, 0], [1, 1], [0, 1]]))


def _pixel(albedo: np.ndarray, scene: hg.Scene, point: tuple[float, float, float]) -> np.ndarray:
    intr, pose = scene.camera.intrinsics, scene.camera.keypoints[0]
    local = np.linalg.inv(pose) @ np.append(point, 1.0)
    u, v = (intr.K @ (local[:3] / local[2]))[:2]
    return albedo[int(v), int(u)]


def test_raster_albedo_is_the_weighted_sum(gl_context, tmp_path) -> None:
    Image.new("RGB", (4, 4), (30, 200, 90)).save(tmp_path / "green.png")
    textured = Material(name="t", base_color_texture=str(tmp_path / "green.png"))
    mixed = Material(name="mixed", base_color=RED, mixes=(MaterialMix.of_mode(Material(base_color=BLUE), "mix", 0.3),
                                                          MaterialMix.of_mode(textured, "mix", 0.5)))
    added = Material(name="added", base_color=RED, mixes=(MaterialMix.of_mode(Material(base_color=BLUE), "add", 0.3),))
    front = Material(name="front", base_color=GREEN, mixes=(MaterialMix.of_mode(Material(base_color=BLUE), "mix", 0.25),))
    scene = _scene(_square("mixed", 0.0, 0.0, mixed), _square("added", 2.0, 0.0, added),
                   _square("plain", 0.0, -2.0, Material(base_color=BLUE)),  # under "mixed": hidden
                   _square("front", 2.4, 0.5, front))  # over the right half of "added"
    albedo = AlbedoPass(hg.RasterView(scene)).render(scene.camera.keypoints[0], background=(0, 0, 0))
    green = srgb_decode(np.array([30, 200, 90]) / 255.0)
    red, blue = np.array(RED[:3]), np.array(BLUE[:3])
    np.testing.assert_allclose(_pixel(albedo, scene, (0.0, 0.0, 0.0)), 0.5 * (0.7 * red + 0.3 * blue) + 0.5 * green,
                               atol=2e-3)
    np.testing.assert_allclose(_pixel(albedo, scene, (1.2, 0.0, 0.0)), 0.5 * blue, atol=1e-6)
    np.testing.assert_allclose(_pixel(albedo, scene, (2.6, 0.0, 0.5)), 0.75 * np.array(GREEN[:3]) + 0.25 * blue,
                               atol=1e-6)


def test_refusals_are_one_line(jit_variant: str) -> None:
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    mi.set_variant(jit_variant)
    see_through = Material(name="glassy", alpha=0.5)
    material = Material(name="m", mixes=(MaterialMix.of_mode(see_through, "mix", 0.5),))
    with pytest.raises(InputError, match="'glassy' has transparency") as raised:
        bsdf_dict(material, "square")
    assert "\n" not in str(raised.value)


def _sun_scene(material: Material) -> hg.Scene:
    scene = hg.Scene()
    scene.add(_square("square", 0.0, 0.0, material))
    scene.world.strength = 0.0
    scene.add_light(hg.Light("sun", "SUN", energy=3.0, local2world=np.eye(4)))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.25, 24, 24, clip_start=0.01)
    scene.camera.add_keypoint(hg.look_at([0.0, -0.3, 6.0], [0.0, 0.0, 0.0]))
    return scene


def _render(material: Material, variant: str) -> np.ndarray:
    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from tools.principled_vs_cycles import hybridgen_settings

    scene = _sun_scene(material)
    view = PathTraceView(scene, hybridgen_settings(1), variant=variant)
    return np.asarray(view.render(scene.camera.keypoints[0], seed=0, spp=64), np.float64)


@pytest.mark.parametrize("mode, f", [("mix", 0.3), ("add", 0.6)])
def test_path_traced_mix_is_the_weighted_sum_of_renders(jit_variant: str, mode: str, f: float) -> None:
    matte = Material(name="matte", base_color=RED, specular=0.0)
    glossy = Material(name="glossy", base_color=BLUE, roughness=0.35, specular=0.8, emission=(1.0, 1.0, 0.0),
                      emission_strength=0.4)
    mixed = Material(name="mixed", base_color=RED, specular=0.0, mixes=(MaterialMix.of_mode(glossy, mode, f),))
    keep, weight = (1 - f, f) if mode == "mix" else (0.0, 0.5)
    expected = keep * _render(matte, jit_variant).mean((0, 1)) + weight * _render(glossy, jit_variant).mean((0, 1))
    ours = _render(mixed, jit_variant).mean((0, 1))
    np.testing.assert_allclose(ours, expected, rtol=0.02, atol=2e-3)
    assert np.abs(ours - _render(matte, jit_variant).mean((0, 1))).max() > 0.05  # the mix shows


def test_a_mirror_in_a_mix_is_one_line(jit_variant: str) -> None:
    """The path kernel treats singular (mirror-smooth metal or glass) surfaces by their own BSDF; inside a blend it
    cannot tell them, so such a mix is refused rather than rendered wrong."""
    import mitsuba as mi

    from hybridgen.render.pathtrace.mitsuba_materials import bsdf_dict

    mi.set_variant(jit_variant)
    mirror = Material(name="mirror", base_color=BLUE, metallic=1.0, roughness=0.0)
    with pytest.raises(InputError, match="'mirror' has a mirror-smooth metal or glass surface"):
        bsdf_dict(Material(name="m", mixes=(MaterialMix.of_mode(mirror, "mix", 0.5),)), "square")
