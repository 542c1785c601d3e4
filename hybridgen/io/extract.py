"""``hybridgen extract``: every keypoint's keys of HDF5 outputs as separate image / array files.

Reads both layouts: the single file (keypoint axis first, docs/conventions.md section 4) and BlenderProc's one
``<i>.hdf5`` per keypoint. Files are named ``<file stem>_<keypoint, 4 digits>_<key>.<ext>`` (single file) or
``<file stem>_<key>.<ext>`` (per-keypoint file); stereo keys get ``_left`` / ``_right``.

``png`` (default) encodings, chosen so that values survive (each pass's ``png`` field of the catalogue,
:mod:`hybridgen.render.passes`; otherwise by dtype and shape):

- ``colors`` (uint8): 8-bit RGB as stored (sRGB); other uint8 maps (e.g. flow occlusion masks) as stored.
- ``depth``, ``distance`` (metres): 16-bit grey, value * depth_scale = millimetres (depth_scale 1.0 by
  default: 1 mm steps up to 65.535 m); no hit or too far = 0.
- ``*_segmaps`` (ids): 16-bit grey, the ids themselves (0 = background).
- ``normals``: 8-bit RGB of ``(n + 1) / 2`` (single file, n in [-1, 1]) or of the stored ``0.5 n + 0.5``
  (BlenderProc layout); ``nocs`` and other [0, 1] float images: 8-bit, clipped.
- ``colors_hdr``, ``albedo`` (linear): 8-bit sRGB (clipped to [0, 1]), like ``colors``.
- ``*_flow`` (pixels): 16-bit RGB in the KITTI flow format: (u * 64 + 2^15, v * 64 + 2^15, valid).

``exr`` writes the stored floats unchanged (depth with ``inf`` background, normals, flow as channels u, v;
ids as uint32; uint8 colors decoded to linear float) with Mitsuba's Bitmap; ``npy`` the stored arrays exactly.
JSON values (``instance_attribute_maps``, ``cam_states``...) become ``.json`` files and camera matrices
(``cam_K``, ``cam2world``) ``.json`` (or ``.npy``). Every key and file is checked before anything is written.
"""
from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, Sequence

import h5py
import numpy as np

from ..errors import InputError
from ..render.passes import RECORDS, recognise
from ..render.tonemap import to_srgb8
from ..run.shard_index import check_index_sources
from .atomic import prepare_output_dir
from .depth_png import depth_png_values
from .hdf5_filters import enable_filters
from .integrity import DIGEST_ATTR, verify
from .label_encoding import decode_dataset
from .image_files import json_bytes, npy_bytes, png_bytes, write_exr_file, write_file

FORMATS = ("png", "npy", "exr")


def _png(key: str) -> str:
    """The catalogue's PNG encoding of a stored key ('' when it has none or is no pass)."""
    entry = recognise(key)
    return entry.png if entry is not None else ""


def _one_channel(key: str) -> bool:
    """Whether a stored key is a one-channel image pass (H, W) - stereo pairs of them are (2, H, W)."""
    entry = recognise(key)
    return entry is not None and entry.channels == 0


@dataclass
class Source:
    """One HDF5 output: its keypoint count, whether it is a per-keypoint (BlenderProc) file, and its keys."""

    path: Path
    per_keypoint: bool
    count: int
    stereo: bool
    images: list[str] = field(default_factory=list)
    texts: list[str] = field(default_factory=list)
    arrays: list[str] = field(default_factory=list)

    @property
    def keys(self) -> list[str]:
        return self.images + self.texts + self.arrays


def inspect(path: Path, h5: h5py.File) -> Source:
    """Classify the datasets of an open file (see the module documentation)."""
    datasets = {k: v for k, v in h5.items() if isinstance(v, h5py.Dataset)}
    cam_K = datasets.get("cam_K")
    per_keypoint = not (cam_K is not None and cam_K.ndim == 3)
    count = 1 if per_keypoint else int(cam_K.shape[0])  # type: ignore[union-attr]
    if per_keypoint:
        stereo = any((d.ndim == 4 and d.shape[0] == 2) or (_one_channel(k) and d.ndim == 3 and d.shape[0] == 2)
                     for k, d in datasets.items())
    else:
        stereo = "stereo_baseline" in h5.attrs
    source = Source(path, per_keypoint, count, stereo)
    for key, dset in sorted(datasets.items()):
        is_text = dset.dtype.kind in ("S", "O", "U")
        per_frame = dset.shape if per_keypoint else dset.shape[1:] if dset.ndim and dset.shape[0] == count else None
        if per_frame is None or (not per_keypoint and RECORDS.get(key) == "scene"):
            continue
        if is_text:
            source.texts.append(key)
        elif len(per_frame) - (1 if stereo else 0) >= 2 and RECORDS.get(key) != "camera":
            source.images.append(key)
        elif not per_keypoint:
            source.arrays.append(key)
    return source


