"""Blender's "Filmic" view transform (BlenderProc 2's default colors), computed from Blender's own color tables.

Blender 4.2's OpenColorIO configuration (``datafiles/colormanagement/config.ocio``) defines the view ``Filmic`` as
the color space "Filmic sRGB": from scene-linear Rec.709,

1. ``log2(max(x, FLT_MIN))`` per channel, mapped from [-12.473931188, 12.526068812] to [0, 1] (an OCIO ``lg2``
   AllocationTransform);
2. the 33 x 33 x 33 table ``filmic/filmic_desat_33.cube``, interpolated tetrahedrally, its input clamped to [0, 1];
3. divided by 0.66 (a ``uniform`` AllocationTransform from [0, 0.66] to [0, 1]) - the "Filmic Log" encoding;
4. the 4096-entry curve ``filmic/filmic_to_0-70_1-03.spi1d`` (the base contrast, the look "None"), interpolated
   linearly, its input clamped to its domain: display values, sRGB-coded, that Blender writes as 8-bit codes
   ``round(255 v)``.

The tables are Blender's (and Troy Sobotka's), not hybridgen's: they are read at run time from an installed Blender
or ``bpy`` (:func:`find_colormanagement`; ``make bpy-venv`` installs one), never copied. Without them BlenderProc
runs keep the Standard view with a notice saying how to get Filmic. Blender dithers its 8-bit output (scene
``dither_intensity`` 1: noise of about half a code); hybridgen does not. Measured against Blender 4.2 writing
float images through the view (``tools/filmic_vs_blender.py``, 4096 values over 30 stops, dithering off): every
8-bit code equal, 16-bit codes within 1.
"""
from __future__ import annotations

import glob
import os
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import InputError

COLORMANAGEMENT_ENV = "HYBRIDGEN_BLENDER_COLORMANAGEMENT"
"""A Blender ``datafiles/colormanagement`` folder to read the Filmic tables from, the only one looked at when set
(set but empty: none, so BlenderProc runs keep the Standard view - the test suite's setting); unset,
:func:`find_colormanagement` looks for one."""
CUBE = Path("filmic") / "filmic_desat_33.cube"
CURVE = Path("filmic") / "filmic_to_0-70_1-03.spi1d"
LOG_RANGE = (-12.473931188, 12.526068812)
"""The ``lg2`` allocation of "Filmic Log": log2 stops mapped to [0, 1]."""
LOG_SCALE = 0.66
"""The ``uniform`` allocation [0, 0.66] -> [0, 1] after the table."""
FLT_MIN = float(np.finfo(np.float32).tiny)
"""OpenColorIO's floor before a logarithm."""


def _candidates(environment: bool) -> list[Path]:
    """Where a ``colormanagement`` folder may be: the environment variable (when ``environment`` and it is set: only
    there), a ``bpy`` of this interpreter or of the blend extra's Python (``HYBRIDGEN_BPY_PYTHON``, the
    repository's ``.venv-bpy``), of the repository's ``.venv-blenderproc`` (tools/blenderproc_reference.py), a
    system Blender."""
    from ..io.blend_loader import BPY_PYTHON_ENV, DEFAULT_BPY_PYTHON

    if environment and COLORMANAGEMENT_ENV in os.environ:
        given = os.environ[COLORMANAGEMENT_ENV]
        return [Path(given)] if given else []
    found: list[Path] = []
    prefixes = [Path(sys.prefix)]
    bpy_python = Path(os.environ.get(BPY_PYTHON_ENV) or DEFAULT_BPY_PYTHON)
    prefixes.append(bpy_python.parent.parent)
    prefixes.append(DEFAULT_BPY_PYTHON.parents[2] / ".venv-blenderproc")  # the tools' real BlenderProc (bpy 4.2)
    for prefix in prefixes:
        pattern = str(prefix / "lib" / "python3*" / "site-packages" / "bpy" / "*" / "datafiles" / "colormanagement")
        found += [Path(p) for p in sorted(glob.glob(pattern), reverse=True)]
    for root in ("/usr/share/blender", "/usr/local/share/blender"):
        found += [Path(p) for p in sorted(glob.glob(f"{root}/*/datafiles/colormanagement"), reverse=True)]
    return found


def find_colormanagement(environment: bool = True) -> Path | None:
    """The first Blender ``colormanagement`` folder that has the Filmic tables, or None; ``environment`` False
    ignores :data:`COLORMANAGEMENT_ENV`."""
    for folder in _candidates(environment):
        if (folder / CUBE).is_file() and (folder / CURVE).is_file():
            return folder
    return None


def read_cube(path: Path) -> np.ndarray:
    """A ``.cube`` 3D table as an (N, N, N, 3) float32 array indexed [r, g, b] (the file's red varies fastest);
    its domain must be [0, 1]."""
    size, rows = 0, []
    for line in Path(path).read_text().splitlines():
        words = line.split(maxsplit=1)
        if not words or words[0].startswith("#") or words[0] == "TITLE":
            continue
        if words[0] == "LUT_3D_SIZE":
            size = int(words[1])
        elif words[0] in ("DOMAIN_MIN", "DOMAIN_MAX"):
            if [float(w) for w in words[1].split()] != ([0.0] * 3 if words[0] == "DOMAIN_MIN" else [1.0] * 3):
                raise InputError(f"{path}: a 3D table over another domain than [0, 1] is not supported")
        else:
            rows.append(line)
    table = np.fromstring("\n".join(rows), dtype=np.float32, sep=" ")
    table = table.reshape(-1, 3) if table.size % 3 == 0 else table
    if size < 2 or table.shape != (size ** 3, 3):
        raise InputError(f"{path}: expected LUT_3D_SIZE and size^3 rows of three values")
    return np.ascontiguousarray(table.reshape(size, size, size, 3).transpose(2, 1, 0, 3))


