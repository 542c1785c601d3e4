"""The light paths the color benchmarks render hybridgen with (``--lobes``): named PathTraceSettings keywords.

Imports nothing, so that tools/default_color_process.py can read it before its timed ``import hybridgen``.
"""
from __future__ import annotations

from typing import Any

LOBES: dict[str, dict[str, int | bool]] = {
    "default": {}, "blenderproc": {"glossy_bounces": 0, "transmission_bounces": 0},
    "no-refractive-caustics": {"caustics_refractive": False}}
"""``--lobes``: hybridgen's default light paths; BlenderProc's (glossy and transmission bounces 0: the light
paths Cycles renders at BlenderProc's defaults); or hybridgen's without refraction after a diffuse bounce
(``caustics_refractive: false``)."""


def lobes_name(args: Any) -> str:
    """The name of the :data:`LOBES` entry a benchmark renders hybridgen with: ``args.lobes``, or
    ``blenderproc`` for ``args.blenderproc_lobes``."""
    return args.lobes if args.lobes else ("blenderproc" if args.blenderproc_lobes else "default")
