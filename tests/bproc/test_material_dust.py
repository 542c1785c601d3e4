"""bproc.material.add_dust (BlenderProc 2.8): a dust layer per call on the material (nested calls stack), the
texture drawn from texture_nodes with random.choice as BlenderProc draws it (else its warning and the noise), one
line for unusable arguments; through render(), a dusty square primitive (Blender's plane UVs) gets brighter
toward the dust color by the weight hybridgen.scene.dust gives, in flakes across it."""
from __future__ import annotations

import random
import warnings

import numpy as np
import pytest
from PIL import Image

from hybridgen.bproc.loader_materials import Texture
from hybridgen.errors import InputError
from hybridgen.scene.dust import Dust, dust_weight
from writer_session import bproc  # noqa: F401 - the fixture


def test_layers_and_warning(bproc) -> None:  # noqa: F811
    material = bproc.material.create("m")
    with pytest.warns(UserWarning, match="noise"):
        bproc.material.add_dust(material, strength=0.8, texture_scale=0.05)
    assert material.blender_obj.dust == (Dust(0.8, 0.05),)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        bproc.material.add_dust(material, np.float32(1.5))
    assert material.blender_obj.dust == (Dust(0.8, 0.05), Dust(1.5, 0.1))
    assert material.duplicate().blender_obj.dust == material.blender_obj.dust


def test_texture_drawn_as_blenderproc_draws_it(bproc, tmp_path) -> None:  # noqa: F811
    for name in ("a.png", "b.png", "c.png"):
        Image.new("RGB", (4, 4), (200, 10, 10)).save(tmp_path / name)
    nodes = bproc.loader.load_texture(str(tmp_path))
    data = [Texture(nodes[0].name, nodes[0].image, "Non-Color")]  # a data image (e.g. a height map)
    material = bproc.material.create("m")
    for seed in (1, 2, 3):
        random.seed(seed)
        expected = random.choice(nodes).image.filepath
        random.seed(seed)
        bproc.material.add_dust(material, 1.0, texture_nodes=nodes, texture_scale=2.0)
        assert material.blender_obj.dust[-1] == Dust(1.0, 2.0, expected, True)
    bproc.material.add_dust(material, 1.0, texture_nodes=data)
    assert material.blender_obj.dust[-1].texture_srgb is False


@pytest.mark.parametrize("call, message", [
    (lambda b, m: b.material.add_dust(m, float("nan")), "strength must be a finite number"),
    (lambda b, m: b.material.add_dust(m, 1.0, texture_scale="x"), "texture_scale must be a finite number"),
    (lambda b, m: b.material.add_dust(m, 1.0, texture_nodes=[object()]), "has no image file"),
    (lambda b, m: b.material.add_dust("m", 1.0), "expected a bproc.types.Material"),
])
def test_unusable_arguments_give_one_line(bproc, call, message: str) -> None:  # noqa: F811
    with pytest.raises(InputError, match=message) as raised:
        call(bproc, bproc.material.create("m"))
    assert "\n" not in str(raised.value)


def _render_square(bproc, strength: float | None) -> np.ndarray:  # noqa: F811
    floor = bproc.object.create_primitive("PLANE", size=2)
    material = bproc.material.create("floor")
    material.set_principled_shader_value("Base Color", [0.1, 0.2, 0.6, 1.0])
    material.set_principled_shader_value("Specular IOR Level", 0.0)
    floor.replace_materials(material)
    if strength is not None:
        bproc.material.add_dust(material, strength, texture_scale=20.0)
    light = bproc.types.Light()
    light.set_type("SUN")
    light.set_energy(3)
    bproc.camera.set_intrinsics_from_blender_params(lens=0.8, lens_unit="FOV")
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 2.0]  # looking straight down at the square, which fills the view
    bproc.camera.add_camera_pose(pose)
    bproc.renderer.set_world_background([0.0, 0.0, 0.0], strength=0.0)  # the sun alone
    bproc.renderer.set_max_amount_of_samples(16)
    bproc.renderer.set_denoiser(None)
    bproc.renderer.set_output_format(color_depth=16)
    colors = np.asarray(bproc.renderer.render()["colors"][0], np.float64) / 65535.0
    return np.where(colors <= 0.04045, colors / 12.92, ((colors + 0.055) / 1.055) ** 2.4)  # linear


@pytest.mark.filterwarnings("ignore:bproc.material.add_dust")
@pytest.mark.parametrize("strength", [1.0])
def test_dusty_square_renders_toward_dust(bproc, strength: float) -> None:  # noqa: F811
    import hybridgen.bproc as module
    from hybridgen.bproc.session import reset
    from hybridgen.render.pathtrace.mitsuba_variant import choose_variant, is_jit

    if not is_jit(choose_variant(None)):
        pytest.skip("dust renders in the JIT variants")

    plain = _render_square(bproc, None)
    reset(keep_initialized=False)
    module.init()
    module.camera.set_resolution(32, 24)
    dusty = _render_square(module, strength)
    irradiance = 3.0 / np.pi
    base, dust = irradiance * np.array([0.1, 0.2, 0.6]), irradiance * np.array([0.8, 0.773, 0.7])
    np.testing.assert_allclose(plain.mean((0, 1)), base, rtol=0.02)
    # the square's points the pixels see (4 x 4 per pixel): x = 2 tan(0.4) (column - 15.5) / 16, and likewise y
    offsets = (np.arange(128) + 0.5) / 128 - 0.5
    x, y = np.meshgrid(2 * np.tan(0.4) * offsets, -2 * np.tan(0.4) * offsets[16:112])
    cosine = 2.0 / np.sqrt(x * x + y * y + 4.0)
    f32 = [np.float32(a) for a in (x / 2 + 0.5, y / 2 + 0.5, np.ones_like(x), cosine)]
    mean_w = dust_weight(*f32, Dust(strength, 20.0)).mean()
    toward = (dusty[..., 0].mean() - base[0]) / (dust[0] - base[0])
    assert toward == pytest.approx(mean_w, abs=0.02) and dusty[..., 0].std() > 0.05  # flakes, not a uniform film
