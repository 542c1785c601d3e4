"""Blender's Filmic view (render/filmic_view.py): the table readers and OpenColorIO's tetrahedral interpolation on
tables written here, Blender 4.2's own 8-bit codes where its tables are installed (tools/filmic_vs_blender.py
--store: 256 of 4096 values, all equal there), and a BlenderProc run's colors going through the view."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from hybridgen.render.filmic_view import (CURVE, LOG_RANGE, LOG_SCALE, FilmicView, find_colormanagement, read_cube,
                                          read_spi1d, tetrahedral)
from tests.filmic_tables import grid, identity_tables, write_cube

TABLE = Path(__file__).parent / "data" / "filmic_blender.json"


def test_cube_rows_run_red_fastest(tmp_path) -> None:
    n = 3
    r, g, b = np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing="ij")
    table = np.stack([r, 10 * g, 100 * b], axis=-1).astype(np.float32)
    write_cube(tmp_path / "t.cube", table)
    assert np.array_equal(read_cube(tmp_path / "t.cube"), table)
    assert (tmp_path / "t.cube").read_text().splitlines()[4] == "1.0000000 0.0000000 0.0000000"


def test_tetrahedral_interpolation(tmp_path) -> None:
    """Exact for an affine table (any of the six tetrahedra), continuous across them, and not trilinear: in a 2^3
    table that is 1 at (1, 1, 1) only, a point's value is its smallest fraction."""
    rng = np.random.default_rng(3)
    matrix, offset = rng.normal(size=(3, 3)), rng.normal(size=3)
    table = (grid(5) @ matrix.T + offset).astype(np.float32)
    points = rng.random((2000, 3)).astype(np.float32)
    np.testing.assert_allclose(tetrahedral(table, points), points @ matrix.T + offset, atol=2e-5)
    np.testing.assert_allclose(tetrahedral(table, np.array([[-0.5, 1.5, 0.25]])),  # clamped to the domain
                               np.array([[0.0, 1.0, 0.25]]) @ matrix.T + offset, atol=2e-5)
    corner = np.zeros((2, 2, 2, 3), np.float32)
    corner[1, 1, 1] = 1.0
    for point in ([0.5, 0.25, 0.75], [0.1, 0.9, 0.4], [0.3, 0.3, 0.8]):
        assert tetrahedral(corner, np.array([point]))[0, 0] == pytest.approx(min(point), abs=1e-6)
    ties = np.array([[0.5, 0.5, 0.5], [0.2, 0.7, 0.7], [0.6, 0.6, 0.1]])
    near = ties + np.array([1e-6, 0.0, -1e-6])
    np.testing.assert_allclose(tetrahedral(corner, ties), tetrahedral(corner, near), atol=1e-5)


def test_display_through_the_log_shaper_and_the_curve(tmp_path) -> None:
    """With an identity cube and a square-root curve, the view is sqrt(clip(shaped / 0.66)) with shaped the log2
    stops mapped from LOG_RANGE to [0, 1]: 2^-12.47 (and anything darker, zero and negatives) is black."""
    identity_tables(tmp_path, np.sqrt(np.linspace(0.0, 1.0, 4097)))
    low, high, values = read_spi1d(tmp_path / CURVE)
    assert (low, high, len(values)) == (0.0, 1.0, 4097)
    view = FilmicView.from_folder(tmp_path)
    linear = np.array([[2.0 ** LOG_RANGE[0], 0.0, -1.0], [0.18, 1.0, 2.0 ** 4], [2.0 ** 20, 1e-3, 0.5]])
    shaped = (np.log2(np.maximum(linear, 1e-38)) - LOG_RANGE[0]) / (LOG_RANGE[1] - LOG_RANGE[0])
    expected = np.sqrt(np.clip(np.clip(shaped, 0.0, 1.0) / LOG_SCALE, 0.0, 1.0))
    np.testing.assert_allclose(view.display(linear), expected, atol=2e-4)
    assert np.array_equal(view.to_uint8(linear[None])[0], np.round(expected * 255).astype(np.uint8))
    assert view.to_uint16(linear[None]).dtype == np.uint16


def test_blenders_filmic_codes() -> None:
    """Blender 4.2's own 8-bit Filmic codes of 256 values (gray ramps over 30 stops, log-uniform colors; dithering
    off): hybridgen's view from the same installed tables gives every one of them."""
    folder = find_colormanagement(environment=False)
    if folder is None:
        pytest.skip("Blender's color tables are not installed (make bpy-venv)")
    rows = json.loads(TABLE.read_text())["rows"]
    linear = np.array([row[0] for row in rows], np.float32)
    codes = np.array([row[1] for row in rows], np.uint8)
    assert np.array_equal(FilmicView.from_folder(folder).to_uint8(linear), codes)
    assert len(np.unique(codes)) > 100  # the table spans the whole range
