"""Headless OpenGL 4.3+ context through EGL (Mesa llvmpipe without a GPU).

glcontext's EGL backend enumerates EGL devices and needs no display or window system. On a multi-GPU
machine the device is chosen by ``device_index`` or the ``HYBRIDGEN_EGL_DEVICE`` environment variable
(EGL device order is not CUDA order). Failures become :class:`SystemSetupError` with the fix.
"""
from __future__ import annotations

import os
import threading
from typing import Any

from ... import stop_request
from ...errors import SystemSetupError

MIN_GL_VERSION = 430
_FIX = ("install Mesa's EGL and its software driver: "
        "apt-get install libegl1 libegl-mesa0 libgbm1 libgl1 libgl1-mesa-dri "
        "(or run `make setup`, which does it when run as root)")

_lock = threading.Lock()
_shared: dict[int, Any] = {}


EGL_CUDA_DEVICE_NV = 0x323A


def egl_device_for_cuda(cuda_index: int) -> int | None:
    """The EGL device index whose ``EGL_CUDA_DEVICE_NV`` is CUDA device ``cuda_index`` (NVIDIA drivers), or
    None when EGL cannot tell (no NVIDIA EGL, no such device). EGL enumerates devices in its own order."""
    import ctypes

    try:
        egl = ctypes.CDLL("libEGL.so.1")
        get_proc = egl.eglGetProcAddress
        get_proc.restype = ctypes.c_void_p
        get_proc.argtypes = [ctypes.c_char_p]
        query_devices = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_int, ctypes.POINTER(ctypes.c_void_p),
                                         ctypes.POINTER(ctypes.c_int))(get_proc(b"eglQueryDevicesEXT"))
        query_attrib = ctypes.CFUNCTYPE(ctypes.c_uint, ctypes.c_void_p, ctypes.c_int,
                                        ctypes.POINTER(ctypes.c_ssize_t))(get_proc(b"eglQueryDeviceAttribEXT"))
    except (OSError, TypeError, AttributeError):
        return None
    count = ctypes.c_int(0)
    devices = (ctypes.c_void_p * 32)()
    if not query_devices(32, devices, ctypes.byref(count)):
        return None
    for index in range(count.value):
        value = ctypes.c_ssize_t(-1)
        if query_attrib(devices[index], EGL_CUDA_DEVICE_NV, ctypes.byref(value)) and value.value == cuda_index:
            return index
    return None


def egl_device_index(device_index: int | None = None) -> int:
    """The EGL device to use: the argument, else ``$HYBRIDGEN_EGL_DEVICE``, else the EGL device of the first
    CUDA device this process may use (``$CUDA_VISIBLE_DEVICES``, as Ray and SLURM set it per worker), else 0."""
    if device_index is not None:
        return int(device_index)
    env = os.environ.get("HYBRIDGEN_EGL_DEVICE", "").strip()
    if not env:
        visible = os.environ.get("CUDA_VISIBLE_DEVICES", "").split(",")[0].strip()
        if visible.isdigit():
            matched = egl_device_for_cuda(int(visible))
            if matched is not None:
                return matched
        return 0
    try:
        return int(env)
    except ValueError as exc:
        raise SystemSetupError(f"HYBRIDGEN_EGL_DEVICE must be an integer, got {env!r}") from exc


def create_context(device_index: int | None = None) -> Any:
    """A new standalone moderngl context on EGL device ``device_index``, asked for OpenGL 4.3 (NVIDIA's EGL
    creates exactly the version asked for - 3.3 unless told - where Mesa creates its highest)."""
    import moderngl

    index = egl_device_index(device_index)
    try:
        with stop_request.deferred():  # moderngl parses the context's settings through Python callbacks
            ctx = moderngl.create_standalone_context(backend="egl", device_index=index, require=MIN_GL_VERSION)
    except Exception as exc:  # glcontext raises plain Exceptions with EGL codes
        raise SystemSetupError(f"cannot create an EGL OpenGL context on device {index} ({exc}); {_FIX}") from exc
    if ctx.version_code < MIN_GL_VERSION:
        version = ctx.version_code
        ctx.release()
        raise SystemSetupError(f"OpenGL {version // 100}.{version % 100 // 10} found, hybridgen needs 4.3 "
                               "(storage buffers); update Mesa (libgl1-mesa-dri)")
    return ctx


def compile_program(ctx: Any, **shaders: str) -> Any:
    """``ctx.program(**shaders)`` that a stop request (SIGTERM, SIGINT) cannot interrupt: moderngl builds the
    program's uniforms and attributes by calling back into Python and uses the results unchecked, so an
    exception raised there by a signal handler crashed the process (SIGSEGV) instead of stopping it. The
    request is raised when the program is made (:func:`hybridgen.stop_request.deferred`)."""
    with stop_request.deferred():
        return ctx.program(**shaders)


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


SOFTWARE_RENDERERS = ("llvmpipe", "softpipe", "swr", "software")


def software_renderer(ctx: Any) -> bool:
    """True when ``ctx`` rasterizes on the CPU (Mesa llvmpipe and kin), False on a GPU driver."""
    renderer = str(ctx.info.get("GL_RENDERER", "")).lower()
    return any(name in renderer for name in SOFTWARE_RENDERERS)
