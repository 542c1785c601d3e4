"""io/ values the mutation run (tools/mutation) found unchecked: temporary names for the longest allowed file
name, the multi-material notice of the mesh loader, the flow preview's scale without any finite flow."""
from __future__ import annotations

import os

import numpy as np

import hybridgen as hg
from tests.conftest import REPO


def test_longest_allowed_final_name_gets_a_temporary_file_that_fits(tmp_path):
    from hybridgen.io.atomic import commit, temporary_path

    longest = os.pathconf(tmp_path, "PC_NAME_MAX")
    final = tmp_path / ("d" * (longest - 5) + ".hdf5")
    temp = temporary_path(final)
    assert temp.parent == tmp_path and temp.name.startswith(".d") and temp.name.endswith(".incomplete")
    assert len(os.fsencode(temp.name)) <= longest and temp.exists()
    temp.write_bytes(b"done")
    commit(temp, final)
    assert final.read_bytes() == b"done" and not temp.exists()


def test_mesh_loader_notices_only_objects_with_several_materials(tmp_path):
    notices: list[str] = []
    hg.load_objects(REPO / "configs/assets/knot.obj", name="knot", category_id=1, notify=notices.append)
    assert notices == []
    (tmp_path / "two.mtl").write_text("newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n")
    (tmp_path / "two.obj").write_text(
        "mtllib two.mtl\no slab\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "usemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\n"
        "o post\nv 3 0 0\nv 4 0 0\nv 4 0 1\nusemtl red\nf 5 6 7\n")
    objects = hg.load_objects(tmp_path / "two.obj", category_id=1, notify=notices.append)
    assert sorted(o.name for o in objects) == ["post", "slab", "slab"]
    assert len(notices) == 1 and "'slab'" in notices[0] and "'post'" not in notices[0]


def test_flow_preview_scale_without_finite_flow_starts_and_ends_at_zero():
    from hybridgen.io.preview import preview

    flow = np.full((3, 4, 2), np.nan, np.float32)
    legend = preview("forward_flow", flow).legend
    assert (legend.low, legend.high) == (0.0, 0.0)
    flow[1, 2] = (3.0, 4.0)
    assert preview("forward_flow", flow).legend.high == 5.0


def test_bop_depth_png_values_in_units_of_depth_scale_and_too_far_as_zero():
    """value * depth_scale = mm, rounded; background, non-finite and beyond-16-bit depths are 0 and the
    too-far ones are counted (worked out by hand: depth_scale 0.5 -> 2 units per mm)."""
    from hybridgen.io.depth_png import depth_png_values

    depth = np.array([[1.0, 32.7675, 32.768, np.inf], [0.0, np.nan, 0.00025, 5.0]])
    values, too_far = depth_png_values(depth, 0.5, background=5.0)
    assert values.dtype == np.uint16
    np.testing.assert_array_equal(values, [[2000, 65535, 0, 0], [0, 0, 0, 0]])  # 0.5 units rounds to even
    assert too_far == 1


def test_box_of_an_empty_mask_is_the_toolkits_no_box():
    from hybridgen.io.mask_encoding import bbox_of

    assert bbox_of(np.zeros((4, 5), bool)) == [-1, -1, -1, -1]
    mask = np.zeros((4, 5), bool)
    mask[1:3, 2:5] = True
    assert bbox_of(mask) == [2, 1, 3, 2]


def test_contact_sheet_legend_bar_ends_and_id_swatches():
    """The scale bar runs from the colormap's first entry (left) to its last (right), matplotlib's viridis
    ends written out; each id swatch is a 10 px square on its 12 px row, with the gap below it left dark."""
    from hybridgen.io.preview import Legend
    from hybridgen.io.visualize import _id_rows, _scale_bar

    bar = np.asarray(_scale_bar(Legend("depth", 0.0, 5.0, "m"), 100))
    np.testing.assert_array_equal(bar[2, 0], [68, 1, 84])      # viridis(0.0)
    np.testing.assert_array_equal(bar[2, -1], [253, 231, 36])  # viridis(1.0)
    colors = [(255, 0, 0), (0, 255, 0), (0, 0, 255)]
    rows = np.asarray(_id_rows(Legend("ids", entries=[(i + 1, c, f"o{i}") for i, c in enumerate(colors)]), 120))
    assert rows.shape[0] == 12 * 3 + 2
    for i, color in enumerate(colors):
        top = 1 + 12 * i
        np.testing.assert_array_equal(rows[top + 5, 6], color)          # inside the swatch
        np.testing.assert_array_equal(rows[top + 11:top + 13, 6], 0)  # the gap under it
