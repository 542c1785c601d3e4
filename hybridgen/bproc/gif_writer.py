"""``bproc.writer.write_gif_animation``: BlenderProc 2.8's GIF animation per key of render()'s data dict, for a
quick look at the frames.

Where, as BlenderProc writes them: ``<output_dir_path>/gif_animations/<n>_<key>_animation.gif``, one per image key
(keys whose first value is not text and not one-dimensional: ``instance_attribute_maps`` and such are skipped);
a stereo value (first axis 2) makes ``<n>_<key>_L_animation.gif`` and ``..._R_...``. ``n`` is 0, or with
``append_to_existing_output`` one more than the highest ``n`` of that key already there. Each frame is what
BlenderProc's viewer draws for the key (:mod:`hybridgen.bproc.gif_frames`), shown ``frame_duration_in_ms`` ms,
looping forever, in reverse order with ``reverse_animation``. The GIF is encoded by Pillow from the RGBA frames,
as BlenderProc has Pillow encode them; each file is written under a temporary name and renamed when complete.
"""
from __future__ import annotations

import io
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError
from .gif_frames import frame_image
from .session import SESSION

FOLDER = "gif_animations"
SUFFIX = "_animation.gif"


def image_keys(output_data_dict: dict[str, Any]) -> list[str]:
    """The keys BlenderProc animates: a non-empty list whose first value is neither text nor one-dimensional."""
    keys = []
    for key, block in output_data_dict.items():
        if len(block) == 0:
            continue
        first = np.asarray(block[0])
        if first.dtype.kind not in "SU" and first.ndim != 1:
            keys.append(key)
    return keys


def next_number(folder: Path, name: str, append: bool) -> int:
    """0, or with ``append`` one more than the highest ``<n>_<name>_animation.gif`` in ``folder``."""
    if not append:
        return 0
    ending = f"_{name}{SUFFIX}"
    numbers = [int(path.name[:-len(ending)]) for path in folder.iterdir()
               if path.name.endswith(ending) and path.name[:-len(ending)].isdigit()]
    return max(numbers, default=-1) + 1


def gif_bytes(frames: list[np.ndarray], duration_ms: int) -> bytes:
    """An endlessly looping GIF of RGBA ``frames``, each shown ``duration_ms`` ms."""
    from PIL import Image

    images = [Image.fromarray(np.ascontiguousarray(frame)) for frame in frames]
    buffer = io.BytesIO()
    images[0].save(buffer, format="GIF", append_images=images[1:], save_all=True, duration=duration_ms, loop=0)
    return buffer.getvalue()


def write_gif_animation(output_dir_path: str, output_data_dict: dict[str, list[Any]],
                        append_to_existing_output: bool = False, frame_duration_in_ms: int = 50,
                        reverse_animation: bool = False) -> None:
    """Write one GIF per image key of ``output_data_dict`` (``{key: [value per frame]}``; see the module doc)."""
    from ..io.atomic import prepare_output_dir
    from ..io.image_files import write_file

    count = max((len(block) for block in output_data_dict.values() if isinstance(block, list)), default=0)
    frames = SESSION.frame_end - SESSION.frame_start
    if count != frames:
        raise InputError(f"The amount of images stored in the output_data_dict ({count}) does not correspond with the "
                         f"amount of images specified by frame_start to frame_end ({frames}).")
    folder = prepare_output_dir(Path(output_dir_path) / FOLDER)
    animations: dict[str, list[np.ndarray]] = {}
    for key in image_keys(output_data_dict):
        values = [np.asarray(value) for value in output_data_dict[key]]
        if values[0].shape[0] == 2:  # a stereo pair (BlenderProc's test, also for an image 2 pixels high)
            for eye, side in enumerate(("L", "R")):
                animations[f"{key}_{side}"] = [frame_image(key, value[eye]) for value in values]
        else:
            animations[key] = [frame_image(key, value) for value in values]
    for name, images in animations.items():
        if reverse_animation:
            images.reverse()
        number = next_number(folder, name, append_to_existing_output)
        write_file(folder / f"{number}_{name}{SUFFIX}", gif_bytes(images, int(frame_duration_in_ms)))
