"""Choosing the Mitsuba 3 variant: ``cuda_ad_rgb`` on a working CUDA device, else ``llvm_ad_rgb`` when
Dr.Jit finds a usable libLLVM, else ``scalar_rgb``.

A JIT variant is only chosen after a probe **in a child process** rendered a tiny scene with it: with an
unsuitable LLVM (e.g. 15 or 16) Dr.Jit aborts the whole process at the first kernel, which no ``try`` can
catch. The choice can be forced with the ``HYBRIDGEN_MITSUBA_VARIANT`` environment variable or the
renderer's ``variant`` option.

The probe's answer is kept in hybridgen's cache folder (``mitsuba_variants.json``,
:mod:`hybridgen.io.cache_folder`; ``HYBRIDGEN_CACHE_DIR=off`` probes every time), keyed by the Python
executable, the Mitsuba and Dr.Jit versions and the version of the LLVM / CUDA library Dr.Jit loaded in
this process (loading it runs no kernel, so that much is safe in-process). A backend Dr.Jit cannot load at
all is answered in-process, without a child. The child probe costs about 0.6 s (wall) per process, a
quarter of a small frame's whole run.
"""
from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from functools import lru_cache

from ...errors import SystemSetupError
from ...io.cache_folder import cache_path
from .huge_pages import decline_huge_pages

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


PROBE_CACHE = "mitsuba_variants.json"
"""File in hybridgen's cache folder with the probes' answers, by :func:`probe_key`."""


@lru_cache(maxsize=None)
def variant_works(variant: str, timeout: float = 180.0) -> bool:
    """True if a child process can render with ``variant`` (cached per process, and on disk by
    :func:`probe_key`)."""
    key = probe_key(variant)
    if key is None:  # Dr.Jit cannot load the backend's library at all
        return False
    cached = _read_probe_cache().get(key)
    if isinstance(cached, bool):
        return cached
    try:
        done = subprocess.run([sys.executable, "-c", _PROBE, variant], capture_output=True, text=True,
                              timeout=timeout)
    except (subprocess.TimeoutExpired, OSError):
        return False  # not kept: a timeout may be the machine's load
    works = done.returncode == 0 and done.stdout.strip().endswith("ok")
    _write_probe_cache(key, works)
    return works


def probe_key(variant: str) -> str | None:
    """What a probe's answer depends on: ``variant``, the Python executable, the Mitsuba and Dr.Jit versions
    and the version of the backend library (libLLVM / the CUDA driver) Dr.Jit loads in this process; None
    when Dr.Jit cannot load it (no kernel is run to find out)."""
    import drjit as dr
    import mitsuba as mi

    if variant.startswith("cuda_"):
        backend, version = dr.JitBackend.CUDA, dr.detail.cuda_version
    elif variant.startswith("llvm_"):
        backend, version = dr.JitBackend.LLVM, dr.detail.llvm_version
    else:
        return f"{variant}"
    if not dr.has_backend(backend):
        return None
    library = ".".join(str(part) for part in version())
    return f"{variant}|{sys.executable}|mitsuba {mi.__version__}|drjit {dr.__version__}|{library}"


def _read_probe_cache() -> dict[str, object]:
    path = cache_path(PROBE_CACHE)
    try:
        answers = json.loads(path.read_text()) if path is not None else {}
    except (OSError, ValueError):
        return {}
    return answers if isinstance(answers, dict) else {}


def _write_probe_cache(key: str, works: bool) -> None:
    """Adds one answer (written to a temporary file, then renamed: readers never see half a file)."""
    path = cache_path(PROBE_CACHE)
    if path is None:
        return
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        answers = {**_read_probe_cache(), key: works}
        with tempfile.NamedTemporaryFile("w", dir=path.parent, suffix=".tmp", delete=False) as handle:
            json.dump(answers, handle, indent=1, sort_keys=True)
        os.replace(handle.name, path)
    except OSError:
        pass  # a read-only cache folder costs the probe next time, nothing else


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
    """Make ``variant`` the current Mitsuba variant of this process, with the threads it was given. Mitsuba's
    Python AD integrators, which the first switch to a JIT variant would execute, run on first use instead
    (:mod:`hybridgen.render.pathtrace.deferred_ad_integrators`). The LLVM variants run with 4 KiB pages
    (:mod:`hybridgen.render.pathtrace.huge_pages`)."""
    import mitsuba as mi

    if variant.startswith("llvm_"):
        decline_huge_pages()  # before Dr.Jit's first allocation: see huge_pages.py
    if mi.variant() != variant:
        from . import deferred_ad_integrators

        deferred = deferred_ad_integrators.defer() if is_jit(variant) else {}
        mi.set_variant(variant)
        deferred_ad_integrators.register_forwarders(deferred)
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
