"""Object names as Blender's importers make them: names truncated to 63 bytes with Blender's ``.001`` suffixes, and
an OBJ's ``o`` statements tagged so that each becomes one object with Blender's name (docs/blenderproc.md)."""
from __future__ import annotations

import re
from typing import Iterable, Iterator

NAME_SUFFIX = re.compile(r"^(.*)\.(\d+)$")
"""A numeric suffix Blender strips before numbering a taken name: any digits after the last dot (``a.2`` taken
gives ``a.001``, measured with bpy 4.2.0)."""
BLENDER_NAME_BYTES = 63
"""Blender truncates object names to 63 bytes."""

_SENTINEL = "__hybridgen_object_{}__"
_SENTINEL_RE = re.compile(r"__hybridgen_object_(\d+)__")


def blender_name(text: str) -> str:
    """An object name as Blender stores it: words joined by one space, at most 63 UTF-8 bytes. Bytes of a
    file name that are not UTF-8 (Python's surrogate escapes) become U+FFFD, as in the OBJ text."""
    name = " ".join(text.split()).encode("utf-8", "surrogateescape").decode("utf-8", "replace")
    return name.encode("utf-8")[:BLENDER_NAME_BYTES].decode("utf-8", errors="ignore")


def unique_blender_name(name: str, taken: Iterable[str]) -> str:
    """``name``, or Blender's next free ``base.001``, ``base.002`` ... when ``name`` is taken (``base``: ``name``
    without its :data:`NAME_SUFFIX`)."""
    used = taken if isinstance(taken, (set, frozenset)) else set(taken)
    if name not in used:
        return name
    match = NAME_SUFFIX.match(name)
    base = match.group(1) if match else name
    number = 1
    while f"{base}.{number:03d}" in used:
        number += 1
    return f"{base}.{number:03d}"


def tag_obj_objects(text: str, default_name: str) -> tuple[str, list[str]]:
    """OBJ text with every ``o`` line replaced by a numbered marker, and the Blender names by number.

    Faces before the first ``o`` belong to an object named ``default_name`` (Blender uses the file name);
    an ``o`` name that comes again continues the same object, as Blender's importer does.
    """
    names: list[str] = []
    index_of: dict[str, int] = {}

    def number(name: str) -> int:
        if name not in index_of:
            index_of[name] = len(names)
            names.append(name)
        return index_of[name]

    text = text.replace("\r\n", "\n").replace("\\\n", "")
    out = [f"o {_SENTINEL.format(number(blender_name(default_name)))}\n"]
    done = 0  # text before this index is in ``out``
    for start, end in _object_statements(text):
        name = blender_name(text[start + 1:end]) or blender_name(default_name)
        line_start = text.rfind("\n", 0, start) + 1
        out.append(text[done:line_start])
        out.append(f"o {_SENTINEL.format(number(name))}")
        done = end
    out.append(text[done:])
    return "".join(out), names


def _object_statements(text: str) -> Iterator[tuple[int, int]]:
    """(index of the ``o``, end of its line) of every ``o`` statement in OBJ ``text`` (lines split at "\\n"):
    a line whose first non-whitespace character is ``o`` followed by a space, a tab or the line's end. Only the
    lines holding an "o" are looked at (an OBJ of 10 MB has few: vertex and face lines hold none)."""
    start = text.find("o")
    while start >= 0:
        line_end = text.find("\n", start)
        line_end = len(text) if line_end < 0 else line_end
        line_start = text.rfind("\n", 0, start) + 1
        before = text[line_start:start]
        if (not before or before.isspace()) and (start + 1 == line_end or text[start + 1] in " \t"):
            yield start, line_end
        start = text.find("o", line_end)
