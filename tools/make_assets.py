"""Regenerates the small example assets in configs/assets/ (deterministic; run once, outputs committed).

- knot.obj: a trefoil-knot tube with vertex normals and UVs (u along the tube, v around it), knot.mtl/png
- crate.obj: a unit cube with one UV square per face, crate.mtl + crate.png (planks texture)
"""
from __future__ import annotations

from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

ASSETS = Path(__file__).resolve().parents[1] / "configs" / "assets"


def _write_obj(path: Path, vertices: np.ndarray, normals: np.ndarray | None, uvs: np.ndarray,
               faces: np.ndarray, material: str) -> None:
    # OBJ files are +Y up (Blender's importer reads them with axis_forward -Z, axis_up Y): world (x, y, z)
    # is written as (x, z, -y), so the object loads back Z-up exactly as modelled here.
    lines = [f"mtllib {path.stem}.mtl", f"o {path.stem}"]
    lines += [f"v {x:.6f} {z:.6f} {-y + 0.0:.6f}" for x, y, z in vertices]
    lines += [f"vt {u:.6f} {v:.6f}" for u, v in uvs]
    if normals is not None:
        lines += [f"vn {x:.6f} {z:.6f} {-y + 0.0:.6f}" for x, y, z in normals]
    lines.append(f"usemtl {material}")
    for tri in faces + 1:
        if normals is not None:
            lines.append("f " + " ".join(f"{i}/{i}/{i}" for i in tri))
        else:
            lines.append("f " + " ".join(f"{i}/{i}" for i in tri))
    path.write_text("\n".join(lines) + "\n")


def _write_mtl(path: Path, material: str, texture: str) -> None:
    path.write_text(f"newmtl {material}\nKd 1.0 1.0 1.0\nKs 0.0 0.0 0.0\nmap_Kd {texture}\n")


def knot() -> None:
    rings, sides, radius = 200, 16, 0.4
    t = np.linspace(0, 2 * np.pi, rings, endpoint=False)
    path = np.stack([np.sin(t) + 2 * np.sin(2 * t), np.cos(t) - 2 * np.cos(2 * t), -np.sin(3 * t)], 1)
    tangent = np.gradient(path, axis=0)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    binormal = np.cross(tangent, [0.0, 0.0, 1.0])
    binormal /= np.linalg.norm(binormal, axis=1, keepdims=True)
    normal = np.cross(binormal, tangent)
    angle = np.linspace(0, 2 * np.pi, sides + 1)  # seam duplicated for UVs
    ring = np.cos(angle)[None, :, None] * normal[:, None] + np.sin(angle)[None, :, None] * binormal[:, None]
    ring = np.concatenate([ring, ring[:1]], axis=0)  # closing ring duplicated for UVs
    centre = np.concatenate([path, path[:1]], axis=0)
    vertices = (centre[:, None] + radius * ring).reshape(-1, 3)
    normals = ring.reshape(-1, 3)
    u, v = np.meshgrid(np.linspace(0, 8, rings + 1), np.linspace(0, 1, sides + 1), indexing="ij")
    uvs = np.stack([u.ravel(), v.ravel()], 1)
    cols = sides + 1
    faces = []
    for i in range(rings):
        for j in range(sides):
            a, b, c, d = i * cols + j, i * cols + j + 1, (i + 1) * cols + j, (i + 1) * cols + j + 1
            faces += [[a, d, c], [a, b, d]]
    _write_obj(ASSETS / "knot.obj", vertices, normals, uvs, np.array(faces), "knot_stripes")
    _write_mtl(ASSETS / "knot.mtl", "knot_stripes", "knot.png")
    image = np.zeros((64, 64, 3), np.uint8)
    image[:] = (200, 140, 30)
    image[:, ::16] = (40, 60, 160)
    image[:, 1::16] = (40, 60, 160)
    Image.fromarray(np.ascontiguousarray(image.transpose(1, 0, 2))).save(ASSETS / "knot.png")


def crate() -> None:
    corners = {"+x": ([1, -1, -1], [1, 1, -1], [1, 1, 1], [1, -1, 1]),
               "-x": ([-1, 1, -1], [-1, -1, -1], [-1, -1, 1], [-1, 1, 1]),
               "+y": ([1, 1, -1], [-1, 1, -1], [-1, 1, 1], [1, 1, 1]),
               "-y": ([-1, -1, -1], [1, -1, -1], [1, -1, 1], [-1, -1, 1]),
               "+z": ([-1, -1, 1], [1, -1, 1], [1, 1, 1], [-1, 1, 1]),
               "-z": ([-1, 1, -1], [1, 1, -1], [1, -1, -1], [-1, -1, -1])}
    vertices, uvs, faces = [], [], []
    for quad in corners.values():
        base = len(vertices)
        vertices += [np.array(c, float) * 0.5 for c in quad]
        uvs += [[0, 0], [1, 0], [1, 1], [0, 1]]
        faces += [[base, base + 1, base + 2], [base, base + 2, base + 3]]
    _write_obj(ASSETS / "crate.obj", np.array(vertices), None, np.array(uvs, float), np.array(faces), "planks")
    _write_mtl(ASSETS / "crate.mtl", "planks", "crate.png")
    image = Image.new("RGB", (128, 128), (150, 100, 55))
    draw = ImageDraw.Draw(image)
    for y in range(0, 128, 32):
        draw.rectangle([0, y, 127, y + 2], fill=(70, 45, 20))
    draw.rectangle([0, 0, 127, 127], outline=(60, 40, 18), width=6)
    draw.line([0, 0, 127, 127], fill=(90, 60, 28), width=8)
    image.save(ASSETS / "crate.png")


if __name__ == "__main__":
    ASSETS.mkdir(parents=True, exist_ok=True)
    knot()
    crate()
    print(f"wrote assets to {ASSETS}")