def _decode_text(value: Any) -> Any:
    text = value.decode("utf-8") if isinstance(value, bytes) else str(value)
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def png_image(key: str, value: np.ndarray, *, encoded_normals: bool, depth_scale: float) -> tuple[np.ndarray, int]:
    """The PNG samples of one image value and how many valid depth pixels did not fit (written as 0)."""
    if value.dtype == np.uint8:
        return value, 0
    if _png(key) == "millimetres":
        return depth_png_values(value, depth_scale)
    if np.issubdtype(value.dtype, np.integer) and value.ndim == 2:
        if value.size and (value.min() < 0 or value.max() > 65535):
            raise InputError(f"'{key}' has values outside 0..65535 that a 16-bit PNG cannot hold; use --format npy "
                             "or exr")
        return value.astype(np.uint16), 0
    if value.ndim == 3 and value.shape[2] == 2 and np.issubdtype(value.dtype, np.floating):  # optical flow
        finite = np.isfinite(value).all(axis=2)
        kitti = np.clip(np.rint(np.where(finite[..., None], value, 0.0) * 64.0 + 2 ** 15), 0, 65535)
        return np.dstack([kitti, finite]).astype(np.uint16), 0
    if value.ndim == 3 and value.shape[2] in (3, 4) and np.issubdtype(value.dtype, np.floating):
        if _png(key) == "srgb":
            return to_srgb8(value[..., :3].astype(np.float32)), 0
        unit = value if (encoded_normals or _png(key) != "half_unit") else (value + 1.0) / 2.0
        return np.rint(np.clip(np.nan_to_num(unit), 0.0, 1.0) * 255.0).astype(np.uint8), 0
    raise InputError(f"no PNG encoding for '{key}' ({value.dtype}, shape {value.shape}); use --format npy or exr")


def exr_image(key: str, value: np.ndarray) -> tuple[np.ndarray, Sequence[str] | None]:
    """Samples and channel names of one image value for an EXR file."""
    if value.dtype == np.uint8 and value.ndim == 3 and value.shape[2] in (3, 4):
        srgb = value[..., :3].astype(np.float32) / 255.0  # sRGB -> linear (IEC 61966-2-1)
        return np.where(srgb <= 0.04045, srgb / 12.92, ((srgb + 0.055) / 1.055) ** 2.4).astype(np.float32), None
    if np.issubdtype(value.dtype, np.integer):
        if value.size and value.min() < 0:
            return value.astype(np.float32), None
        return value.astype(np.uint32), None
    if value.ndim == 3 and value.shape[2] == 2:
        return value.astype(np.float32), ("u", "v")
    entry = recognise(key)
    if value.ndim == 3 and entry is not None and entry.exr_channels and value.shape[2] == len(entry.exr_channels):
        return value.astype(np.float32), entry.exr_channels
    dtype = np.float16 if value.dtype == np.float16 else np.float32
    return value.astype(dtype), None


@dataclass
class ExtractResult:
    """Files written and notes for the user (e.g. depth pixels that did not fit)."""

    files: list[Path]
    notes: list[str]


def _open(path: Path) -> h5py.File:
    if path.is_dir():
        raise InputError(f"'{path}' is a directory, not an HDF5 file")
    enable_filters()  # compression: blosc2 files
    try:
        h5 = h5py.File(path, "r")
    except FileNotFoundError:
        raise InputError(f"'{path}' does not exist") from None
    except OSError as exc:
        raise InputError(f"cannot open '{path}' as HDF5: {str(exc).splitlines()[0] if str(exc) else exc}") from None
    try:
        check_index_sources(path, h5)  # a sharded index over missing shards would read fill values
    except BaseException:
        h5.close()
        raise
    return h5


