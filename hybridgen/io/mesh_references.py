"""Files a mesh file names: the MTL libraries of an OBJ and the texture maps of an MTL.

Used to check that they exist before loading (trimesh renders a mesh untextured, without a word, when they
are missing), to include them in a run's fingerprint (an edited texture changes the output) and in the mesh
cache's key. The scan of a file is remembered by the file's identity (:mod:`hybridgen.io.file_identity`),
so these users share one read of a large OBJ per process.
"""
from __future__ import annotations

import os
import re
from pathlib import Path

from .file_identity import IdentityMemo

MAX_SCANNED_BYTES = 512 * 2**20
_MTLLIB = re.compile(rb"^[ \t]*mtllib[ \t]+(.+?)[ \t]*\r?$", re.MULTILINE)
_MAPS = re.compile(rb"^[ \t]*(?:map_\w+|bump|disp|decal|norm|refl)[ \t]+"  # statement
                   rb"(?:-\S+(?:[ \t]+[-\d.]+)*[ \t]+)*"  # options such as -s 1 1 1 or -bm 0.5
                   rb"(\S.*?)[ \t]*\r?$", re.MULTILINE)


def referenced_files(path: Path) -> list[Path]:
    """The files ``path`` (an .obj or .mtl) names, relative to its folder as OBJ readers resolve them;
    empty for other formats and for files beyond :data:`MAX_SCANNED_BYTES`."""
    suffix = path.suffix.lower()
    if suffix not in (".obj", ".mtl") or path.stat().st_size > MAX_SCANNED_BYTES:
        return []
    return [path.parent / name for name in scanned_names(path)]


def _scan(path: Path) -> tuple[str, ...]:
    data = path.read_bytes()
    matches = _mtllib_statements(data) if path.suffix.lower() == ".obj" else _MAPS.finditer(data)
    return tuple(os.fsdecode(m.group(1)).replace("\\", "/") for m in matches)


scanned_names: IdentityMemo[tuple[str, ...]] = IdentityMemo(_scan)
"""The names an .obj (``mtllib``) or .mtl (texture maps) file holds, as written ('/' separators), read once
per process and file identity."""


def _mtllib_statements(data: bytes) -> list[re.Match[bytes]]:
    """``_MTLLIB``'s matches in an OBJ's bytes, found by looking only at the lines that contain ``mtllib``
    (a regex tried at every line start of a 10 MB OBJ took ~0.2 s, twice per run)."""
    matches = []
    start = data.find(b"mtllib")
    while start >= 0:
        line_start = data.rfind(b"\n", 0, start) + 1
        line_end = data.find(b"\n", start)
        line_end = len(data) if line_end < 0 else line_end
        match = _MTLLIB.match(data, line_start, line_end)
        if match is not None:
            matches.append(match)
        start = data.find(b"mtllib", line_end)
    return matches


def missing_references(path: Path) -> list[Path]:
    """The MTL files an OBJ names, and the textures those name, that do not exist."""
    missing: list[Path] = []
    for library in referenced_files(path):
        if not library.is_file():
            missing.append(library)
            continue
        missing.extend(texture for texture in referenced_files(library) if not texture.is_file())
    return missing


LENIENT_ENV = "HYBRIDGEN_LENIENT"


def is_lenient() -> bool:
    """``hybridgen run --lenient`` (inherited by worker processes): missing MTL/texture files are a notice."""
    return os.environ.get(LENIENT_ENV, "") not in ("", "0")


def check_references(path: Path) -> str | None:
    """None when every file ``path`` names exists; else the one-line problem (raise it, or with
    :func:`is_lenient` report it as a notice)."""
    missing = missing_references(path)
    if not missing:
        return None
    shown = ", ".join(f"'{p}'" for p in missing[:3]) + (f" and {len(missing) - 3} more" if len(missing) > 3 else "")
    return f"mesh '{path}': missing file(s) it names: {shown}; it would render without its materials/textures"
