"""A small stand-in for the ``bpy`` module, for the parts of it BlenderProc's example scripts touch directly:
``bpy.data.images.load(filepath=...)`` (an image to link to a material input) and the scene camera's
``clip_start`` / ``clip_end`` (metres). Anything else under ``bpy`` raises one line naming the attribute.

``hybridgen run`` puts this module in ``sys.modules['bpy']`` for the script (never when a real ``bpy`` is
imported by something else in the process first)."""
from __future__ import annotations

import os
from dataclasses import dataclass
from typing import Any

from .types.unsupported import fail


@dataclass
class Image:
    """An image data block: its file path (what a material input links to)."""

    filepath: str

    @property
    def name(self) -> str:
        return os.path.basename(self.filepath)


class _Namespace:
    """An attribute namespace whose unknown attributes raise one line naming ``bpy.<path>.<name>``."""

    _path = "bpy"

    def __getattr__(self, name: str) -> Any:
        if name.startswith("__"):
            raise AttributeError(name)
        fail(f"{self._path}.{name}", "hybridgen's bpy stand-in has images.load and the camera's clip range only")


class _Images(_Namespace):
    _path = "bpy.data.images"

    def load(self, filepath: str, check_existing: bool = False) -> Image:
        """An image of the file ``filepath`` (it must exist, as Blender's loader requires)."""
        from ..errors import InputError

        if not os.path.isfile(filepath):
            raise InputError(f"bpy.data.images.load: cannot read '{filepath}'")
        return Image(str(filepath))


class _Data(_Namespace):
    _path = "bpy.data"

    def __init__(self) -> None:
        self.images = _Images()


class _CameraData(_Namespace):
    """``bpy.context.scene.camera.data``: the clip range of the session's camera (m)."""

    _path = "bpy.context.scene.camera.data"

    @property
    def clip_start(self) -> float:
        return self._intrinsics().clip_start

    @property
    def clip_end(self) -> float:
        return self._intrinsics().clip_end

    @staticmethod
    def _intrinsics() -> Any:
        from .session import current_intrinsics

        return current_intrinsics()


class _CameraObject(_Namespace):
    _path = "bpy.context.scene.camera"

    def __init__(self) -> None:
        self.data = _CameraData()


class _Scene(_Namespace):
    _path = "bpy.context.scene"

    def __init__(self) -> None:
        self.camera = _CameraObject()


class _Context(_Namespace):
    _path = "bpy.context"

    def __init__(self) -> None:
        self.scene = _Scene()


data = _Data()
context = _Context()


def __getattr__(name: str) -> Any:  # noqa: N807 - the module's own
    if name.startswith("__"):
        raise AttributeError(name)
    fail(f"bpy.{name}", "hybridgen's bpy stand-in has data.images.load and the camera's clip range only")
