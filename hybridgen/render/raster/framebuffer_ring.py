"""The raster view's framebuffers: a ring of them per image shape, taken in turn by the keypoints in flight.

Why a ring of three for a two-deep pipeline (Mesa llvmpipe, measured 2026-11-24): reading a render target
back (``glReadPixels``) first asks whether a scene of the context still references it; if one does, the read
flushes the scene being drawn and waits for *every* queued scene. llvmpipe drops a finished scene's references
only lazily, when it takes that scene object for a new scene (the first finished one in its list). With two
framebuffers in turn, keypoint k was read while keypoint k+1 was being drawn or rasterized, so every readback
waited for the next keypoint too: the drawing thread's binning and llvmpipe's rasterizer threads never
overlapped. :class:`~hybridgen.render.raster.raster_view.RasterView` therefore fences every keypoint and, when it collects
keypoint k while another is in flight, waits for k's fence alone and then begins the scene of the keypoint
after next by clearing its framebuffer - the third of the ring (:meth:`FramebufferRing.upcoming`). llvmpipe
takes k's finished scene object for it, so the read of k waits for nothing, while keypoint k+1 rasterizes.
The values are the same either way (the order of the draws into each framebuffer does not change).
"""
from __future__ import annotations

from typing import Any, Callable, Hashable

Shape = tuple[int, int, Any]
"""(width, height, label targets or None) of a framebuffer."""
Key = tuple[int, int, Any, int]
"""A shape and the framebuffer's place in that shape's ring."""

RECENT_SHAPES = 3
"""Framebuffers of this many most recently used shapes are kept (labels, an amodal canvas, supersampled guides)."""


class FramebufferRing:
    """Framebuffers (with whatever ``create`` makes along: pixel-pack buffers) bound to caller slots.

    ``create(shape)`` makes the resources of one framebuffer, ``destroy(resources)`` frees them. A slot is bound
    by :meth:`bind` and freed by :meth:`unbind`; a bound framebuffer is never handed out again meanwhile.
    """

    def __init__(self, create: Callable[[Shape], Any], destroy: Callable[[Any], None]) -> None:
        self._create, self._destroy = create, destroy
        self._resources: dict[Key, Any] = {}
        self._bound: dict[Hashable, Key] = {}
        self._recent: list[Shape] = []  # least recently bound first
        self._upcoming: dict[Shape, Key] = {}

    def resources(self, key: Key) -> Any:
        return self._resources[key]

    def key(self, slot: Hashable) -> Key:
        """The framebuffer bound to ``slot``."""
        return self._bound[slot]

    def bind(self, slot: Hashable, shape: Shape) -> Key:
        """Bind a free framebuffer of ``shape`` to ``slot`` (the one :meth:`upcoming` chose, if free): its key.
        A slot still bound is freed first."""
        self._bound.pop(slot, None)
        key = self._upcoming.pop(shape, None)
        if key is None or key in self._bound.values():
            key = self._free(shape)
        self._bound[slot] = key
        if shape in self._recent:
            self._recent.remove(shape)
        self._recent.append(shape)
        self._forget_old_shapes()
        return key

    def upcoming(self, shape: Shape) -> Key:
        """The framebuffer of ``shape`` that the next :meth:`bind` of that shape will take (made now if needed)."""
        self._upcoming[shape] = self._free(shape)
        return self._upcoming[shape]

    def unbind(self, slot: Hashable) -> Key:
        return self._bound.pop(slot)

    def in_flight(self) -> int:
        """How many slots are bound."""
        return len(self._bound)

    def release(self) -> None:
        """Free every framebuffer."""
        for resources in self._resources.values():
            self._destroy(resources)
        self._resources.clear()
        self._bound.clear()
        self._recent.clear()
        self._upcoming.clear()

    def _free(self, shape: Shape) -> Key:
        """The first framebuffer of ``shape`` bound to no slot, made if there is none."""
        taken = set(self._bound.values())
        place = 0
        while (*shape, place) in taken:
            place += 1
        key: Key = (*shape, place)
        if key not in self._resources:
            self._resources[key] = self._create(shape)
        return key

    def _forget_old_shapes(self) -> None:
        """Free the unbound framebuffers of shapes older than the :data:`RECENT_SHAPES` most recent ones."""
        keep = set(self._recent[-RECENT_SHAPES:])
        taken = set(self._bound.values())
        for key in [k for k in self._resources if k[:3] not in keep and k not in taken]:
            self._destroy(self._resources.pop(key))
            if self._upcoming.get(key[:3]) == key:
                del self._upcoming[key[:3]]
        self._recent = [shape for shape in self._recent
                        if shape in keep or any(k[:3] == shape for k in self._resources)]
