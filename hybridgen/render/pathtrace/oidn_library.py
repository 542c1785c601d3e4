"""Open Image Denoise's C API through ``ctypes``: the library the ``pyoidn`` wheel ships, called without importing
``pyoidn``'s Python package.

``import pyoidn`` parses OIDN's C header with cffi (pycparser) on every import: ~0.1 s of CPU per process, on the
render loop's thread before the Mitsuba scene is built. The calls hybridgen makes are few - a CPU device, the
``RT`` filter with shared float3 images, ``hdr``, ``cleanAux`` and ``quality`` - and are declared here instead
(~1 ms). The filter and its device are made once per process, reused by every call (serialized: one filter) and
released at exit; each call binds its images, commits the filter and executes it synchronously, as pyoidn's
``denoise`` does (tests/render/test_oidn_library.py compares the two byte for byte).
"""
from __future__ import annotations

import atexit
import ctypes
import importlib.util
import sys
import threading
from pathlib import Path

import numpy as np

DEVICE_TYPE_CPU = 1
"""``OIDN_DEVICE_TYPE_CPU``: the images are host (NumPy) memory."""
FORMAT_FLOAT3 = 3
"""``OIDN_FORMAT_FLOAT3``: three float32 channels per pixel."""
QUALITY_HIGH = 6
"""``OIDN_QUALITY_HIGH``: the final-frame quality (Cycles' default denoising quality)."""
IMAGES = ("color", "albedo", "normal", "output")
"""The ``RT`` filter's images, in the order :meth:`Denoiser.run` takes them."""


LIBRARY_NAMES = {"win32": ("bin", "OpenImageDenoise.dll"), "darwin": ("lib", "libOpenImageDenoise.dylib")}
"""Where the pyoidn wheel keeps the library on each platform (its ``oidn`` folder); elsewhere ``lib`` and
``libOpenImageDenoise.so``. A versioned name (``libOpenImageDenoise.2.dylib``, ``.so.2``) is taken if the plain one
is missing."""


def pyoidn_folder() -> Path | None:
    """The installed ``pyoidn`` package's folder (found without importing it), or None."""
    spec = importlib.util.find_spec("pyoidn")
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations)))


def library_file() -> Path | None:
    """The OIDN library inside the installed ``pyoidn`` package, or None (no pyoidn, or no library in it)."""
    package = pyoidn_folder()
    if package is None:
        return None
    folder, name = LIBRARY_NAMES.get(sys.platform, ("lib", "libOpenImageDenoise.so"))
    plain = package / "oidn" / folder / name
    if plain.is_file():
        return plain
    stem, suffix = name.rsplit(".", 1)
    versioned = sorted((package / "oidn" / folder).glob(f"{stem}.*{suffix}*"))
    return versioned[0] if versioned else None


def _declared(path: Path) -> ctypes.CDLL:
    """The library at ``path`` with the signatures of the functions :class:`Denoiser` calls."""
    if sys.platform == "win32":  # the CPU device's DLL first, as OIDN's loader expects there
        ctypes.CDLL(str(path.with_name("OpenImageDenoise_device_cpu.dll")))
    lib = ctypes.CDLL(str(path))
    handle, name, size = ctypes.c_void_p, ctypes.c_char_p, ctypes.c_size_t
    signatures = {
        "oidnNewDevice": ([ctypes.c_int], handle),
        "oidnCommitDevice": ([handle], None),
        "oidnReleaseDevice": ([handle], None),
        "oidnGetDeviceError": ([handle, ctypes.POINTER(ctypes.c_char_p)], ctypes.c_int),
        "oidnNewFilter": ([handle, name], handle),
        "oidnSetSharedFilterImage": ([handle, name, ctypes.c_void_p, ctypes.c_int, size, size, size, size, size],
                                     None),
        "oidnSetFilterBool": ([handle, name, ctypes.c_bool], None),
        "oidnSetFilterInt": ([handle, name, ctypes.c_int], None),
        "oidnCommitFilter": ([handle], None),
        "oidnExecuteFilter": ([handle], None),
        "oidnReleaseFilter": ([handle], None),
    }
    for function, (arguments, result) in signatures.items():
        getattr(lib, function).argtypes = arguments
        getattr(lib, function).restype = result
    return lib


