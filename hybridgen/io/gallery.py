"""``hybridgen gallery OUT``: a static HTML page of an output folder - every keypoint's color and label passes.

Writes ``<OUT>/gallery/index.html`` with ``images/`` (full-size previews, PNG) and ``thumbs/`` (thumbnails)
beside it; every path in the page is relative, nothing is fetched from a network and no server is needed
(open the file in a browser). Previews and legends are those of :mod:`hybridgen.io.preview`: depth and
distance in viridis with their scale in metres, segmentation ids with a table naming each id (object name
and category), flow in the Middlebury color wheel with its largest magnitude. Clicking a thumbnail
enlarges it; the scene and keypoint selectors (also ``index.html#scene=1&keypoint=0``) filter the page;
``#open=000003_depth`` opens with that preview enlarged.

A script in the page records, once loaded, each image's ``naturalWidth`` in ``data-natural-width`` and a
summary in ``#image-check`` (``data-total``, ``data-loaded``, ``data-failed``), so a headless browser can
check that every image loads.
"""
from __future__ import annotations

import html
import json
from pathlib import Path
from typing import Any, Sequence

import numpy as np
from PIL import Image

from ..errors import InputError
from ..render.passes import exact
from .colormaps import flow_to_color, viridis
from .image_files import png_bytes, write_file
from .preview import Legend, eye_visible, eyes, is_image, preview
from .visualize import image_keys

THUMB_WIDTH = 192
_PAGE = Path(__file__).with_name("gallery_page.html")


def _write_png(path: Path, image: np.ndarray) -> str:
    write_file(path, png_bytes(image))
    return f"{path.parent.name}/{path.name}"


def _thumbnail(image: np.ndarray, smooth: bool) -> np.ndarray:
    height, width = image.shape[:2]
    if width <= THUMB_WIDTH:
        return image
    size = (THUMB_WIDTH, max(1, round(height * THUMB_WIDTH / width)))
    resample = Image.Resampling.BILINEAR if smooth else Image.Resampling.NEAREST  # ids stay ids
    return np.asarray(Image.fromarray(image).resize(size, resample))


def _legend_html(legend: Legend | None) -> str:
    if legend is None:
        return ""
    if legend.entries:
        rows = "".join(
            f'<tr><td><span class="swatch" style="background: rgb{rgb}"></span></td><td>{value}</td>'
            f"<td>{html.escape(label)}</td></tr>" for value, rgb, label in legend.entries)
        return (f'<table class="legend ids"><caption>{html.escape(legend.title)}</caption>'
                f"<tr><th></th><th>id</th><th>what</th></tr>{rows}</table>")
    bar = "scale_flow.png" if legend.unit == "px" else "scale_viridis.png"
    return (f'<div class="legend scale"><img class="bar" src="images/{bar}" alt="color scale">'
            f'<span class="low">{legend.low:.3f} {legend.unit}</span>'
            f'<span class="high">{legend.high:.3f} {legend.unit}</span></div>')


def _keypoint_html(sample: dict[str, Any], index: int, keys: Sequence[str], stereo: bool, folder: Path) -> str:
    scene, keypoint = sample["scene_index"], sample["keypoint_index"]
    visible = sample.get("instance_attribute_maps")
    figures = []
    for key in keys:
        for eye, (title, value) in enumerate(eyes(key, sample[key], stereo)):
            if not is_image(key, value):
                continue
            shown = preview(key, value, eye_visible(visible, eye, stereo))
            name = f"{index:06d}_{title.replace(' (', '_').rstrip(')')}.png"
            full = _write_png(folder / "images" / name, shown.image)
            entry = exact(key)
            smooth = value.dtype == np.uint8 and value.ndim == 3 or (entry is not None and entry.smooth)
            thumb = _write_png(folder / "thumbs" / name, _thumbnail(shown.image, smooth))
            figures.append(
                f'<figure class="pass" data-key="{html.escape(key)}"><figcaption>{html.escape(title)}</figcaption>'
                f'<a class="enlarge" href="{full}"><img src="{thumb}" data-full="{full}" '
                f'alt="{html.escape(title)}, scene {scene}, keypoint {keypoint}"></a>{_legend_html(shown.legend)}'
                "</figure>")
    return (f'<section class="keypoint" data-scene="{scene}" data-keypoint="{keypoint}" id="kp{index}">'
            f"<h2>scene {scene} &middot; keypoint {keypoint}</h2><div class=\"passes\">{''.join(figures)}</div>"
            "</section>")


def build_gallery(source: str | Path, out_dir: str | Path | None = None, *, keys: Sequence[str] | None = None,
                  limit: int | None = None) -> Path:
    """Write the gallery of the output at ``source`` (folder or file) into ``out_dir`` (default:
    ``<folder>/gallery``) and return the path of its ``index.html``. ``keys``: passes to show (default: all
    image keys); ``limit``: show at most this many keypoints (the first ones)."""
    from ..data import KeypointDataset

    data = KeypointDataset(source)
    if len(data) == 0:
        raise InputError(f"'{source}' has no keypoints to show")
    stereo = "stereo_baseline" in data.attributes
    first = data[0]
    available = image_keys(first, stereo)
    chosen = list(keys) if keys else available
    missing = [k for k in chosen if k not in available]
    if missing:
        raise InputError(f"'{source}' has no image key(s) {missing}; available: {available}")
    base = Path(source) if Path(source).is_dir() else Path(source).parent
    folder = Path(out_dir) if out_dir is not None else base / "gallery"
    for sub in ("images", "thumbs"):  # the gallery's own folders: previews of an earlier gallery go
        (folder / sub).mkdir(parents=True, exist_ok=True)
        for stale in (folder / sub).glob("*.png"):
            stale.unlink()
    ramp = np.linspace(0, 1, 256)
    _write_png(folder / "images/scale_viridis.png", viridis(ramp)[None].repeat(12, axis=0))
    flow = flow_to_color(np.stack([ramp, np.zeros_like(ramp)], -1), max_radius=1.0)
    _write_png(folder / "images/scale_flow.png", flow[None].repeat(12, axis=0))
    count = len(data) if limit is None else min(len(data), max(0, int(limit)))
    sections, positions = [], []
    for index in range(count):
        sample = data[index]
        positions.append((sample["scene_index"], sample["keypoint_index"]))
        sections.append(_keypoint_html(sample, index, chosen, stereo, folder))
    data.close()
    scenes = sorted({s for s, _ in positions})
    keypoints = sorted({k for _, k in positions})
    info = {k: data.attributes[k] for k in ("seed", "samples", "mitsuba_variant", "hybridgen_version")
            if k in data.attributes}
    page = _PAGE.read_text(encoding="utf-8")
    replacements = {
        "{{title}}": html.escape(f"hybridgen gallery: {source}"),
        "{{summary}}": html.escape(f"{count} of {len(data)} keypoint(s), {len(scenes)} scene(s); "
                                   + ", ".join(f"{k} {v}" for k, v in info.items())),
        "{{scene_options}}": "".join(f'<option value="{s}">{s}</option>' for s in scenes),
        "{{keypoint_options}}": "".join(f'<option value="{k}">{k}</option>' for k in keypoints),
        "{{keys_json}}": html.escape(json.dumps(chosen)),
        "{{sections}}": "\n".join(sections),
    }
    for placeholder, value in replacements.items():
        page = page.replace(placeholder, value)
    return write_file(folder / "index.html", page.encode("utf-8"))
