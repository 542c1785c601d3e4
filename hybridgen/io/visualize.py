"""Contact sheets of HDF5 outputs: one PNG per keypoint with every image-like key side by side.

Depth and distance get a colormap with a legend (metres, background black), normals are shown as
``(n + 1) / 2`` RGB, segmentation maps get one distinct color per value (0 black), optical flow as HSV
(hue: direction, saturation: magnitude), colors as stored.
"""
from __future__ import annotations

from pathlib import Path
from typing import Iterable, Sequence

import h5py
import numpy as np
from PIL import Image, ImageDraw

from ..errors import InputError

_LABEL_HEIGHT = 14
_LEGEND_HEIGHT = 16


def _colormap(t: np.ndarray) -> np.ndarray:
    """A perceptual blue-green-yellow ramp for t in [0, 1] (viridis-like anchor points), uint8 RGB."""
    anchors = np.array([[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], float)
    x = np.clip(t, 0, 1) * (len(anchors) - 1)
    lo = np.floor(x).astype(int).clip(0, len(anchors) - 2)
    frac = (x - lo)[..., None]
    return (anchors[lo] * (1 - frac) + anchors[lo + 1] * frac).astype(np.uint8)


def _segmentation_colors(ids: np.ndarray) -> np.ndarray:
    """Distinct, stable color per integer id (golden-ratio hues); 0 is black."""
    values = ids.astype(np.int64)
    hue = (values * 0.618033988749895) % 1.0
    h6 = hue * 6
    c = np.stack([np.abs(h6 - 3) - 1, 2 - np.abs(h6 - 2), 2 - np.abs(h6 - 4)], -1).clip(0, 1)
    rgb = (0.25 + 0.7 * c) * 255
    rgb[values == 0] = 0
    return rgb.astype(np.uint8)


def _metric_tile(values: np.ndarray, unit: str) -> Image.Image:
    finite = np.isfinite(values)
    lo, hi = (float(values[finite].min()), float(values[finite].max())) if finite.any() else (0.0, 1.0)
    scaled = (values - lo) / (hi - lo if hi > lo else 1.0)
    rgb = _colormap(np.where(finite, scaled, 0))
    rgb[~finite] = 0
    height, width = values.shape
    tile = Image.new("RGB", (width, height + _LEGEND_HEIGHT))
    tile.paste(Image.fromarray(rgb), (0, 0))
    bar = _colormap(np.linspace(0, 1, width))[None].repeat(4, axis=0)
    tile.paste(Image.fromarray(bar), (0, height + 1))
    draw = ImageDraw.Draw(tile)
    draw.text((2, height + 5), f"{lo:.2f} {unit}", fill=(255, 255, 255))
    label = f"{hi:.2f} {unit}"
    draw.text((max(2, width - 6 * len(label) - 2), height + 5), label, fill=(255, 255, 255))
    return tile


def flow_colors(flow: np.ndarray) -> np.ndarray:
    """Optical flow (H, W, 2) as colors: hue = direction, saturation = magnitude relative to the largest."""
    magnitude = np.linalg.norm(flow, axis=-1)
    hue = (np.arctan2(flow[..., 1], flow[..., 0]) / (2 * np.pi)) % 1.0
    saturation = magnitude / max(float(magnitude.max()), 1e-9)
    hsv = np.stack([hue * 255, saturation * 255, np.full_like(hue, 255)], axis=-1).astype(np.uint8)
    return np.asarray(Image.fromarray(hsv, mode="HSV").convert("RGB"))


def render_tile(key: str, value: np.ndarray) -> Image.Image | None:
    """An image of one keypoint's ``value`` of ``key``; None for keys that are not images."""
    if value.ndim == 3 and value.shape[-1] == 2 and np.issubdtype(value.dtype, np.floating):
        return Image.fromarray(flow_colors(value))
    if value.ndim == 3 and value.shape[-1] in (3, 4) and value.dtype == np.uint8:
        return Image.fromarray(value[..., :3])
    if key.startswith("normals") and value.ndim == 3:
        return Image.fromarray(((value[..., :3] + 1) * 127.5).clip(0, 255).astype(np.uint8))
    if value.ndim == 3 and value.shape[-1] == 3 and np.issubdtype(value.dtype, np.floating):
        return Image.fromarray((np.clip(value, 0, 1) ** (1 / 2.2) * 255).astype(np.uint8))
    if value.ndim == 2 and np.issubdtype(value.dtype, np.integer):
        return Image.fromarray(_segmentation_colors(value))
    if value.ndim == 2 and np.issubdtype(value.dtype, np.floating):
        return _metric_tile(value, "m")
    return None


def contact_sheet(tiles: Sequence[tuple[str, Image.Image]], columns: int = 3) -> Image.Image:
    """Lay titled tiles out on a grid."""
    width = max(t.width for _, t in tiles)
    height = max(t.height for _, t in tiles) + _LABEL_HEIGHT
    rows = (len(tiles) + columns - 1) // columns
    cols = min(columns, len(tiles))
    sheet = Image.new("RGB", (cols * width, rows * height), (32, 32, 32))
    draw = ImageDraw.Draw(sheet)
    for i, (title, tile) in enumerate(tiles):
        x, y = (i % columns) * width, (i // columns) * height
        draw.text((x + 3, y + 1), title, fill=(230, 230, 230))
        sheet.paste(tile, (x, y + _LABEL_HEIGHT))
    return sheet


def image_keys(h5: h5py.File) -> list[str]:
    """Keys of ``h5`` holding per-keypoint images (N, H, W[, C])."""
    keys = [k for k in h5 if isinstance(h5[k], h5py.Dataset) and h5[k].ndim >= 3 and not k.startswith("cam")]
    return sorted(keys, key=lambda k: (not k.startswith("colors"), k))


def save_contact_sheets(files: Iterable[str | Path], out_dir: str | Path,
                        keys: Sequence[str] | None = None) -> list[Path]:
    """Write ``<out_dir>/<file stem>_<keypoint>.png`` for every keypoint of every file; returns the paths."""
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"--save target '{out}' exists and is not a directory")
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for file in files:
        path = Path(file)
        try:
            h5 = h5py.File(path, "r")
        except OSError as exc:
            raise InputError(f"cannot open '{path}' as HDF5: {exc}") from None
        with h5:
            available = image_keys(h5)
            chosen = list(keys) if keys else available
            missing = [k for k in chosen if k not in available]
            if missing:
                raise InputError(f"'{path}' has no image key(s) {missing}; available: {available}")
            count = h5[chosen[0]].shape[0] if chosen else 0
            for index in range(count):
                tiles = [(k, t) for k in chosen if (t := render_tile(k, h5[k][index])) is not None]
                target = out / f"{path.stem}_{index:04d}.png"
                contact_sheet(tiles).save(target)
                written.append(target)
    return written
