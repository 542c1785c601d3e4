"""Blender's default anisotropy tangent (render/pathtrace/principled_tangent.py): the radial-Z tangent of Cycles'
Tangent node on the generated coordinates (texture space = the mesh's bounding box), in world axes, and the
Principled BSDF's anisotropy frame built from it at a real hit. Against Cycles: the sweep's anisotropic metal
sphere is in tests/render/test_principled_vs_cycles.py's second test view."""
from __future__ import annotations

import math

import numpy as np
import pytest

from hybridgen.render.pathtrace.principled_tangent import needs_radial_tangent, radial_tangents
from hybridgen.scene.frames import object_pose
from hybridgen.scene.material import Material


def test_radial_tangent_of_the_generated_coordinates() -> None:
    """T = (-(g_y - 1/2), g_x - 1/2, 0) with g the position in the bounding box (centre (1, -2, 0.5), half sizes
    (2, 0.5, 0.5)), turned by the object's rotation and scaled by its scale."""
    vertices = np.array([[-1.0, -2.5, 0.0], [3.0, -1.5, 1.0], [2.0, -2.0, 0.25], [1.0, -1.5, 0.5]])
    pose = object_pose([5.0, 0.0, 0.0], [0.0, 0.0, math.pi / 2], [2.0, 1.0, 1.0])
    g = (vertices - [1.0, -2.0, 0.5]) / (2.0 * np.array([2.0, 0.5, 0.5]))
    local = np.stack([-g[:, 1], g[:, 0], np.zeros(4)], axis=1)
    expected = local * [2.0, 1.0, 1.0]  # scaled along local x, then turned by +90 degrees about z
    expected = np.stack([-expected[:, 1], expected[:, 0], expected[:, 2]], axis=1)
    np.testing.assert_allclose(radial_tangents(vertices, pose), expected, atol=1e-6)
    flat = radial_tangents(np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]]), np.eye(4))  # y extent 0: half size 1
    np.testing.assert_allclose(flat, [[0.0, -0.5, 0.0], [0.0, 0.5, 0.0]], atol=1e-7)
    assert needs_radial_tangent(Material(extra={"anisotropic": 0.5}))
    assert not needs_radial_tangent(Material(extra={"anisotropic": 0.0})) and not needs_radial_tangent(Material())


def test_the_bsdf_turns_its_anisotropy_to_the_radial_tangent(jit_variant: str) -> None:
    """At a hit on a sphere whose mesh carries the tangent, the anisotropic BSDF equals the same BSDF evaluated
    in a shading frame whose first axis is the tangent made perpendicular to the normal (then turned by the
    rotation) - and differs from the frame of the mesh's own dP/du."""
    import drjit as dr
    import mitsuba as mi

    import hybridgen as hg
    from hybridgen.render.pathtrace.mitsuba_scene import mesh_shape
    from hybridgen.render.pathtrace.principled_bsdf import PLUGIN_NAME, register

    mi.set_variant(jit_variant)
    register(jit_variant)
    ball = hg.make_primitive("sphere", 0.5, name="ball", local2world=object_pose([0.3, -0.2, 1.0], [0.4, 0.2, 0.0]))
    ball.material.metallic, ball.material.roughness = 1.0, 0.35
    ball.material.extra = {"anisotropic": 0.8, "anisotropic_rotation": 0.1}
    scene = mi.load_dict({"type": "scene", "ball": mesh_shape(ball)})
    origins = np.array([[0.3 + dx, -0.2 + dy, 3.0] for dx in (-0.1, 0.05, 0.12) for dy in (-0.08, 0.0, 0.1)])
    ray = mi.Ray3f(mi.Point3f(origins.T.astype(np.float32)), mi.Vector3f(0.0, 0.0, -1.0))
    si = scene.ray_intersect(ray)
    assert bool(dr.all(si.is_valid()))
    bsdf = si.bsdf()
    wo = dr.normalize(si.sh_frame.n + mi.Vector3f(0.3, -0.2, 0.1))
    value = np.array(bsdf.eval(mi.BSDFContext(), si, si.to_local(wo)))
    centre = np.array([0.3, -0.2, 1.0])  # the tangent about the object's z axis, from the world position
    axis = ball.local2world[:3, :3] @ [0.0, 0.0, 1.0]
    tangent = np.cross(axis, np.array(si.p).T - centre)
    normal = np.array(si.sh_frame.n).T
    tangent -= normal * np.sum(tangent * normal, axis=1, keepdims=True)
    tangent /= np.linalg.norm(tangent, axis=1, keepdims=True)
    angle = 2.0 * math.pi * 0.1  # Anisotropic Rotation 0.1 turns, about the normal
    turned = tangent * math.cos(angle) + np.cross(normal, tangent) * math.sin(angle)
    plain = mi.load_dict({"type": PLUGIN_NAME, "base_color": {"type": "rgb", "value": [0.8, 0.8, 0.8]},
                          "roughness": 0.35, "metallic": 1.0, "anisotropic": 0.8})
    framed = dr.zeros(mi.SurfaceInteraction3f, 9)
    framed.sh_frame = mi.Frame3f(mi.Vector3f(turned.T.astype(np.float32)), mi.Vector3f(
        np.cross(normal, turned).T.astype(np.float32)), si.sh_frame.n)
    framed.wi = framed.sh_frame.to_local(si.to_world(si.wi))
    expected = np.array(plain.eval(mi.BSDFContext(), framed, framed.sh_frame.to_local(wo)))
    np.testing.assert_allclose(value, expected, rtol=2e-3)
    own = dr.zeros(mi.SurfaceInteraction3f, 9)  # the mesh's own frame (what hybridgen used before) differs
    own.sh_frame, own.wi = si.sh_frame, si.wi
    assert not np.allclose(np.array(plain.eval(mi.BSDFContext(), own, si.to_local(wo))), expected, rtol=0.02)


@pytest.mark.parametrize("anisotropic", [0.0, 0.5])
def test_anisotropic_objects_are_not_instanced(jit_variant: str, anisotropic: float) -> None:
    """Mitsuba's instances do not carry a mesh attribute into world axes: objects sharing geometry (the same
    arrays and material) are instanced unless their material is anisotropic."""
    import copy

    import mitsuba as mi

    import hybridgen as hg
    from hybridgen.render.pathtrace.mitsuba_scene import scene_dict

    mi.set_variant(jit_variant)
    scene = hg.Scene()
    first = hg.make_primitive("cube", 0.3, name="c0")
    first.material.metallic, first.material.extra = 1.0, {"anisotropic": anisotropic}
    for index in range(3):
        obj = copy.copy(first)
        obj.name, obj.local2world = f"c{index}", object_pose([index * 0.5, 0.0, 0.0])
        scene.add(obj)
    kinds = [entry.get("type") for entry in scene_dict(scene).values() if isinstance(entry, dict)]
    assert ("instance" in kinds) == (anisotropic == 0.0)
