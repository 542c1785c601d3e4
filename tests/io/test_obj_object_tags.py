"""tag_obj_objects (which finds OBJ ``o`` statements without walking every line) marks exactly the lines a
line-by-line reading marks: first non-whitespace character ``o`` followed by a space, a tab or the line's end."""
from __future__ import annotations

import random

from hybridgen.io.mesh_loader import _SENTINEL, blender_name, tag_obj_objects


def _line_by_line(text: str, default_name: str) -> tuple[str, list[str]]:
    """The reference: split into lines, test each one."""
    names: list[str] = []

    def number(name: str) -> int:
        if name not in names:
            names.append(name)
        return names.index(name)

    out = [f"o {_SENTINEL.format(number(blender_name(default_name)))}"]
    for line in text.replace("\r\n", "\n").replace("\\\n", "").split("\n"):
        stripped = line.lstrip()
        if stripped.startswith(("o ", "o\t")) or stripped == "o":
            out.append(f"o {_SENTINEL.format(number(blender_name(stripped[1:]) or blender_name(default_name)))}")
        else:
            out.append(line)
    return "\n".join(out), names


def test_named_objects_and_repeats():
    text = "v 0 0 0\no first\nf 1 1 1\n  o\tsecond  part \nusemtl wood\no first\r\no\nfoo o bar\noo x\n"
    tagged, names = tag_obj_objects(text, "stem")
    assert names == ["stem", "first", "second part"]
    assert tagged.splitlines()[1:] == ["v 0 0 0", "o " + _SENTINEL.format(1), "f 1 1 1", "o " + _SENTINEL.format(2),
                                       "usemtl wood", "o " + _SENTINEL.format(1), "o " + _SENTINEL.format(0),
                                       "foo o bar", "oo x"]
    assert (tagged, names) == _line_by_line(text, "stem")


def test_random_texts_match_the_line_by_line_reading():
    rng = random.Random(5)
    pieces = ["o", "o ", "o\t", "\n", "\r\n", "\r", " ", "\t", "v 1 2 3", "\\\n", "x", "wood", "\x0b", "\u2028",
              "\xa0", "\x85", "o\n", "  o name\n", "oo", "\x1c", "f 1 2 3\n"]
    for _ in range(3000):
        text = "".join(rng.choice(pieces) for _ in range(rng.randint(0, 30)))
        assert tag_obj_objects(text, "d") == _line_by_line(text, "d"), repr(text)
