"""The color benchmarks' converged references: each engine's own estimator at a fixed spp, without denoising,
found in tools/reference_cache.py's on-disk cache when their key matches, else rendered and stored.

Images are 8-bit sRGB (H x W x 3 uint8); ``seconds`` in a record is the wall time the render took.
"""
from __future__ import annotations

import time
from importlib.metadata import version
from pathlib import Path
from typing import Any

import numpy as np
from color_lobes import LOBES
from color_quality import build
from cycles_export import export_for_cycles
from cycles_worker import CyclesSession, bpy_version
from image_scores import read_png
from reference_cache import ReferenceCache, code_digest, estimator_digest, scene_digest

REPO = Path(__file__).resolve().parents[1]
REFERENCE_SEED = 12345
"""Seed of both engines' references (the measured renders use seed 1)."""
SECOND_SEED = 54321
"""Seed of hybridgen's second, independent reference (tools/reference_noise.py, tools/color_regions.py)."""
CLAMP = 10.0
"""hybridgen's default indirect clamp, the value its reference is rendered with (and 0 for the clamp bias)."""


def hybridgen_reference(scene: Any, spp: int, clamp: float, lobes: dict[str, int] | None = None,
                        seed: int = REFERENCE_SEED) -> tuple[np.ndarray, float]:
    """hybridgen's own estimator at a fixed ``spp`` (no adaptivity, no denoising) with indirect clamp ``clamp``
    (0: off) and per-lobe bounces ``lobes`` (default: hybridgen's): the sRGB frame and its wall seconds, in
    this process."""
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView
    from hybridgen.render.tonemap import to_srgb8

    start = time.perf_counter()
    view = PathTraceView(scene, PathTraceSettings(samples=spp, clamp_indirect=clamp, **(lobes or {})))
    image = view.render(scene.camera.keypoints[0], seed=seed)
    return to_srgb8(image), time.perf_counter() - start


def scene_and_content(name: str, width: int, height: int, workdir: Path,
                      threads: int | None = None) -> tuple[Any, Path, str]:
    """Scene ``name`` of tools/color_quality.py at ``width`` x ``height`` px, its export for Cycles
    (``workdir/<name>.npz``: BlenderProc's 1024 spp and 3 bounces, ``threads`` render threads) and the export's
    content digest, which keys both engines' references."""
    scene = build(name, width, height, workdir)
    npz = workdir / f"{name}.npz"
    export_for_cycles(scene, npz, 1024, 3, 0, threads=threads)
    return scene, npz, scene_digest(npz)


class References:
    """Both engines' ``spp`` references of the scenes at ``resolution`` from the :class:`ReferenceCache`, or
    rendered and stored (keys: tools/reference_cache.py)."""

    def __init__(self, cache: ReferenceCache, spp: int, resolution: str, lobes: str, bpy_python: Path | None,
                 workdir: Path) -> None:
        self.cache, self.spp, self.resolution, self.lobes, self.workdir = cache, spp, resolution, lobes, workdir
        self.hybridgen_code = {"estimator": estimator_digest(), "mitsuba": version("mitsuba"),
                               "drjit": version("drjit")}
        self.cycles_code = {"bpy": bpy_version(bpy_python) if bpy_python else None,
                            "cycles_render": code_digest(REPO / "tools" / "cycles_render.py")}

    def _key(self, name: str, content: str) -> dict[str, Any]:
        return {"scene": name, "resolution": self.resolution, "spp": self.spp, "seed": REFERENCE_SEED,
                "content": content}

    def hybridgen(self, name: str, scene: Any, content: str, clamp: float,
                  seed: int = REFERENCE_SEED) -> tuple[np.ndarray, dict[str, Any]]:
        """hybridgen's reference with indirect clamp ``clamp`` at ``seed`` (and the record: seconds, cached)."""
        key = {**self._key(name, content), "seed": seed, "clamp_indirect": clamp, "lobes": self.lobes,
               **self.hybridgen_code}

        def render() -> tuple[np.ndarray, dict[str, Any]]:
            image, seconds = hybridgen_reference(scene, self.spp, clamp, LOBES[self.lobes], seed)
            return image, {"seconds": seconds}

        return self.cache.fetch("hybridgen", key, render)

    def hybridgen_pair(self, name: str, scene: Any, content: str) -> tuple[np.ndarray, np.ndarray]:
        """hybridgen's reference at the default clamp and a second, independent one (:data:`SECOND_SEED`)."""
        return (self.hybridgen(name, scene, content, CLAMP)[0],
                self.hybridgen(name, scene, content, CLAMP, seed=SECOND_SEED)[0])

    def cycles(self, name: str, content: str, session: CyclesSession) -> tuple[np.ndarray, dict[str, Any]]:
        """Cycles' reference (BlenderProc's estimator at a fixed spp, ``mode: reference``) and its record."""
        key = {**self._key(name, content), "mode": "reference", "light_tree": False, **self.cycles_code}

        def render() -> tuple[np.ndarray, dict[str, Any]]:
            png = self.workdir / f"{name}_cycles_ref.png"
            answer = session.render(REFERENCE_SEED, png, mode="reference", spp=self.spp)
            return read_png(png), {"seconds": answer["seconds"], "cpu_s": answer["cpu_s"],
                                   "blender": session.worker.hello["blender"]}

        return self.cache.fetch("cycles", key, render)
