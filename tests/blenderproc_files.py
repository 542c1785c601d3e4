"""Reading BlenderProc's per-keypoint output (``<output_dir>/<i>.hdf5``) in tests."""
from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import h5py


def numbered_files(folder: Path) -> list[Path]:
    """The ``<i>.hdf5`` files of ``folder`` in numeric order."""
    found = [p for p in Path(folder).iterdir() if re.fullmatch(r"\d+\.hdf5", p.name)]
    return sorted(found, key=lambda p: int(p.stem))


def read_numbered(folder: Path) -> dict[str, list[Any]]:
    """Every dataset of the numbered files, per key the values of the files in numeric order (as stored)."""
    out: dict[str, list[Any]] = {}
    for path in numbered_files(folder):
        with h5py.File(path) as f:
            for key in f:
                if isinstance(f[key], h5py.Dataset):
                    out.setdefault(key, []).append(f[key][()])
    return out
