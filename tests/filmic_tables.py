"""Filmic tables written for tests (hybridgen/render/filmic_view.py reads Blender's; these stand in for them)."""
from __future__ import annotations

from pathlib import Path

import numpy as np

from hybridgen.render.filmic_view import CUBE, CURVE


def write_cube(path: Path, values: np.ndarray, title: str = "t") -> None:
    """``values`` (N, N, N, 3) indexed [r, g, b] as a .cube file (red fastest)."""
    n = values.shape[0]
    rows = values.transpose(2, 1, 0, 3).reshape(-1, 3)
    path.write_text(f'TITLE "{title}"\n# comment\nLUT_3D_SIZE {n}\n' +
                    "\n".join(" ".join(f"{v:.7f}" for v in row) for row in rows) + "\n")


def write_spi1d(path: Path, values: np.ndarray) -> None:
    """A one-component curve over [0, 1]."""
    path.write_text(f"Version 1\nFrom 0.0 1.0\nLength {len(values)}\nComponents 1\n{{\n" +
                    "\n".join(f"    {v:.10e}" for v in values) + "\n}\n")


def grid(n: int) -> np.ndarray:
    """The identity table of size ``n``: (n, n, n, 3) [r, g, b] -> (r, g, b)."""
    axis = np.linspace(0.0, 1.0, n)
    return np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), axis=-1)


def identity_tables(folder: Path, curve: np.ndarray) -> Path:
    """A colormanagement folder under ``folder`` with an identity cube and ``curve``."""
    (folder / "filmic").mkdir(parents=True, exist_ok=True)
    write_cube(folder / CUBE, grid(9).astype(np.float32))
    write_spi1d(folder / CURVE, curve)
    return folder
