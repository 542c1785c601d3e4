"""BlenderProc-compatible output (docs/conventions.md section 4): one ``<i>.hdf5`` per keypoint, BlenderProc keys.

Per file: every image pass under its key (``colors``, ``depth``, ``distance``, ``<attr>_segmaps``, flow,
...), gzip-compressed; ``normals`` in the camera frame with **Blender axes** (x right, y up, z backwards:
OpenCV's with y and z negated) encoded ``0.5 * n + 0.5``; JSON values (``instance_attribute_maps``,
``object_records``) and ``cam_states`` (Blender-axes ``cam2world`` - BlenderProc 2's name - and
``cam2world_matrix`` - 1.x's -, ``cam_K``, ``location``, ``fov_x``/``fov_y``) as scalar byte strings,
like BlenderProc's ``WriterUtility``. BlenderProc's viewer (``blenderproc vis hdf5``) opens them.

Each file is written under a temporary name while renderers add keys to it and renamed by
:meth:`finalize`; ``append`` continues the numbering after the highest ``<i>.hdf5`` already in the folder.
"""
from __future__ import annotations

import json
import math
import re
from pathlib import Path
from typing import Any

import h5py
import numpy as np

from ..render.passes import exact
from ..scene.frames import opencv_to_blender
from .atomic import commit, discard, hdf5_temporary, prepare_output_dir, temporary_path
from .output_lock import hold_output_lock
from .frame_sink import PassLayout
from .hdf5_single import Hdf5Options


def next_index(directory: Path) -> int:
    """One past the highest ``<i>.hdf5`` in ``directory`` (0 when there is none)."""
    numbers = [int(m.group(1)) for p in directory.glob("*.hdf5") if (m := re.fullmatch(r"(\d+)\.hdf5", p.name))]
    return max(numbers, default=-1) + 1


def cam_state(K: np.ndarray, cam2world_cv: np.ndarray, width: int, height: int) -> dict[str, Any]:
    """BlenderProc's camera attributes of one keypoint (Blender camera axes)."""
    cam2world = opencv_to_blender(cam2world_cv)
    return {"cam2world": cam2world.tolist(), "cam2world_matrix": cam2world.tolist(),
            "cam_K": np.asarray(K).tolist(),
            "location": cam2world[:3, 3].tolist(),
            "fov_x": 2 * math.atan(width / (2 * K[0, 0])), "fov_y": 2 * math.atan(height / (2 * K[1, 1]))}


def encode_normals(normals: np.ndarray, cam2world_cv: np.ndarray, space: str) -> np.ndarray:
    """Unit normals (OpenCV camera or world axes) -> Blender camera axes, encoded 0.5 * n + 0.5."""
    n = np.asarray(normals, dtype=np.float32)
    if space == "world":
        n = n @ cam2world_cv[:3, :3].astype(np.float32)  # world -> OpenCV camera: R^T n, row-vector form
    blender = n * np.array([1.0, -1.0, -1.0], np.float32)
    return (0.5 * blender + 0.5).astype(np.float32)