def extract(files: Sequence[str | Path], output_dir: str | Path, keys: Sequence[str] | None = None,
            fmt: str = "png", depth_scale: float = 1.0) -> ExtractResult:
    """Write every keypoint's ``keys`` (default: every image key) of ``files`` into ``output_dir``."""
    if fmt not in FORMATS:
        raise InputError(f"--format must be one of {list(FORMATS)}, got {fmt!r}")
    if not depth_scale > 0:
        raise InputError(f"--depth_scale must be > 0, got {depth_scale}")
    paths = [Path(f) for f in files]
    out = Path(output_dir)
    if out.exists() and not out.is_dir():
        raise InputError(f"output directory '{out}' exists and is not a directory")
    # Check everything first: no file is written unless every input and key is fine.
    plan: list[tuple[Source, list[str]]] = []
    for path in paths:
        with _open(path) as h5:
            source = inspect(path, h5)
            sealed = DIGEST_ATTR in h5.attrs
        problem = verify(path) if sealed else None  # a damaged chunk fails here, before any file is written
        if problem is not None:
            raise InputError(f"'{path}': {problem}")
        chosen = list(keys) if keys else source.images
        missing = [k for k in chosen if k not in source.keys]
        if missing:
            raise InputError(f"'{path}' has no key(s) {missing}; available: {source.keys}")
        if not chosen:
            raise InputError(f"'{path}' has no image keys to extract; available: {source.keys}")
        plan.append((source, chosen))
    targets: dict[Path, Path] = {}
    for source, chosen in plan:
        for name in _target_names(source, chosen, fmt):
            target = out / name
            if target in targets:
                raise InputError(f"'{source.path}' and '{targets[target]}' would both write '{target}'; extract "
                                 "them into separate folders")
            targets[target] = source.path
    prepare_output_dir(out)
    written: list[Path] = []
    too_far = 0
    for source, chosen in plan:
        with _open(source.path) as h5:
            for index in range(source.count):
                for key in chosen:
                    count, paths_written = _write_key(h5, source, index, key, out, fmt, depth_scale)
                    too_far += count
                    written += paths_written
    notes = []
    if too_far:
        notes.append(f"{too_far} depth/distance pixel(s) beyond {65535 * depth_scale:.0f} mm were written as 0 "
                     "(no depth); use a larger --depth_scale")
    return ExtractResult(written, notes)


def _stem(source: Source, index: int) -> str:
    return source.path.stem if source.per_keypoint else f"{source.path.stem}_{index:04d}"


def _extension(source: Source, key: str, fmt: str) -> str:
    if key in source.texts:
        return ".json"
    if key in source.arrays:
        return ".npy" if fmt == "npy" else ".json"
    return "." + fmt


def _target_names(source: Source, chosen: list[str], fmt: str) -> list[str]:
    names = []
    for index in range(source.count):
        for key in chosen:
            eyes = ("_left", "_right") if source.stereo and key in source.images else ("",)
            names += [f"{_stem(source, index)}_{key}{eye}{_extension(source, key, fmt)}" for eye in eyes]
    return names


def _exr_writer(samples: np.ndarray, names: Sequence[str] | None) -> Callable[[Path], None]:
    return lambda temp: write_exr_file(temp, samples, names)


def _write_key(h5: h5py.File, source: Source, index: int, key: str, out: Path, fmt: str,
               depth_scale: float) -> tuple[int, list[Path]]:
    dset = h5[key]
    value = decode_dataset(dset, () if source.per_keypoint else index)  # compact encodings: documented dtypes
    base = f"{_stem(source, index)}_{key}"
    if key in source.texts:
        text = _decode_text(value)
        return 0, [write_file(out / f"{base}.json", json_bytes(text, indent=1))]
    value = np.asarray(value)
    if key in source.arrays:
        data = npy_bytes(value) if fmt == "npy" else json_bytes(value.tolist())
        return 0, [write_file(out / f"{base}{_extension(source, key, fmt)}", data)]
    eyes = [("_left", value[0]), ("_right", value[1])] if source.stereo else [("", value)]
    written, too_far = [], 0
    for eye, image in eyes:
        target = out / f"{base}{eye}.{fmt}"
        if fmt == "npy":
            written.append(write_file(target, npy_bytes(image)))
        elif fmt == "exr":
            written.append(write_file(target, _exr_writer(*exr_image(key, image))))
        else:
            samples, count = png_image(key, image, encoded_normals=source.per_keypoint, depth_scale=depth_scale)
            too_far += count
            written.append(write_file(target, png_bytes(samples)))
    return too_far, written
