"""A config's image texture (``getter.Texture``'s result or a path), as BlenderProc 1.x's material functions take it:
a list is drawn from (one texture, as BlenderProc draws one), the file must exist, and its pixels read as sRGB unless
the scene's texture of that path (``loader.TextureLoader``) is tagged with a data color space."""
from __future__ import annotations

from pathlib import Path
from typing import Any, Sequence

import numpy as np

from ..errors import ConfigError
from ..scene.dust import DATA_SPACES, SRGB_SPACES, reads_as_srgb
from ..scene.image_texture import ImageTexture


def drawn_texture(value: Any, rng: np.random.Generator, textures: Sequence[ImageTexture], key: str,
                  empty: str, noun: str) -> tuple[str, bool] | None:
    """(path, decoded from sRGB) of the configured texture ``value`` at config key ``key``; None for none. ``empty``:
    the message for an empty list; ``noun``: what the texture is called in the color-space message."""
    if isinstance(value, (list, tuple)):
        if not value:
            raise ConfigError(empty, key=key)
        value = value[int(rng.integers(len(value)))]
    if value is None:
        return None
    path = Path(str(value))
    if not path.is_file():
        raise ConfigError(f"no such image file: {path}", key=key)
    spaces = [t.colorspace for t in textures if Path(t.path).resolve() == path.resolve()] or ["sRGB"]
    srgb = reads_as_srgb(spaces[0])
    if srgb is None:
        raise ConfigError(f"{noun} in color space {spaces[0]!r} is not supported (supported: "
                          f"{', '.join(SRGB_SPACES + DATA_SPACES)})", key=key)
    return str(path), srgb