class Denoiser:
    """One CPU device and one ``RT`` filter of the library at ``path``, made on the first :meth:`run`."""

    def __init__(self, path: Path) -> None:
        self._lib = _declared(path)
        self._lock = threading.Lock()
        self._device: int | None = None
        self._filter: int | None = None
        self._bound: tuple[np.ndarray, ...] = ()  # the images the filter points to, kept alive until rebound

    def _check(self, operation: str) -> None:
        message = ctypes.c_char_p()
        code = self._lib.oidnGetDeviceError(self._device, ctypes.byref(message))
        if code != 0:
            text = message.value.decode("utf-8", errors="replace") if message.value else "no message"
            raise RuntimeError(f"Open Image Denoise: {operation} failed (error {code}): {text}")

    def _made(self) -> int:
        """The filter, made with its device on the first call (a failure releases what was made)."""
        if self._filter is None:
            self._device = self._lib.oidnNewDevice(DEVICE_TYPE_CPU)
            if not self._device:
                self._device = None
                raise RuntimeError("Open Image Denoise: no CPU device could be made")
            try:
                self._lib.oidnCommitDevice(self._device)
                self._check("committing the device")
                made = self._lib.oidnNewFilter(self._device, b"RT")
                self._check("making the RT filter")
                if not made:
                    raise RuntimeError("Open Image Denoise: no RT filter could be made")
            except BaseException:
                self._lib.oidnReleaseDevice(self._device)
                self._device = None
                raise
            self._filter = made
        return self._filter

    def run(self, color: np.ndarray, albedo: np.ndarray, normal: np.ndarray, *, hdr: bool, clean_aux: bool,
            quality: int = QUALITY_HIGH) -> np.ndarray:
        """The denoised ``color`` (float32 H x W x 3, C-contiguous, as the guides ``albedo`` and ``normal``)."""
        output = np.empty_like(color)
        images = (color, albedo, normal, output)
        for image in images:
            if image.dtype != np.float32 or image.shape != color.shape or image.ndim != 3 or image.shape[2] != 3 \
                    or not image.flags.c_contiguous:
                raise ValueError(f"denoiser images must be C-contiguous float32 H x W x 3 of one shape, got "
                                 f"{image.dtype} {image.shape}")
        height, width = color.shape[:2]
        with self._lock:
            flt = self._made()
            for name, image in zip(IMAGES, images):
                self._lib.oidnSetSharedFilterImage(flt, name.encode(), image.ctypes.data, FORMAT_FLOAT3, width, height,
                                                   0, 0, 0)
            self._bound = images
            self._lib.oidnSetFilterBool(flt, b"hdr", hdr)
            self._lib.oidnSetFilterBool(flt, b"cleanAux", clean_aux)
            self._lib.oidnSetFilterInt(flt, b"quality", quality)
            self._check("configuring the filter")
            self._lib.oidnCommitFilter(flt)
            self._check("committing the filter")
            self._lib.oidnExecuteFilter(flt)
            self._check("denoising")
        return output

    def close(self) -> None:
        """Releases the filter, then its device."""
        with self._lock:
            if self._filter is not None:
                self._lib.oidnReleaseFilter(self._filter)
                self._filter = None
            if self._device is not None:
                self._lib.oidnReleaseDevice(self._device)
                self._device = None


_SHARED: list[Denoiser] = []
_SHARED_LOCK = threading.Lock()


def shared_denoiser(path: Path) -> Denoiser:
    """The process's one :class:`Denoiser` (made on the first call, released at exit)."""
    with _SHARED_LOCK:
        if not _SHARED:
            _SHARED.append(Denoiser(path))
            atexit.register(_SHARED[0].close)
        return _SHARED[0]
