"""bproc.renderer.enable_diffuse_color_output: ``diffuse`` is Cycles' Diffuse Color pass as 8-bit sRGB - a metal
square 0, a Specular IOR Level 0 square exactly its base color, a default dielectric what its specular layer leaves
(the path tracer's layer weight: tests/render/test_diffuse_color.py has it against Cycles), the world 0."""
from __future__ import annotations

import numpy as np

from writer_session import bproc  # noqa: F401 - the fixture


def _srgb8(linear: np.ndarray) -> np.ndarray:
    srgb = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
    return np.clip(np.rint(srgb * 255), 0, 255).astype(np.uint8)


def test_diffuse_output_is_cycles_diffuse_color(gl_context, bproc) -> None:  # noqa: F811
    base = [0.7, 0.35, 0.15, 1.0]
    squares = {}
    for name, x, inputs in (("metal", -2.2, {"Metallic": 1.0}), ("matte", 0.0, {"Specular IOR Level": 0.0}),
                            ("dielectric", 2.2, {"Roughness": 0.2})):
        square = bproc.object.create_primitive("PLANE", location=[x, 0, 0])
        material = square.new_material(name)
        material.set_principled_shader_value("Base Color", base)
        for key, value in inputs.items():
            material.set_principled_shader_value(key, value)
        squares[name] = x
    pose = np.eye(4)
    pose[:3, 3] = [0.0, 0.0, 6.0]  # looking down -Z
    bproc.camera.add_camera_pose(pose)
    bproc.renderer.enable_diffuse_color_output()
    data = bproc.renderer.render()
    diffuse = data["diffuse"][0]
    assert diffuse.dtype == np.uint8 and diffuse.shape == (24, 32, 3)
    K = bproc.camera.get_intrinsics_as_K_matrix()
    v, u = np.mgrid[0:24, 0:32]
    x, y = (u - K[0, 2]) / K[0, 0] * 6.0, -(v - K[1, 2]) / K[1, 1] * 6.0
    inside = {name: (np.abs(x - cx) < 0.85) & (np.abs(y) < 0.85) for name, cx in squares.items()}
    assert all(mask.sum() >= 4 for mask in inside.values())
    assert not diffuse[inside["metal"]].any()
    assert np.all(diffuse[inside["matte"]] == _srgb8(np.array(base[:3])))
    dielectric = diffuse[inside["dielectric"]].astype(int)
    # seen head-on at roughness 0.2, IOR 1.5 (Blender 4.2's default): the specular layer leaves 0.960 of the base
    # (principled_layers' weight, 0.95998; at IOR 1.45 it would be 0.966, with no layer 1)
    assert np.all(np.abs(dielectric - _srgb8(0.96 * np.array(base[:3]))) <= 1)
    assert np.all(dielectric < _srgb8(np.array(base[:3])))
    background = ~np.any(np.abs(x[..., None] - [-2.2, 0.0, 2.2]) < 1.05, axis=-1) | (np.abs(y) > 1.05)
    assert background.sum() > 50 and not diffuse[background].any()
