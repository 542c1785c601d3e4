"""An OBJ's MTL values become the Principled values Blender 4.2's OBJ importer gives them (what BlenderProc
renders), asserted on the materials hybridgen's loader builds."""
from __future__ import annotations

import pytest

from hybridgen.io.mesh_loader import load_objects

# MTL statements -> (Roughness, Metallic, Specular IOR Level, IOR, Alpha, Transmission Weight), measured with
# bpy 4.2.0: bpy.ops.wm.obj_import of an OBJ with one triangle per material, the Principled BSDF's inputs printed.
MEASURED = {
    "kd_only": ("Kd 0.2 0.4 0.6", (1.0, 0.0, 0.0, 1.5, 1.0, 0.0)),
    "ns10": ("Ns 10\nillum 2", (0.9, 0.0, 1.0, 1.5, 1.0, 0.0)),
    "ns225": ("Ns 225\nillum 2", (0.5257, 0.0, 1.0, 1.5, 1.0, 0.0)),
    "ns324": ("Ns 324\nillum 2", (0.4308, 0.0, 1.0, 1.5, 1.0, 0.0)),
    "ns1500": ("Ns 1500\nillum 2", (0.0, 0.0, 1.0, 1.5, 1.0, 0.0)),
    "nsneg": ("Ns -5\nillum 2", (0.0, 0.0, 1.0, 1.5, 1.0, 0.0)),
    "ns_noillum": ("Ns 100", (0.6838, 0.0, 0.0, 1.5, 1.0, 0.0)),
    "il1": ("Ka 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 100\nillum 1", (0.6838, 0.0, 0.3, 1.5, 1.0, 0.0)),
    "il3": ("Ka 0.2 0.5 0.8\nKs 0.3 0.6 0.9\nNs 100\nillum 3", (0.6838, 0.5, 0.6, 1.5, 1.0, 0.0)),
    "il4": ("Ka 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 100\nillum 4", (0.6838, 0.5, 0.3, 1.5, 1.0, 0.0)),
    "il7": ("Ka 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 100\nillum 7", (0.6838, 0.5, 0.3, 1.0, 1.0, 0.0)),
    "il9": ("Ka 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 100\nillum 9", (0.6838, 0.0, 0.3, 1.5, 1.0, 0.0)),
    "il3_noka": ("illum 3", (1.0, 1.0, 0.0, 1.5, 1.0, 0.0)),
    "ni_il6": ("illum 6", (1.0, 1.0, 0.0, 1.0, 1.0, 0.0)),
    "ka_noillum": ("Ka 0.7 0.7 0.7", (1.0, 0.0, 0.0, 1.5, 1.0, 0.0)),
    "ks_big": ("Ks 1.5 1.5 1.5\nillum 2", (0.0, 0.0, 1.5, 1.5, 1.0, 0.0)),
    "ni2": ("Ni 2.0\nillum 2", (0.0, 0.0, 1.0, 2.0, 1.0, 0.0)),
    "d05": ("d 0.5", (1.0, 0.0, 0.0, 1.5, 0.5, 0.0)),
    "tr03": ("Tr 0.3", (1.0, 0.0, 0.0, 1.5, 1.0, 0.0)),
    "tr_d": ("Tr 0.3\nd 0.4", (1.0, 0.0, 0.0, 1.5, 0.4, 0.0)),
    "pbr": ("Pr 0.3\nPm 0.7\nNs 900\nKa 0.5 0.5 0.5\nillum 3", (0.3, 0.7, 0.0, 1.5, 1.0, 0.0)),
    "tf": ("Tf 0.2 0.3 0.4", (1.0, 0.0, 0.0, 1.5, 1.0, 0.3)),
    "blender_export": ("Ns 225.000000\nKa 1.000000 1.000000 1.000000\nKd 0.800000 0.800000 0.800000\n"
                       "Ks 0.500000 0.500000 0.500000\nKe 0.000000 0.000000 0.000000\nNi 1.450000\nd 1.000000\n"
                       "illum 2", (0.5257, 0.0, 0.5, 1.45, 1.0, 0.0)),
}


def test_mtl_values_load_as_blender_42_sets_them(tmp_path):
    obj = ["mtllib table.mtl"]
    for index, name in enumerate(MEASURED):
        first = 3 * index + 1
        obj += [f"o {name}", f"v {index} 0 0", f"v {index} 1 0", f"v {index} 0 1", f"usemtl {name}",
                f"f {first} {first + 1} {first + 2}"]
    (tmp_path / "table.mtl").write_text("".join(f"newmtl {n}\n{body}\n\n" for n, (body, _) in MEASURED.items()))
    (tmp_path / "table.obj").write_text("\n".join(obj) + "\n")
    loaded = {o.name: o.material for o in load_objects(tmp_path / "table.obj")}
    assert sorted(loaded) == sorted(MEASURED)
    for name, (_, expected) in MEASURED.items():
        material = loaded[name]
        got = (material.roughness, material.metallic, material.specular, material.ior, material.alpha,
               material.transmission)
        assert got == pytest.approx(expected, abs=5e-5), name
    assert loaded["kd_only"].base_color[:3] == pytest.approx((0.2, 0.4, 0.6))
    assert loaded["ns324"].emission_strength == 0.0
