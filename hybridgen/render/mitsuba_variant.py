"""Choosing the Mitsuba 3 variant: ``cuda_ad_rgb`` on a working CUDA device, else ``llvm_ad_rgb`` when
Dr.Jit finds a usable libLLVM, else ``scalar_rgb``.

A JIT variant is only chosen after a probe **in a child process** rendered a tiny scene with it: with an
unsuitable LLVM (e.g. 15 or 16) Dr.Jit aborts the whole process at the first kernel, which no ``try`` can
catch. The choice can be forced with the ``HYBRIDGEN_MITSUBA_VARIANT`` environment variable or the
renderer's ``variant`` option.
"""
from __future__ import annotations

import os
import subprocess
import sys
from functools import lru_cache

from ..errors import SystemSetupError

AUTO_ORDER = ("cuda_ad_rgb", "llvm_ad_rgb", "scalar_rgb")
ENV_VARIABLE = "HYBRIDGEN_MITSUBA_VARIANT"

_PROBE = """
import sys
import mitsuba as mi
mi.set_variant(sys.argv[1])
scene = mi.load_dict({"type": "scene", "integrator": {"type": "path", "max_depth": 3},
    "sensor": {"type": "perspective", "film": {"type": "hdrfilm", "width": 4, "height": 4}},
    "light": {"type": "constant"},
    "ball": {"type": "sphere", "center": [0, 0, 3], "bsdf": {"type": "principled"}}})
image = mi.render(scene, spp=2)
value = float(mi.TensorXf(image).numpy().max())
print("ok" if value == value else "nan")
"""


@lru_cache(maxsize=None)
def variant_works(variant: str, timeout: float = 180.0) -> bool:
    """True if a child process can render with ``variant`` (cached per process)."""
    try:
        done = subprocess.run([sys.executable, "-c", _PROBE, variant], capture_output=True, text=True,
                              timeout=timeout)
    except (subprocess.TimeoutExpired, OSError):
        return False
    return done.returncode == 0 and done.stdout.strip().endswith("ok")


def available_variants() -> list[str]:
    """Variants compiled into the installed Mitsuba."""
    import mitsuba as mi

    return list(mi.variants())


def choose_variant(requested: str | None = None) -> str:
    """The variant to use: ``requested`` / ``$HYBRIDGEN_MITSUBA_VARIANT`` if given (not 'auto'), else the first
    working one of :data:`AUTO_ORDER`."""
    wanted = requested if requested not in (None, "", "auto") else os.environ.get(ENV_VARIABLE, "auto")
    compiled = available_variants()
    if wanted and wanted != "auto":
        if wanted not in compiled:
            raise SystemSetupError(f"Mitsuba variant {wanted!r} is not available; this Mitsuba has {compiled}")
        if wanted != "scalar_rgb" and not variant_works(wanted):
            raise SystemSetupError(f"Mitsuba variant {wanted!r} does not run here (for llvm_ad_rgb install "
                                   "libLLVM >= 17, e.g. `apt-get install libllvm19`; for cuda_ad_rgb a CUDA driver)")
        return wanted
    for variant in AUTO_ORDER:
        if variant in compiled and (variant == "scalar_rgb" or variant_works(variant)):
            return variant
    raise SystemSetupError(f"no usable Mitsuba variant among {compiled}")


def activate(variant: str) -> None:
    """Make ``variant`` the current Mitsuba variant of this process, with the threads it was given."""
    import mitsuba as mi

    if mi.variant() != variant:
        mi.set_variant(variant)
    apply_thread_limit()


def apply_thread_limit() -> None:
    """Dr.Jit uses the threads :func:`hybridgen.run.unit_task.limit_threads` gave this process
    (``$HYBRIDGEN_THREADS``). Called when Mitsuba is put to work, so a labels-only run never imports it."""
    threads = os.environ.get("HYBRIDGEN_THREADS", "")
    if threads.isdigit():
        import drjit

        if drjit.thread_count() != int(threads):
            drjit.set_thread_count(int(threads))


def is_jit(variant: str) -> bool:
    """True for the Dr.Jit variants (cuda_*, llvm_*), which trace kernels and vectorise over samples."""
    return variant.startswith(("cuda_", "llvm_"))
