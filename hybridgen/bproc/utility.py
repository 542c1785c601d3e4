"""``bproc.utility``: paths, the frame range and keyframes (BlenderProc's Utility)."""
from __future__ import annotations

import os
import time
from types import TracebackType


from ..logs import LOGGER
from .label_id_mapping import LabelIdMapping, resolve_resource  # noqa: F401 - bproc.utility names
from .pattern import generate_random_pattern_img  # noqa: F401 - a bproc.utility name
from .session import SESSION
from .undo import UndoAfterExecution  # noqa: F401 - a bproc.utility name


def resolve_path(path: str) -> str:
    """``path`` made absolute as BlenderProc does: stripped; ``~`` is the home folder; a relative path is
    taken from the current working directory."""
    path = str(path).strip()
    if path.startswith("/"):
        return path
    if path.startswith("~"):
        return path.replace("~", os.environ.get("HOME", "~"))
    return os.path.join(os.getcwd(), path)


def num_frames() -> int:
    """How many frames ``render()`` renders: ``frame_end - frame_start``."""
    return SESSION.frame_end - SESSION.frame_start


def reset_keyframes() -> None:
    """Drop every keyframe (camera poses, keyed object and light values) and set the frame range to 0..0;
    current values stay."""
    SESSION.frame_start = SESSION.frame_end = 0
    SESSION.camera.pose.keys.clear()
    for block in [*SESSION.entities, *SESSION.materials]:
        block.clear_keyframes()


def set_keyframe_render_interval(frame_start: int | None = None, frame_end: int | None = None) -> None:
    """Set the rendered frame range (``frame_end`` exclusive, as BlenderProc counts)."""
    if frame_start is not None:
        SESSION.frame_start = int(frame_start)
    if frame_end is not None:
        SESSION.frame_end = int(frame_end)


class BlockStopWatch:
    """``with BlockStopWatch("what"):`` logs how long the block took (seconds)."""

    def __init__(self, block_name: str) -> None:
        self.block_name = block_name
        self.start = 0.0

    def __enter__(self) -> "BlockStopWatch":
        LOGGER.info("#### Start - %s ####", self.block_name)
        self.start = time.perf_counter()
        return self

    def __exit__(self, kind: type[BaseException] | None, value: BaseException | None,
                 traceback: TracebackType | None) -> None:
        LOGGER.info("#### Finished - %s (took %.3f seconds) ####", self.block_name, time.perf_counter() - self.start)

