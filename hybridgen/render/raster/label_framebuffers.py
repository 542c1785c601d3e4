"""The label draw's framebuffers: their colour attachments (default or packed targets), creation with the
pixel-pack buffers of PBO readback, clearing, and release. Rings of them per image shape are kept by
:mod:`.framebuffer_ring`."""
from __future__ import annotations

from typing import Any

from .framebuffer_ring import Shape
from .label_targets import LabelTargets

DEFAULT_ATTACHMENTS = [("normal_depth", 4, "f4"), ("instance", 1, "u4")]
"""(name, components, moderngl dtype) of the default label targets."""


def attachments(targets: LabelTargets | None) -> list[tuple[str, int, str]]:
    """(name, components, moderngl dtype) of each colour attachment of a label draw into ``targets``."""
    return DEFAULT_ATTACHMENTS if targets is None else targets.attachments()


def create_framebuffer(ctx: Any, readback: str, shape: Shape) -> tuple[Any, list[Any]]:
    """A framebuffer of ``shape`` (width, height, targets) and, for PBO readback, a pixel-pack buffer per
    attachment."""
    width, height, targets = shape
    formats = [(c, d) for _, c, d in attachments(targets)]
    fbo = ctx.framebuffer(color_attachments=[ctx.renderbuffer((width, height), c, dtype=d) for c, d in formats],
                          depth_attachment=ctx.depth_renderbuffer((width, height)))
    pbos = ([ctx.buffer(reserve=width * height * c * int(d[1])) for c, d in formats]
            if readback == "pbo" else [])
    return fbo, pbos

def destroy_framebuffer(resources: tuple[Any, list[Any]]) -> None:
    fbo, pbos = resources
    release_framebuffer(fbo)
    for pbo in pbos:
        pbo.release()

def clear_framebuffer(fbo: Any, targets: LabelTargets | None, depth_background: float) -> None:
    """Clear ``fbo``: everything to 0 (depth buffer to 1); packed targets' depth to ``depth_background``
    (a float clear value is undefined for integer targets: those are masked out of that clear)."""
    if targets is None:
        fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
        return
    count = len(targets.attachments())
    fbo.color_mask = [(False,) * 4] + [(True,) * 4] * (count - 1)
    fbo.clear(0.0, 0.0, 0.0, 0.0, depth=1.0)
    fbo.color_mask = [(True,) * 4] + [(False,) * 4] * (count - 1)
    fbo.clear(depth_background, 0.0, 0.0, 0.0)
    fbo.color_mask = [(True,) * 4] * count


def release_framebuffer(fbo: Any) -> None:
    """Release ``fbo`` and its attachments."""
    for attachment in (*fbo.color_attachments, fbo.depth_attachment):
        attachment.release()
    fbo.release()
