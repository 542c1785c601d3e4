"""The few GL calls of a label keypoint that do real work, called through ctypes so that they release the GIL.

moderngl holds the GIL inside every call. With llvmpipe a draw call shades the vertices and bins the
triangles on the calling thread, and ``glReadPixels`` waits for the rasterizer threads: holding the GIL there
stops every other Python thread (the HDF5 compressors, a second raster thread) for most of a keypoint.
These wrappers make the same GL calls on the context current on the calling thread (EGL's entry points
dispatch per thread), with the objects moderngl made (``.glo`` names), so the values are the same.

Fences (``fence``/``wait``) let the raster view wait for one keypoint's draws alone: see ``RasterView.collect``.
"""
from __future__ import annotations

import ctypes
from typing import Any

import numpy as np

GL_TRIANGLES = 0x0004
GL_UNSIGNED_BYTE, GL_UNSIGNED_SHORT, GL_UNSIGNED_INT, GL_FLOAT = 0x1401, 0x1403, 0x1405, 0x1406
GL_PACK_ALIGNMENT = 0x0D05
GL_READ_FRAMEBUFFER = 0x8CA8
GL_DRAW_INDIRECT_BUFFER = 0x8F3F
GL_COLOR_ATTACHMENT0 = 0x8CE0
GL_SYNC_GPU_COMMANDS_COMPLETE = 0x9117
GL_ALREADY_SIGNALED, GL_TIMEOUT_EXPIRED, GL_CONDITION_SATISFIED, GL_WAIT_FAILED = 0x911A, 0x911B, 0x911C, 0x911D
_WAIT_STEP_NS = 1_000_000_000
_FLOAT_FORMATS = {1: 0x1903, 2: 0x8227, 3: 0x1907, 4: 0x1908}  # GL_RED, GL_RG, GL_RGB, GL_RGBA
_INTEGER_FORMATS = {1: 0x8D94, 2: 0x8228, 3: 0x8D98, 4: 0x8D99}  # GL_RED_INTEGER ... GL_RGBA_INTEGER
_TYPES = {"f4": GL_FLOAT, "u1": GL_UNSIGNED_BYTE, "u2": GL_UNSIGNED_SHORT, "u4": GL_UNSIGNED_INT}

_uint, _int, _ptr, _size = ctypes.c_uint, ctypes.c_int, ctypes.c_void_p, ctypes.c_ssize_t
_SIGNATURES: dict[str, tuple[Any, ...]] = {  # name: (return type, *argument types)
    "glUseProgram": (None, _uint),
    "glBindVertexArray": (None, _uint),
    "glBindBuffer": (None, _uint, _uint),
    "glBindFramebuffer": (None, _uint, _uint),
    "glReadBuffer": (None, _uint),
    "glPixelStorei": (None, _uint, _int),
    "glDrawElements": (None, _uint, _int, _uint, _ptr),
    "glMultiDrawElementsIndirect": (None, _uint, _uint, _ptr, _int, _int),
    "glReadPixels": (None, _int, _int, _int, _int, _uint, _uint, _ptr),
    "glFenceSync": (_ptr, _uint, _uint),
    "glClientWaitSync": (_uint, _ptr, _uint, ctypes.c_uint64),
    "glDeleteSync": (None, _ptr),
}


class GlCalls:
    """GL entry points from ``eglGetProcAddress`` (None when EGL cannot give them: then callers use moderngl)."""

    def __init__(self) -> None:
        egl = ctypes.CDLL("libEGL.so.1")
        get_proc = egl.eglGetProcAddress
        get_proc.restype, get_proc.argtypes = ctypes.c_void_p, [ctypes.c_char_p]
        self._current = egl.eglGetCurrentContext
        self._current.restype, self._current.argtypes = ctypes.c_void_p, []
        self.functions: dict[str, Any] = {}
        for name, (result, *args) in _SIGNATURES.items():
            address = get_proc(name.encode())
            if not address:
                raise OSError(f"eglGetProcAddress found no {name}")
            self.functions[name] = ctypes.CFUNCTYPE(result, *args)(address)  # CFUNCTYPE calls release the GIL

    def egl_context_current(self) -> bool:
        """Whether an EGL context is current on this thread (a context made otherwise, e.g. OSMesa, is not
        reached by these entry points)."""
        return bool(self._current())

    def draw(self, program: Any, vao: Any) -> None:
        """``vao.render()`` of an indexed (uint32) triangle vertex array, without the GIL."""
        f = self.functions
        f["glUseProgram"](program.glo)
        f["glBindVertexArray"](vao.glo)
        f["glDrawElements"](GL_TRIANGLES, vao.vertices, GL_UNSIGNED_INT, None)

    def draw_indirect(self, program: Any, vao: Any, commands: Any, count: int) -> None:
        """``vao.render_indirect(commands, count=count)`` (20-byte indexed commands), without the GIL."""
        f = self.functions
        f["glUseProgram"](program.glo)
        f["glBindVertexArray"](vao.glo)
        f["glBindBuffer"](GL_DRAW_INDIRECT_BUFFER, commands.glo)
        f["glMultiDrawElementsIndirect"](GL_TRIANGLES, GL_UNSIGNED_INT, None, count, 20)

    def fence(self) -> int:
        """A fence after the commands issued so far (``glFenceSync``; it also flushes them, so that the
        rasterizer starts on them now)."""
        return int(self.functions["glFenceSync"](GL_SYNC_GPU_COMMANDS_COMPLETE, 0))

    def wait(self, fence: int) -> None:
        """Wait, without the GIL, until the commands before ``fence`` are done, then delete it."""
        try:
            while True:
                status = self.functions["glClientWaitSync"](fence, 0, _WAIT_STEP_NS)
                if status in (GL_ALREADY_SIGNALED, GL_CONDITION_SATISFIED):
                    return
                if status != GL_TIMEOUT_EXPIRED:
                    raise RuntimeError(f"glClientWaitSync failed (0x{status:x})")
        finally:
            self.discard(fence)

    def discard(self, fence: int) -> None:
        """Delete ``fence`` without waiting for it."""
        self.functions["glDeleteSync"](fence)

    def read_into(self, out: np.ndarray, fbo: Any, attachment: int, components: int, dtype: str) -> None:
        """``fbo.read_into(out, attachment=..., components=..., dtype=...)`` of the whole framebuffer into the
        C-contiguous ``out``, without the GIL (waits for the rasterizer). Binds only the read framebuffer."""
        if not out.flags.c_contiguous:
            raise ValueError("read_into needs a C-contiguous array")
        width, height = fbo.size
        formats = _FLOAT_FORMATS if dtype == "f4" else _INTEGER_FORMATS  # the targets' dtypes: f4 or u1/u2/u4
        f = self.functions
        f["glBindFramebuffer"](GL_READ_FRAMEBUFFER, fbo.glo)
        f["glReadBuffer"](GL_COLOR_ATTACHMENT0 + attachment)
        f["glPixelStorei"](GL_PACK_ALIGNMENT, 1)
        f["glReadPixels"](0, 0, width, height, formats[components], _TYPES[dtype], out.ctypes.data)


_calls: GlCalls | None = None
_tried = False


def gl_calls() -> GlCalls | None:
    """The process's :class:`GlCalls` when an EGL context is current on this thread, else None (no EGL entry
    points, or the current context is not EGL's): then callers use moderngl."""
    global _calls, _tried
    if not _tried:
        _tried = True
        try:
            _calls = GlCalls()
        except (OSError, AttributeError):
            _calls = None
    return _calls if _calls is not None and _calls.egl_context_current() else None
