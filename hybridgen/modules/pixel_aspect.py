"""``camera.PixelAspect``: render with non-square pixels, as Blender's ``render.pixel_aspect_x / _y`` settings do."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param
from ..run.context import RunContext
from .base import Module, Role


def _positive(value: float) -> str | None:
    return None if value > 0 else "must be positive"


@register_module("camera.PixelAspect")
class PixelAspect(Module):
    """Gives the camera Blender's pixel aspect ``pixel_aspect_x : pixel_aspect_y`` from here on (every keypoint's
    intrinsics; the lens and sensor kept, sensor fit AUTO: ``fy = fx x pixel_aspect_x / pixel_aspect_y``, see
    :meth:`hybridgen.scene.camera.Intrinsics.with_pixel_aspect`). BlenderProc 1.0 configs get it from the
    renderers' ``pixel_aspect_x`` (``global.renderer``), which Blender applies when they render."""

    role = Role.MANIPULATOR

    params = (
        Param("pixel_aspect_x", "float", 1.0, doc="Blender's render.pixel_aspect_x (relative width of a pixel)",
              check=_positive),
        Param("pixel_aspect_y", "float", 1.0, doc="Blender's render.pixel_aspect_y (relative height of a pixel)",
              check=_positive),
    )

    def run(self, context: RunContext) -> None:
        camera = context.scene.camera
        aspect = (self.config["pixel_aspect_x"], self.config["pixel_aspect_y"])
        camera.intrinsics = camera.intrinsics.with_pixel_aspect(*aspect)
        if camera.intrinsics_per_keypoint is not None:
            camera.intrinsics_per_keypoint = [i.with_pixel_aspect(*aspect) for i in camera.intrinsics_per_keypoint]