def read_spi1d(path: Path) -> tuple[float, float, np.ndarray]:
    """A one-component ``.spi1d`` curve: (domain start, domain end, values)."""
    low, high, values, inside = 0.0, 1.0, [], False
    for line in Path(path).read_text().splitlines():
        words = line.split()
        if not words:
            continue
        if words[0] == "From":
            low, high = float(words[1]), float(words[2])
        elif words[0] == "Components" and words[1] != "1":
            raise InputError(f"{path}: only one-component curves are supported")
        elif words[0] == "{":
            inside = True
        elif words[0] == "}":
            inside = False
        elif inside:
            values.append(float(words[0]))
    if len(values) < 2:
        raise InputError(f"{path}: no curve values")
    return low, high, np.asarray(values, np.float64)


def tetrahedral(table: np.ndarray, rgb: np.ndarray) -> np.ndarray:
    """``table`` ((N, N, N, 3), indexed [r, g, b] over [0, 1]^3) at the points ``rgb`` (..., 3), clamped to the
    domain, interpolated tetrahedrally (OpenColorIO's ``tetrahedral``): in the cube cell of a point, from its lowest
    corner to its highest along the axes in the order of the point's fractions, largest first, each corner weighted
    by the difference of consecutive fractions (the cell split into six tetrahedra along its diagonal)."""
    n = table.shape[0]
    points = np.asarray(rgb, np.float32).reshape(-1, 3)
    x = np.clip(points, 0.0, 1.0) * np.float32(n - 1)
    base = np.minimum(x.astype(np.intp), n - 2)  # x >= 0: truncation is floor
    f = x - base
    fr, fg, fb = f[:, 0], f[:, 1], f[:, 2]
    r_top, g_over_b = (fr >= fg) & (fr >= fb), fg >= fb
    b_low, g_under_r = (fb <= fg) & (fb <= fr), fg <= fr
    # the axes with the largest and smallest fraction (ties: r first among the largest, b first among the smallest,
    # so the two differ; tied fractions give the corners between them weight 0)
    first = np.where(r_top, n * n, np.where(g_over_b, n, 1))
    last = np.where(b_low, 1, np.where(g_under_r, n, n * n))
    high, low = np.maximum(np.maximum(fr, fg), fb), np.minimum(np.minimum(fr, fg), fb)
    middle = fr + fg + fb - high - low
    channels = np.ascontiguousarray(table.reshape(-1, 3).T)  # (3, N^3): one gather per channel and corner
    index = base @ np.array([n * n, n, 1], np.intp)
    second = index + first
    third = second + (n * n + n + 1 - first - last)
    corners = ((index, 1.0 - high), (second, high - middle), (third, middle - low), (third + last, low))
    out = np.empty_like(points)
    for channel in range(3):
        values = channels[channel]
        out[:, channel] = sum(np.take(values, at) * weight for at, weight in corners)
    return out.reshape(np.shape(rgb))


@dataclass(frozen=True)
class FilmicView:
    """Blender's Filmic view from its tables (:meth:`from_folder`): :meth:`display` maps scene-linear Rec.709 to
    sRGB-coded display values in [0, 1]; :meth:`to_uint8` / :meth:`to_uint16` to image codes."""

    cube: np.ndarray
    curve_domain: tuple[float, float]
    curve: np.ndarray

    @staticmethod
    def from_folder(folder: Path) -> "FilmicView":
        low, high, values = read_spi1d(folder / CURVE)
        return FilmicView(read_cube(folder / CUBE), (low, high), values.astype(np.float32))

    def log_encoding(self, linear: np.ndarray) -> np.ndarray:
        """"Filmic Log" of scene-linear RGB (..., 3): steps 1-3 of the module documentation."""
        stops = np.log2(np.fmax(np.asarray(linear, np.float32), np.float32(FLT_MIN)))  # NaN: as black
        shaped = (stops - np.float32(LOG_RANGE[0])) * np.float32(1.0 / (LOG_RANGE[1] - LOG_RANGE[0]))
        return tetrahedral(self.cube, shaped) * np.float32(1.0 / LOG_SCALE)

    def display(self, linear: np.ndarray) -> np.ndarray:
        """Display values in [0, 1] of scene-linear RGB (..., 3)."""
        low, high = self.curve_domain
        scale = np.float32((len(self.curve) - 1) / (high - low))
        position = (np.clip(self.log_encoding(linear), low, high) - low) * scale
        lower = np.minimum(position.astype(np.intp), len(self.curve) - 2)
        fraction = position - lower
        return self.curve[lower] * (1.0 - fraction) + self.curve[lower + 1] * fraction

    def to_uint8(self, linear: np.ndarray) -> np.ndarray:
        return np.round(np.clip(self.display(linear[..., :3]), 0.0, 1.0) * 255.0).astype(np.uint8)

    def to_uint16(self, linear: np.ndarray) -> np.ndarray:
        return np.round(np.clip(self.display(linear[..., :3]), 0.0, 1.0) * 65535.0).astype(np.uint16)


def load_filmic() -> FilmicView | None:
    """The Filmic view from the first folder :func:`find_colormanagement` finds, or None."""
    folder = find_colormanagement()
    return None if folder is None else FilmicView.from_folder(folder)
