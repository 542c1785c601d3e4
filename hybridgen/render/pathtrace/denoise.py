"""Denoising with Intel Open Image Denoise (the library of PyPI ``pyoidn``, a core dependency, called through
:mod:`.oidn_library`), guided by the raster view's exact albedo and normals: the guides are noise-free
(``clean_aux``), which Mitsuba's own AOVs are not, and they cost a raster draw instead of doubling the render
time."""
from __future__ import annotations

import numpy as np

from ...errors import SystemSetupError
from .oidn_library import Denoiser, library_file, pyoidn_folder, shared_denoiser

INSTALL_HINT = ("denoising needs pyoidn (a hybridgen dependency): `pip install pyoidn`, or set `denoise: false` "
                "on renderer.RgbRenderer")


def require_oidn() -> Denoiser:
    """The process's Open Image Denoise filter (:func:`.oidn_library.shared_denoiser`), or a SystemSetupError that
    says how to install it. pyoidn's Python package is not imported (nor the PyTorch it would import when
    installed): only its library file is used."""
    path = library_file()
    if path is None:
        package = pyoidn_folder()
        raise SystemSetupError(INSTALL_HINT if package is None else
                               f"{INSTALL_HINT} (pyoidn at {package} has no Open Image Denoise library under oidn/: "
                               f"reinstall it)")
    try:
        return shared_denoiser(path)
    except OSError as exc:  # the file is there but does not load (a broken or foreign wheel)
        raise SystemSetupError(f"{INSTALL_HINT} ({path.name} does not load: {exc})") from None


BORDER_PAD = 8
"""Pixels of mirrored image (and guides) added around each side before denoising, cropped after.

Open Image Denoise treats the image border poorly: on the tabletop scene of tools/color_quality.py (160x120,
against a 2048-spp reference) the outermost ring of denoised floor pixels was off by 1.9 % on average (the raw
input there: 0.44 %), about a quarter of the whole image's squared error. With the image mirrored outwards
(``numpy.pad`` mode ``symmetric``) the ring is off by 0.14 % and the 8-bit MSE of the whole image drops
1.72 -> 1.53 (64 spp) and 0.84 -> 0.72 (256 spp); 4 / 8 / 16 / 32 px of padding: 0.73 / 0.72 / 0.72 / 0.72."""


def denoise(linear: np.ndarray, albedo: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """Denoised linear HDR RGB (float32, H x W x 3) from noisy ``linear`` and clean guides (each mirrored
    outwards by :data:`BORDER_PAD` px for the denoiser)."""
    denoiser = require_oidn()

    def padded(image: np.ndarray) -> np.ndarray:
        pad = ((BORDER_PAD, BORDER_PAD), (BORDER_PAD, BORDER_PAD), (0, 0))
        return np.ascontiguousarray(np.pad(np.asarray(image, np.float32), pad, mode="symmetric"))

    out = denoiser.run(padded(linear), padded(albedo), padded(normals), hdr=True, clean_aux=True)
    return out[BORDER_PAD:-BORDER_PAD, BORDER_PAD:-BORDER_PAD].copy() if BORDER_PAD else out


WARM_UP_SIZE = 8
"""Pixels per side of the image :func:`warm_up` denoises."""


def warm_up() -> None:
    """Creates Open Image Denoise's device and its filter for :func:`denoise`'s inputs (color, albedo and normals,
    HDR, clean guides) by denoising a tiny black image with :func:`denoise` itself: ~0.05 s of one-time setup that
    a thread can do while the first image is rendered (the denoiser serializes its calls and is safe to call from
    any thread)."""
    zeros = np.zeros((WARM_UP_SIZE, WARM_UP_SIZE, 3), np.float32)
    denoise(zeros, zeros, zeros)
