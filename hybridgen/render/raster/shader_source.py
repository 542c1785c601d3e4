"""Reads GLSL sources shipped in the repository's ``shaders/`` folder (installed as ``hybridgen.shaders``)."""
from __future__ import annotations

from functools import lru_cache
from importlib import resources


@lru_cache(maxsize=None)
def shader_source(name: str) -> str:
    """The text of ``shaders/<name>``."""
    return resources.files("hybridgen.shaders").joinpath(name).read_text(encoding="utf-8")
