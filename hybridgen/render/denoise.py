"""Denoising with Intel Open Image Denoise (PyPI ``pyoidn``, a core dependency), guided by the raster
view's exact albedo and normals: the guides are noise-free (``clean_aux``), which Mitsuba's own AOVs are
not, and they cost a raster draw instead of doubling the render time."""
from __future__ import annotations

import sys
from typing import Any

import numpy as np

from ..errors import SystemSetupError

INSTALL_HINT = ("denoising needs pyoidn (a hybridgen dependency): `pip install pyoidn`, or set `denoise: false` "
                "on renderer.RgbRenderer")


def require_oidn() -> Any:
    """The ``pyoidn`` module, or a SystemSetupError that says how to install it.

    pyoidn imports PyTorch at import time when it is installed (for its tensor inputs), which costs ~1.1 s of
    CPU per process; hybridgen passes NumPy arrays only, so unless torch is already imported, pyoidn is
    imported with torch hidden (pyoidn then takes NumPy arrays only, in this process)."""
    if "pyoidn" in sys.modules:
        return sys.modules["pyoidn"]
    hide_torch = "torch" not in sys.modules
    if hide_torch:
        sys.modules["torch"] = None  # type: ignore[assignment]  # `import torch` raises ImportError
    try:
        import pyoidn
    except ImportError:
        raise SystemSetupError(INSTALL_HINT) from None
    finally:
        if hide_torch:
            del sys.modules["torch"]
    return pyoidn


def denoise(linear: np.ndarray, albedo: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Denoised linear HDR RGB (float32, H x W x 3) from noisy ``linear`` and clean guides."""
    oidn = require_oidn()
    out = oidn.denoise(np.ascontiguousarray(linear, np.float32), np.ascontiguousarray(albedo, np.float32),
                       np.ascontiguousarray(normals, np.float32), hdr=True, clean_aux=True)
    return np.asarray(out, dtype=np.float32)
