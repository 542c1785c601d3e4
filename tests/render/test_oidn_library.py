"""hybridgen's ctypes calls into Open Image Denoise denoise exactly as pyoidn's own ``denoise`` does (the same
library, filter and settings), without importing pyoidn; a missing library is one line saying how to get it."""
from __future__ import annotations

import sys

import numpy as np
import pytest

from hybridgen.errors import SystemSetupError
from hybridgen.render.pathtrace import denoise as denoise_module
from hybridgen.render.pathtrace.oidn_library import Denoiser, library_file


def _inputs(seed: int, height: int = 40, width: int = 56) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A noisy HDR ramp lit by a step, its albedo (two halves) and camera-facing normals with a crease."""
    rng = np.random.default_rng(seed)
    y, x = np.mgrid[0:height, 0:width] / max(height, width)
    albedo = np.stack([np.where(x < 0.5, 0.8, 0.2), 0.5 + 0.3 * y, np.full_like(x, 0.4)], -1).astype(np.float32)
    normals = np.stack([np.where(y < 0.4, 0.0, 0.6), np.zeros_like(x), np.where(y < 0.4, 1.0, 0.8)], -1)
    clean = albedo * (1.5 + 2.0 * x)[..., None]
    noisy = clean * rng.gamma(4.0, 0.25, clean.shape)
    return noisy.astype(np.float32), albedo, normals.astype(np.float32)


def _pyoidn():
    """pyoidn's Python package (with torch hidden, as only NumPy arrays are passed)."""
    saved = sys.modules.get("torch", "absent")
    sys.modules["torch"] = None  # type: ignore[assignment]
    try:
        return pytest.importorskip("pyoidn")
    finally:
        if saved == "absent":
            del sys.modules["torch"]
        else:
            sys.modules["torch"] = saved


@pytest.mark.parametrize("hdr, clean_aux", [(True, True), (False, True), (True, False)])
def test_the_same_bytes_as_pyoidn(hdr: bool, clean_aux: bool) -> None:
    pyoidn = _pyoidn()
    path = library_file()
    assert path is not None and path.is_file()
    ours = Denoiser(path)
    try:
        for seed in (1, 2):
            color, albedo, normals = _inputs(seed)
            mine = ours.run(color, albedo, normals, hdr=hdr, clean_aux=clean_aux)
            theirs = pyoidn.denoise(color, albedo, normals, hdr=hdr, clean_aux=clean_aux)
            np.testing.assert_array_equal(mine, theirs)
            clean = albedo * (1.5 + 2.0 * np.mgrid[0:40, 0:56][1] / 56)[..., None]
            if hdr:  # it took noise out (LDR mode reads the values over 1 as clipped)
                assert np.abs(mine - clean).mean() < 0.5 * np.abs(color - clean).mean()
    finally:
        ours.close()


def test_images_of_another_shape_or_type_are_refused() -> None:
    path = library_file()
    assert path is not None
    ours = Denoiser(path)
    color, albedo, normals = _inputs(3)
    with pytest.raises(ValueError, match="float32"):
        ours.run(color, albedo[:-1], normals, hdr=True, clean_aux=True)
    with pytest.raises(ValueError, match="float32"):
        ours.run(color.astype(np.float64), albedo, normals, hdr=True, clean_aux=True)
    with pytest.raises(ValueError, match="float32"):
        ours.run(color[:, ::2], albedo[:, ::2], normals[:, ::2], hdr=True, clean_aux=True)
    ours.close()


def test_without_the_library_one_line_says_how_to_get_it(monkeypatch) -> None:
    monkeypatch.setattr(denoise_module, "library_file", lambda: None)
    with pytest.raises(SystemSetupError, match="pip install pyoidn"):
        denoise_module.require_oidn()


def test_a_library_that_does_not_load_is_one_line(tmp_path, monkeypatch) -> None:
    broken = tmp_path / "libOpenImageDenoise.so"
    broken.write_bytes(b"not a library")
    monkeypatch.setattr(denoise_module, "library_file", lambda: broken)
    monkeypatch.setattr("hybridgen.render.pathtrace.oidn_library._SHARED", [])
    with pytest.raises(SystemSetupError, match="does not load"):
        denoise_module.require_oidn()


def test_the_library_is_found_by_its_versioned_name_and_missing_is_said(tmp_path, monkeypatch) -> None:
    from hybridgen.render.pathtrace import oidn_library

    package = tmp_path / "pyoidn"
    (package / "oidn" / "lib").mkdir(parents=True)
    (package / "oidn" / "lib" / "libOpenImageDenoise_core.so.2.5.1").write_bytes(b"")
    monkeypatch.setattr(oidn_library, "pyoidn_folder", lambda: package)
    monkeypatch.setattr(denoise_module, "pyoidn_folder", lambda: package)
    monkeypatch.setattr(sys, "platform", "linux")
    assert oidn_library.library_file() is None  # the core library is not the API's
    with pytest.raises(SystemSetupError, match="has no Open Image Denoise library"):
        denoise_module.require_oidn()
    (package / "oidn" / "lib" / "libOpenImageDenoise.so.2").write_bytes(b"")
    assert oidn_library.library_file() == package / "oidn" / "lib" / "libOpenImageDenoise.so.2"
    (package / "oidn" / "lib" / "libOpenImageDenoise.so").write_bytes(b"")
    assert oidn_library.library_file() == package / "oidn" / "lib" / "libOpenImageDenoise.so"


def test_a_filter_that_cannot_be_made_releases_its_device() -> None:
    path = library_file()
    assert path is not None
    ours = Denoiser(path)
    real = ours._lib
    released: list[object] = []

    class NoFilter:  # the library, except that it makes no RT filter
        def __getattr__(self, name: str):
            return getattr(real, name)

        def oidnNewFilter(self, device, kind):
            return None

        def oidnReleaseDevice(self, device):
            released.append(device)
            return real.oidnReleaseDevice(device)

    ours._lib = NoFilter()
    color, albedo, normals = _inputs(4)
    with pytest.raises(RuntimeError, match="no RT filter"):
        ours.run(color, albedo, normals, hdr=True, clean_aux=True)
    assert len(released) == 1 and ours._device is None and ours._filter is None
    ours._lib = real  # the next call starts over and denoises
    assert ours.run(color, albedo, normals, hdr=True, clean_aux=True).shape == color.shape
    ours.close()