class BlenderProcHdf5Writer:
    """A :class:`~hybridgen.io.frame_sink.FrameSink` writing BlenderProc's per-keypoint layout into ``directory``."""

    def __init__(self, directory: str | Path, options: Hdf5Options | None = None, *, append: bool = False,
                 versions: dict[str, str] | None = None, untrimmed: tuple[str, ...] = (),
                 stereo_separate_keys: bool = False, dtypes: dict[str, str] | None = None,
                 encoded: bool = False) -> None:
        """``options``: compression and level as for ``data.hdf5`` (its ``encoding`` does not apply: this layout
        stores BlenderProc's encodings). BlenderProc 1.x's writer also gives: ``versions`` - a ``<key>_version``
        dataset (a one-element byte-string array) beside each pass, ``versions[key]`` or ``versions["*"]``;
        ``untrimmed`` - keys of single-channel float passes (depth, distance) stored H x W x 3, three equal
        channels, as 1.x stores an EXR pass no ``postprocessing.TrimRedundantChannels`` trimmed;
        ``stereo_separate_keys`` - a stereo pass as ``<key>_0`` (left) and ``<key>_1`` instead of one array
        with a leading axis of 2; ``dtypes`` - keys stored as another NumPy dtype (1.x's segmap: float64).
        ``encoded``: the values are in BlenderProc's encodings already (``bproc.writer.write_hdf5``'s data dict:
        normals in Blender camera axes, 0.5 n + 0.5) and are stored as given."""
        self.encoded = encoded
        self.dtypes = {key: np.dtype(name) for key, name in (dtypes or {}).items()}
        self.versions = dict(versions or {})
        self.untrimmed = frozenset(untrimmed)
        self.stereo_separate_keys = stereo_separate_keys
        opts = options if options is not None else Hdf5Options()
        compression, compression_level = opts.compression, opts.compression_level
        self.directory = prepare_output_dir(Path(directory))
        self._unlock = hold_output_lock(self.directory)  # file numbers stay ours until finalize/abort
        self.offset = next_index(self.directory) if append else 0
        self._temps: dict[int, Path] = {}
        self.compression = None if compression == "none" else compression
        self.level = compression_level if compression == "gzip" else None
        self._layouts: dict[str, PassLayout] = {}
        self._records: dict[str, np.ndarray] = {}
        self._attributes: dict[str, Any] = {}
        self._n = 0
        self._touched: set[int] = set()

    def final_path(self, index: int) -> Path:
        return self.directory / f"{index + self.offset}.hdf5"

    def _temp(self, index: int) -> Path:
        if index not in self._temps:
            self._temps[index] = temporary_path(self.final_path(index))
        return self._temps[index]

    def begin(self, n_keypoints: int, layouts: list[PassLayout], camera_records: dict[str, np.ndarray],
              attributes: dict[str, Any]) -> None:
        self._n = max(self._n, n_keypoints)
        self._layouts.update({layout.key: layout for layout in layouts})
        self._records.update(camera_records)
        self._attributes.update(attributes)

    def write(self, index: int, values: dict[str, Any]) -> None:
        held: list[h5py.Dataset] = []  # open until the file closes (a lone close on a full disk: io/atomic.py)
        with hdf5_temporary(self._temp(index), "a" if index in self._touched else "w") as h5:
            for key, value in values.items():
                held += self._store(h5, key, value, index)
        self._touched.add(index)

    def _store(self, h5: h5py.File, key: str, value: Any, index: int) -> list[h5py.Dataset]:
        """Store ``key`` of keypoint ``index``; returns the datasets made."""
        layout = self._layouts.get(key)
        if layout is not None and layout.dtype == "json":
            return [h5.create_dataset(key, data=np.bytes_(json.dumps(value))), *self._store_version(h5, key)]
        array = np.asarray(value)
        entry = exact(key)
        renamed_normals = entry is None and layout is not None and layout.frame in ("camera", "world")
        if not self.encoded and (renamed_normals or (entry is not None and entry.blenderproc == "blender_half_unit")):
            cam2world = self._records["cam2world"][index]
            frame = layout.frame if layout is not None and layout.frame else "camera"
            array = encode_normals(array, cam2world, frame)
        if key in self.dtypes:
            array = array.astype(self.dtypes[key])
        stereo = layout is not None and layout.stereo
        if key in self.untrimmed and array.ndim == (3 if stereo else 2) and array.dtype.kind == "f":
            array = np.repeat(array[..., None], 3, axis=-1)
        if stereo and self.stereo_separate_keys:
            made = [h5.create_dataset(f"{key}_{side}", data=array[side], compression=self.compression,
                                      compression_opts=self.level) for side in (0, 1)]
        else:
            made = [h5.create_dataset(key, data=array, compression=self.compression, compression_opts=self.level)]
        return made + self._store_version(h5, key)

    def _store_version(self, h5: h5py.File, key: str) -> list[h5py.Dataset]:
        version = self.versions.get(key, self.versions.get("*"))
        if version is not None and f"{key}_version" not in h5:
            return [h5.create_dataset(f"{key}_version", data=np.array([version.encode()], dtype=np.bytes_))]
        return []

    def end(self) -> None:
        """Nothing is buffered between keypoints."""

    def finalize(self, records: dict[str, Any] | None = None, attributes: dict[str, Any] | None = None
                 ) -> list[Path]:
        """Add ``cam_states``, the JSON ``records`` (e.g. ``object_states``) and the run's ``attributes``
        (seed, resolved config, ...) to every keypoint's file and rename them all to ``<i>.hdf5``."""
        paths = []
        K, cam2world = self._records.get("cam_K"), self._records.get("cam2world")
        for index in sorted(self._touched):
            held: list[h5py.Dataset] = []  # open until the file closes (see write)
            with hdf5_temporary(self._temp(index), "a") as h5:
                if K is not None and cam2world is not None:
                    height, width = next((layout.image_size for layout in self._layouts.values()
                                          if layout.image_size is not None), (0, 0))
                    state = cam_state(K[index], cam2world[index], width, height)
                    held.append(h5.create_dataset("cam_states", data=np.bytes_(json.dumps(state))))
                for key, value in (records or {}).items():
                    held.append(h5.create_dataset(key, data=np.bytes_(json.dumps(value))))
                for key, value in {**self._attributes, **(attributes or {})}.items():
                    h5.attrs[key] = value
                held.append(h5.create_dataset("hybridgen_version",
                                              data=np.bytes_(str(self._attributes.get("hybridgen_version", "")))))
            commit(self._temps.pop(index), self.final_path(index))
            paths.append(self.final_path(index))
        self._touched.clear()
        self._unlock()
        return paths

    def abort(self) -> None:
        """Delete every temporary file; no ``<i>.hdf5`` of this run appears."""
        for temp in self._temps.values():
            discard(temp)
        self._temps.clear()
        self._touched.clear()
        self._unlock()
