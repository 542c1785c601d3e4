"""The OBJ scan for ``mtllib`` statements (only lines containing the word are matched) names exactly the
files a full regex scan of every line names."""
from __future__ import annotations

from hybridgen.io.mesh_references import _MTLLIB, referenced_files


def test_mtllib_scan_names_what_a_full_scan_names(tmp_path):
    text = (b"# mtllib commented.mtl\nmtllib first.mtl\nv 0 0 0\n  mtllib  two words.mtl  \r\n"
            b"xmtllib not.mtl\n\tmtllib tabbed.mtl mtllib same_line.mtl\nmtllibx no.mtl\nf 1 1 1\nmtllib last.mtl")
    obj = tmp_path / "scene.obj"
    obj.write_bytes(text)
    expected = [tmp_path / m.group(1).decode() for m in _MTLLIB.finditer(text)]
    assert [p.name for p in expected] == ["first.mtl", "two words.mtl", "tabbed.mtl mtllib same_line.mtl",
                                          "last.mtl"]
    assert referenced_files(obj) == expected
