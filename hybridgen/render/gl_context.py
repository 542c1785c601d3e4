"""Headless OpenGL 4.3+ context through EGL (Mesa llvmpipe without a GPU).

glcontext's EGL backend enumerates EGL devices and needs no display or window system. On a multi-GPU
machine the device is chosen by ``device_index`` or the ``HYBRIDGEN_EGL_DEVICE`` environment variable
(EGL device order is not CUDA order). Failures become :class:`SystemSetupError` with the fix.
"""
from __future__ import annotations

import os
import threading
from typing import Any

from ..errors import SystemSetupError

MIN_GL_VERSION = 430
_FIX = ("install Mesa's EGL and its software driver: "
        "apt-get install libegl1 libegl-mesa0 libgbm1 libgl1 libgl1-mesa-dri "
        "(or run `make setup`, which does it when run as root)")

_lock = threading.Lock()
_shared: dict[int, Any] = {}


def egl_device_index(device_index: int | None = None) -> int:
    """The EGL device to use: the argument, else ``$HYBRIDGEN_EGL_DEVICE``, else 0."""
    if device_index is not None:
        return int(device_index)
    env = os.environ.get("HYBRIDGEN_EGL_DEVICE", "").strip()
    if not env:
        return 0
    try:
        return int(env)
    except ValueError as exc:
        raise SystemSetupError(f"HYBRIDGEN_EGL_DEVICE must be an integer, got {env!r}") from exc


def create_context(device_index: int | None = None) -> Any:
    """A new standalone moderngl context on EGL device ``device_index``."""
    import moderngl

    index = egl_device_index(device_index)
    try:
        ctx = moderngl.create_standalone_context(backend="egl", device_index=index)
    except Exception as exc:  # glcontext raises plain Exceptions with EGL codes
        raise SystemSetupError(f"cannot create an EGL OpenGL context on device {index} ({exc}); {_FIX}") from exc
    if ctx.version_code < MIN_GL_VERSION:
        version = ctx.version_code
        ctx.release()
        raise SystemSetupError(f"OpenGL {version // 100}.{version % 100 // 10} found, hybridgen needs 4.3 "
                               "(storage buffers); update Mesa (libgl1-mesa-dri)")
    return ctx


def shared_context(device_index: int | None = None) -> Any:
    """One context per EGL device for this process, created on first use."""
    index = egl_device_index(device_index)
    with _lock:
        if index not in _shared:
            _shared[index] = create_context(index)
        return _shared[index]


def renderer_name(ctx: Any) -> str:
    """The GL renderer string, e.g. 'llvmpipe (LLVM 15.0.6, 256 bits)'."""
    return str(ctx.info.get("GL_RENDERER", "unknown"))
