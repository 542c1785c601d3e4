"""One keypoint's denoising guides, however they are being made, and what is derived from them.

The color producer gets a keypoint's filtered albedo and normals (:mod:`hybridgen.render.denoise_guides`) from
one of three places: the guide worker's thread (:mod:`hybridgen.render.guide_worker`), a filtering thread
(the shared raster view draws on the caller's thread, the filter runs while the samples are traced), or a
filter run by whoever asks first. :class:`KeypointGuides` wraps that call, runs it once, and derives from the
guides what both adaptive sampling and the denoiser's output need - the edge strength, computed once.
"""
from __future__ import annotations

import threading
from typing import Callable

import numpy as np

from .guide_edges import edge_strength_and_texture


class KeypointGuides:
    """``make()`` gives the (albedo, normals) guides of one keypoint (float32 H x W x 3 each); :meth:`get`
    calls it once (thread-safe) and keeps the result."""

    def __init__(self, make: Callable[[], tuple[np.ndarray, np.ndarray]]) -> None:
        self._make = make
        self._lock = threading.Lock()
        self._guides: tuple[np.ndarray, np.ndarray] | None = None
        self._derived_values: tuple[np.ndarray, np.ndarray] | None = None  # (edge strength, textured pixels)

    def get(self) -> tuple[np.ndarray, np.ndarray]:
        """(albedo, normals), made on the first call."""
        with self._lock:
            if self._guides is None:
                self._guides = self._make()
            return self._guides

    def strength(self) -> np.ndarray:
        """Float32 H x W: :func:`~hybridgen.render.guide_edges.edge_strength` of the guides (computed once)."""
        return self._derived()[0]

    def textured(self) -> np.ndarray:
        """Bool H x W: :func:`~hybridgen.render.guide_edges.textured_pixels` of the guides (computed once)."""
        return self._derived()[1]

    def prepare(self) -> None:
        """Makes the guides and everything derived from them (for a thread that works ahead)."""
        self._derived()

    def _derived(self) -> tuple[np.ndarray, np.ndarray]:
        guides = self.get()
        with self._lock:
            if self._derived_values is None:
                self._derived_values = edge_strength_and_texture(*guides)
            return self._derived_values

    def edges(self) -> np.ndarray:
        """Bool H x W: the edge pixels (:func:`~hybridgen.render.guide_edges.guide_edges`: strength above 1)."""
        return self.strength() > 1.0
