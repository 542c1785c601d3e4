"""``bproc.writer``: BlenderProc's output files from the data dict ``render()`` returns.

``write_hdf5`` writes one ``<output_dir>/<i>.hdf5`` per frame (``i`` = frame, or continuing after the highest
number already there with ``append_to_existing_output``), each key's value of that frame as a dataset: arrays
as they are (gzip-compressed, as hybridgen's BlenderProc-layout writer stores them), anything else (dicts,
lists, numbers) as a JSON byte string, as BlenderProc does (plus hybridgen's ``hybridgen_version``). The files are
written and renamed by :class:`hybridgen.io.hdf5_blenderproc.BlenderProcHdf5Writer`, so a file exists under
its final name only when it is complete.
"""
from __future__ import annotations

from typing import Any

import numpy as np

from .._version import __version__
from ..errors import InputError
from .session import SESSION
from .types.unsupported import module_getattr

def _json_ready(value: Any) -> Any:
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, (np.integer, np.floating, np.bool_)):
        return value.item()
    if isinstance(value, dict):
        return {str(k): _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    return value


def _frame_entries(output_data_dict: dict[str, Any], index: int, stereo_separate_keys: bool) -> dict[str, Any]:
    """The datasets of frame ``index``: each key's value, or with ``stereo_separate_keys`` a stereo value as
    ``<key>_0`` (left) and ``<key>_1`` (right) - every key when stereo rendering is on, else an array whose first
    axis has 2 entries (BlenderProc's test, which also splits such an array of a mono render)."""
    entries: dict[str, Any] = {}
    for key, block in output_data_dict.items():
        value = block[index]
        pair = isinstance(value, np.ndarray) and value.ndim > 0 and value.shape[0] == 2
        if stereo_separate_keys and (SESSION.camera.stereo or pair):
            entries[f"{key}_0"], entries[f"{key}_1"] = value[0], value[1]
        else:
            entries[key] = value
    return entries


def write_hdf5(output_dir_path: str, output_data_dict: dict[str, Any], append_to_existing_output: bool = False,
               stereo_separate_keys: bool = False) -> None:
    """Write ``output_data_dict`` (``{key: [value per frame]}``) as BlenderProc's per-frame HDF5 files
    (``stereo_separate_keys``: :func:`_frame_entries`)."""
    from ..io.frame_sink import PassLayout
    from ..io.hdf5_blenderproc import BlenderProcHdf5Writer

    count = max((len(v) for v in output_data_dict.values() if isinstance(v, list)), default=0)
    frames = SESSION.frame_end - SESSION.frame_start
    if count != frames:
        raise InputError(f"The amount of images stored in the output_data_dict ({count}) does not correspond with "
                         f"the amount of images specified by frame_start to frame_end ({frames}).")
    for key, block in output_data_dict.items():
        if len(block) < count:
            raise InputError(f"There are more frames {count} then there are blocks of information {len(block)} in "
                             f"the given list for key {key}.")
    frames = [_frame_entries(output_data_dict, index, stereo_separate_keys) for index in range(count)]
    json_keys = {key for key, value in (frames[0].items() if frames else ()) if not isinstance(value, np.ndarray)}
    writer = BlenderProcHdf5Writer(output_dir_path, append=append_to_existing_output, encoded=True)
    writer.offset += SESSION.frame_start
    try:
        writer.begin(count, [PassLayout(key, "json", ()) for key in json_keys], {}, {"hybridgen_version": __version__})
        for index, entries in enumerate(frames):
            writer.write(index, {key: _json_ready(value) if key in json_keys else np.asarray(value)
                                 for key, value in entries.items()})
        writer.finalize()
    except BaseException:
        writer.abort()
        raise


# the file writers (BOP, COCO, GIF: ~25 ms of imports) are imported when first used
__getattr__ = module_getattr("writer", [], lazy={"write_bop": "bop_writer", "write_coco_annotations": "coco_writer",
                                                 "write_gif_animation": "gif_writer"}, namespace=globals())
