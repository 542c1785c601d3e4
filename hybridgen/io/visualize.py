"""Contact sheets of HDF5 outputs (``hybridgen vis``): one PNG per keypoint with every image key side by side.

Reads every layout through :class:`~hybridgen.data.KeypointDataset` (``data.hdf5``, a sharded index,
BlenderProc ``<i>.hdf5`` files); stereo pairs get a left and a right tile per key. Tiles are the previews
of :mod:`hybridgen.io.preview` (viridis depth with its scale in metres, segmentation with a legend naming
each id, optical flow in the Middlebury color wheel) with their legend drawn below the image.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any, Iterable, Sequence

from PIL import Image, ImageDraw

from ..errors import InputError
from ..render.passes import recognise
from .colormaps import flow_to_color, viridis
from .preview import Legend, eye_visible, eyes, is_image, preview

_LABEL_HEIGHT = 14
_ROW = 12
_MAX_ENTRIES = 12
_MIN_WIDTH = 200  # small images are enlarged (nearest neighbour, whole factors) so that legends stay legible


def _scale_bar(legend: Legend, width: int) -> Image.Image:
    import numpy as np

    bar = Image.new("RGB", (width, 18))
    ramp = np.linspace(0, 1, width)
    if legend.unit == "px":  # flow: saturation grows with magnitude (rightward flow, 0..max)
        colors = flow_to_color(np.stack([ramp, np.zeros_like(ramp)], -1), max_radius=1.0)
    else:
        colors = viridis(ramp)
    bar.paste(Image.fromarray(colors[None].repeat(4, axis=0)), (0, 1))
    draw = ImageDraw.Draw(bar)
    low, high = f"{legend.low:.2f} {legend.unit}", f"{legend.high:.2f} {legend.unit}"
    draw.text((2, 6), low, fill=(255, 255, 255))
    draw.text((max(2, width - 6 * len(high) - 2), 6), high, fill=(255, 255, 255))
    return bar


def _id_rows(legend: Legend, width: int) -> Image.Image:
    shown = legend.entries[:_MAX_ENTRIES]
    extra = len(legend.entries) - len(shown)
    rows = Image.new("RGB", (width, _ROW * (len(shown) + (1 if extra else 0)) + 2))
    draw = ImageDraw.Draw(rows)
    for i, (value, rgb, label) in enumerate(shown):
        y = 1 + i * _ROW
        draw.rectangle((2, y + 1, 11, y + 10), fill=rgb, outline=(200, 200, 200))
        draw.text((15, y), f"{value}: {label}", fill=(230, 230, 230))
    if extra:
        draw.text((15, 1 + len(shown) * _ROW), f"... {extra} more", fill=(230, 230, 230))
    return rows


def render_tile(key: str, value: Any, visible: list[dict[str, Any]] | None = None) -> Image.Image | None:
    """The image of one eye's ``value`` of ``key`` with its legend below; None for keys that are not images."""
    if not is_image(key, value):
        return None
    shown = preview(key, value, visible)
    image = Image.fromarray(shown.image)
    factor = -(-_MIN_WIDTH // image.width)
    if factor > 1:
        image = image.resize((image.width * factor, image.height * factor), Image.Resampling.NEAREST)
    legend = shown.legend
    if legend is None:
        return image
    below = _id_rows(legend, image.width) if legend.entries else _scale_bar(legend, image.width)
    tile = Image.new("RGB", (image.width, image.height + below.height))
    tile.paste(image, (0, 0))
    tile.paste(below, (0, image.height))
    return tile


def contact_sheet(tiles: Sequence[tuple[str, Image.Image]], columns: int = 3) -> Image.Image:
    """Lay titled tiles out on a grid."""
    if not tiles:
        raise InputError("nothing to show: no image keys")
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


def image_keys(sample: dict[str, Any], stereo: bool) -> list[str]:
    """Keys of a sample holding images (colors first: the catalogue's rank, :mod:`hybridgen.render.passes`)."""
    keys = [k for k, v in sample.items() if any(is_image(k, eye) for _, eye in eyes(k, v, stereo))]
    return sorted(keys, key=lambda k: (_rank(k), k))


def _rank(key: str) -> int:
    entry = recognise(key)
    return entry.rank if entry is not None else 1


def keypoint_tiles(sample: dict[str, Any], keys: Sequence[str], stereo: bool) -> list[tuple[str, Image.Image]]:
    """Titled tiles of ``keys`` of one sample (two per key for stereo pairs)."""
    visible = sample.get("instance_attribute_maps")
    tiles = []
    for key in keys:
        for index, (title, value) in enumerate(eyes(key, sample[key], stereo)):
            tile = render_tile(key, value, eye_visible(visible, index, stereo))
            if tile is not None:
                tiles.append((title, tile))
    return tiles


def save_contact_sheets(files: Iterable[str | Path], out_dir: str | Path,
                        keys: Sequence[str] | None = None) -> list[Path]:
    """Write ``<out_dir>/<file stem>_<keypoint>.png`` for every keypoint of every file (``<stem>.png`` for a
    BlenderProc per-keypoint file); returns the paths."""
    from ..data import KeypointDataset
    from ..data.layouts import BlenderProcLayout

    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"--save target '{out}' exists and is not a directory")
    datasets = [(Path(f), KeypointDataset(f)) for f in files]  # every file is checked before anything is written
    plans = []
    for path, data in datasets:
        stereo = "stereo_baseline" in data.attributes
        available = image_keys(data[0], stereo) if len(data) else []
        chosen = list(keys) if keys else available
        missing = [k for k in chosen if k not in available]
        if missing:
            raise InputError(f"'{path}' has no image key(s) {missing}; available: {available}")
        plans.append((path, data, chosen, stereo))
    out.mkdir(parents=True, exist_ok=True)
    written: list[Path] = []
    for path, data, chosen, stereo in plans:
        per_keypoint = not path.is_dir() and isinstance(data.layout, BlenderProcLayout)
        for index, sample in enumerate(data):
            target = out / (f"{path.stem}.png" if per_keypoint else f"{path.stem}_{index:04d}.png")
            contact_sheet(keypoint_tiles(sample, chosen, stereo)).save(target)
            written.append(target)
        data.close()
    return written
