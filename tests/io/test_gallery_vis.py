"""Preview colors (`vis`, `gallery`): viridis against the published table, the Middlebury flow wheel's colors
for the cardinal directions, segmentation legends; `vis` on the BlenderProc layout and on stereo output."""
from __future__ import annotations

import numpy as np
import pytest
from PIL import Image

import hybridgen as hg
from hybridgen.io.colormaps import FLOW_WHEEL, flow_to_color, id_colors, viridis
from hybridgen.io.preview import id_legend
from tests.data.scenes import config_text


def test_viridis_matches_the_published_table():
    # viridis entries 0, 128 and 255 as published (van der Walt & Smith; matplotlib's _viridis_data)
    published = {0: (0.267004, 0.004874, 0.329415), 128: (0.127568, 0.566949, 0.550556),
                 255: (0.993248, 0.906157, 0.143936)}
    for index, rgb in published.items():
        expected = (np.asarray(rgb) * 255).astype(np.uint8)
        np.testing.assert_array_equal(viridis(np.array([index / 256 + 1e-9]))[0], expected)
    np.testing.assert_array_equal(viridis(np.array([0.0, 1.0])), [[68, 1, 84], [253, 231, 36]])
    try:
        from matplotlib import colormaps
    except ImportError:
        return
    t = np.linspace(0, 1, 1001)
    np.testing.assert_array_equal(viridis(t), colormaps["viridis"](t, bytes=True)[:, :3])


def test_flow_wheel_cardinal_directions():
    """Baker et al.'s wheel (55 hues, RY 15, YG 6, GC 4, CB 11, BM 13, MR 6): at full magnitude right is red,
    down yellow, left cyan-blue, up blue-violet; zero flow is white, half magnitude half saturated."""
    assert FLOW_WHEEL.shape == (55, 3)
    flow = np.array([[1, 0], [0, 1], [-1, 0], [0, -1], [0, 0], [0.5, 0], [2, 0]], float)
    colors = flow_to_color(flow, max_radius=1.0).astype(int)
    # right: wheel[0] = (255, 0, 0)
    np.testing.assert_array_equal(colors[0], [255, 0, 0])
    # down (v > 0 in image axes): halfway between wheel[13] = (255, 221, 0) and wheel[14] = (255, 238, 0)
    np.testing.assert_allclose(colors[1], [255, 229, 0], atol=1)
    # left: wheel[27] = (0, 255 - floor(255 * 2 / 11), 255) = (0, 209, 255)
    np.testing.assert_array_equal(colors[2], [0, 209, 255])
    # up: halfway between wheel[40] = (78, 0, 255) and wheel[41] = (98, 0, 255)
    np.testing.assert_allclose(colors[3], [88, 0, 255], atol=1)
    np.testing.assert_array_equal(colors[4], [255, 255, 255])
    np.testing.assert_allclose(colors[5], [255, 127, 127], atol=1)
    np.testing.assert_array_equal(colors[6], [191, 0, 0])  # beyond max_radius: 75 %
    # default normalization: the largest magnitude in the image
    np.testing.assert_array_equal(flow_to_color(flow * 7)[[6, 0]], [[255, 0, 0], [255, 127, 127]])


def test_segmentation_legend_names_ids():
    ids = np.array([[0, 2], [5, 2]])
    visible = [{"idx": 2, "name": "box", "category_id": 4}, {"idx": 5, "name": "ball", "category_id": 4}]
    legend = id_legend("instance_segmaps", ids, visible)
    assert [(v, label) for v, _, label in legend.entries] == [(0, "background"), (2, "box (category 4)"),
                                                              (5, "ball (category 4)")]
    assert legend.entries[1][1] == tuple(int(c) for c in id_colors(np.array([2]))[0])
    by_class = id_legend("category_id_segmaps", np.array([[0, 4]]), visible)
    assert [label for _, _, label in by_class.entries] == ["background", "box, ball"]


@pytest.mark.parametrize("layout", ["blenderproc", "single"])
def test_vis_blenderproc_layout_and_stereo(gl_context, tmp_path, run_cli, layout):
    config = tmp_path / "config.yaml"
    config.write_text(config_text(layout=layout).replace("render_object_records: true}",
                                                         "render_object_records: true, stereo: true}"))
    hg.run_config(config, [str(tmp_path / "out")])
    target = tmp_path / "out/1.hdf5" if layout == "blenderproc" else tmp_path / "out/data.hdf5"
    code, out, err = run_cli("vis", str(target), "--keys", "colors", "depth", "instance_segmaps",
                             "--save", str(tmp_path / "png"))
    assert code == 0, err
    sheets = sorted((tmp_path / "png").glob("*.png"))
    assert [p.name for p in sheets] == (["1.png"] if layout == "blenderproc" else
                                        ["data_0000.png", "data_0001.png", "data_0002.png"])
    sheet = np.asarray(Image.open(sheets[0]).convert("RGB"))
    # 6 tiles (left/right of 3 keys) on 3 columns, each 40x30 enlarged 5x to 200 px: two rows, not 1-px strips
    assert sheet.shape[1] == 3 * 200 and sheet.shape[0] > 2 * 150
    # the depth tile (row 0, column 2) is viridis: every non-black pixel is a table entry
    tile = sheet[14:14 + 150, 400:600].reshape(-1, 3)
    table = {tuple(c) for c in viridis(np.linspace(0, 1, 2048))}
    colored = [tuple(p) for p in tile if p.any()]
    assert colored and all(p in table for p in colored)
