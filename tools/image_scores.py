"""Scores of 8-bit sRGB images (H x W x 3 uint8, the ``colors`` users get), as the color benchmarks compute them:
mean squared error in 8-bit levels squared, and PSNR in dB."""
from __future__ import annotations

import math
from pathlib import Path

import numpy as np


def read_png(path: Path) -> np.ndarray:
    """An image file as 8-bit sRGB (H x W x 3 uint8)."""
    from PIL import Image

    return np.asarray(Image.open(path).convert("RGB"))


def mse(a: np.ndarray, b: np.ndarray) -> float:
    """Mean squared difference of two images (8-bit levels squared)."""
    return float(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))


def db(value: float) -> float:
    """PSNR (dB) of an 8-bit mean squared error (inf for 0)."""
    return float("inf") if value <= 0 else 10 * math.log10(255.0 ** 2 / value)


def psnr(image: np.ndarray, reference: np.ndarray) -> float:
    """PSNR (dB) of two 8-bit sRGB images."""
    return db(mse(image, reference))
