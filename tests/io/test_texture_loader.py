"""loader.TextureLoader and getter.Texture: images the test writes load as named textures with their pixels,
colorspace and custom properties; conditions, index and random_samples select them as BlenderProc does; a
selected texture maps onto a material."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from hybridgen.errors import ConfigError, InputError
from hybridgen.sampling.registry import DrawContext, draw, parse_value
from tests.config.test_blenderproc_modules import run_config_text


@pytest.fixture
def images(tmp_path: Path) -> dict:
    folder = tmp_path / "dust"
    (folder / "nested").mkdir(parents=True)
    rng = np.random.default_rng(0)
    pixels = {"a.png": rng.integers(0, 256, (6, 5, 3), dtype=np.uint8),
              "b.png": rng.integers(0, 256, (4, 4), dtype=np.uint8),
              "c.png": rng.integers(0, 65536, (3, 7), dtype=np.uint16)}
    for name, array in pixels.items():
        Image.fromarray(array).save(folder / name)
    Image.fromarray(pixels["a.png"]).save(folder / "nested" / "d.png")  # sub-folders are not read
    other = tmp_path / "other" / "a.png"  # same file name elsewhere: Blender's .001
    other.parent.mkdir()
    Image.fromarray(pixels["b.png"]).save(other)
    return {"folder": folder, "other": other, "pixels": pixels}


def _run(tmp_path: Path, modules: list, seed: int = 0):
    return run_config_text(tmp_path, json.dumps({"version": 3, "modules": [
        {"module": "main.Initializer", "config": {"global": {"output_dir": str(tmp_path / "out")}, "seed": seed}},
        *modules]}))


def test_folder_and_file_load_as_named_textures(tmp_path, images):
    context = _run(tmp_path, [
        {"module": "loader.TextureLoader", "config": {"path": str(images["folder"]), "colorspace": "Non-Color",
                                                      "add_properties": {"cp_dust_texture": True}}},
        {"module": "loader.TextureLoader", "config": {"path": str(images["other"])}},
        {"module": "loader.TextureLoader", "config": {"path": str(images["folder"] / "b.png")}}])  # loaded: skipped
    textures = context.scene.textures
    assert [t.name for t in textures] == ["ct_a.png", "ct_b.png", "ct_c.png", "ct_a.png.001"]
    for texture in textures[:3]:
        np.testing.assert_array_equal(texture.pixels, images["pixels"][Path(texture.path).name])
        assert texture.colorspace == "Non-Color" and texture.properties == {"dust_texture": True}
    assert textures[2].pixels.dtype == np.uint16
    assert textures[3].colorspace == "sRGB" and textures[3].properties == {}
    assert Path(textures[3].path) == images["other"]


def test_getter_texture_conditions_index_and_samples(tmp_path, images):
    context = _run(tmp_path, [
        {"module": "loader.TextureLoader", "config": {"path": str(images["folder"]),
                                                      "add_properties": {"cp_kind": "dust"}}},
        {"module": "loader.TextureLoader", "config": {"path": str(images["other"]),
                                                      "add_properties": {"cp_kind": "scratch"}}}])
    scene = context.scene
    folder = images["folder"]
    rng = np.random.default_rng(1)

    def get(**params):
        return draw(parse_value({"provider": "getter.Texture", **params}, "t"), DrawContext(rng, scene))

    assert get(conditions={"cp_kind": "dust"}) == [str(folder / n) for n in ("a.png", "b.png", "c.png")]
    assert get(conditions={"name": "ct_a.*"}) == [str(folder / "a.png"), str(images["other"])]
    assert get(conditions={"name": "ct_a"}) == []  # the whole name must match
    assert get(conditions=[{"name": "ct_c.png"}, {"cp_kind": "scr.*"}]) == [str(folder / "c.png"),
                                                                             str(images["other"])]
    assert get(conditions={"type": "IMAGE", "use_nodes": True, "cp_kind": "dust"}, index=1) == str(folder / "b.png")
    assert get(conditions={"cp_missing": 1}) == [] and get(conditions={"colorspace": "sRGB"}) == []
    drawn = get(conditions={"cp_kind": "dust"}, random_samples=2)
    assert len(drawn) == 2 and set(drawn) < {str(folder / n) for n in ("a.png", "b.png", "c.png")}
    assert len({tuple(get(random_samples=2)) for _ in range(20)}) > 1
    with pytest.raises(InputError, match="no texture matches"):
        get(conditions={"name": "nothing"}, check_empty=True)
    with pytest.raises(ConfigError, match="index and random_samples"):
        get(index=0, random_samples=1)


def _quad(path: Path) -> Path:
    path.write_text("o ground\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                    "f 1/1 2/2 3/3 4/4\n")
    return path


def test_selected_texture_maps_onto_a_material(tmp_path, images):
    context = _run(tmp_path, [
        {"module": "loader.TextureLoader", "config": {"path": str(images["folder"]),
                                                      "add_properties": {"cp_dust_texture": True}}},
        {"module": "loader.ObjLoader", "config": {"path": str(_quad(tmp_path / "ground.obj"))}},
        {"module": "manipulators.MaterialManipulator", "config": {
            "selector": {"provider": "getter.Entity", "conditions": {"name": "ground"}},
            "material": {"base_color_texture": {"provider": "getter.Texture", "index": 0,
                                                "conditions": {"cp_dust_texture": True, "name": "ct_b.*"}}}}}])
    assert context.scene.by_name("ground").material.base_color_texture == str(images["folder"] / "b.png")


def test_bad_texture_inputs_are_one_line(tmp_path, images):
    (images["folder"] / "notes.txt").write_text("not an image")
    with pytest.raises(ConfigError, match=r"notes\.txt' is not a readable image") as info:
        _run(tmp_path, [{"module": "loader.TextureLoader", "config": {"path": str(images["folder"])}}])
    assert "loader.TextureLoader" in str(info.value) and "key 'path'" in str(info.value)
    with pytest.raises(ConfigError, match="no image file or folder"):
        _run(tmp_path, [{"module": "loader.TextureLoader", "config": {"path": str(tmp_path / "missing")}}])
    with pytest.raises(ConfigError, match="colorspace"):
        _run(tmp_path, [{"module": "loader.TextureLoader", "config": {"path": "x", "colorspace": "sRGBB"}}])
    with pytest.raises(ConfigError, match="cp_"):
        _run(tmp_path, [{"module": "loader.TextureLoader", "config": {"path": "x", "add_properties": {"a": 1}}}])
