"""Denoising guides that look through sharp glass and mirrors, as Cycles' denoising albedo and normal passes do.

The raster guides (:mod:`hybridgen.render.denoise_guides`) show the first surface: a glass sphere is a white
disk with a sphere's normals, while the color shows the refracted floor. Open Image Denoise, told the guides
are clean, then smears the floor's texture seen through the glass. Cycles writes its denoising features at the
first surface that is not mostly *specular-like* (Blender 5.0's ``film_write_denoising_features_surface``,
Apache-2.0, read for its behaviour):

- a closure is specular-like when its GGX alpha (roughness squared) is at most :data:`SPECULAR_ALPHA` (0.075);
  diffuse closures never are;
- each closure weighs with its sample weight (its average albedo); if more than :data:`NONSPECULAR_SHARE`
  (a quarter) of the summed weight is not specular-like, the surface writes its features (camera-space normal,
  albedo times the throughput so far) and the path stops writing;
- otherwise the feature throughput is multiplied by the specular closures' albedo and the features are taken
  at the next hit of the path (which Cycles samples: reflection or refraction in proportion to their weights),
  up to the path's bounce limits; a path that ends first writes no features, and a path that escapes, or that
  went past a per-lobe limit (``glossy_bounces``/``transmission_bounces``) and then hits an emitter, adds that
  emission to the albedo and no normal.

Here the same rule runs deterministically on the supersampled guide sub-pixels whose raster object could be
specular-like: the camera ray through the sub-pixel centre is traced in the color's own Mitsuba scene, and at
a specular-like surface *both* branches are followed, reflection with weight ``F`` (dielectric, exact Fresnel)
or Schlick's ``F`` of the base color (metal), refraction with ``(1 - F)`` times the base color (glass),
while the normal is averaged with each branch's share of the sampling probability, as Cycles' sample mean
converges to. Albedo at the surface where features are written is its base color as the raster albedo draws
it (Mitsuba's ``eval_diffuse_reflectance``: base color, texture or vertex colors); escaping rays add the world
color (the raster background), and branches past a per-lobe limit that hit an emitting object add its base color
(the raster albedo of emitters). Every other sub-pixel keeps the raster value bit for bit, so scenes without
smooth specular materials cost nothing.

Principled closures and their sample weights (``m`` metallic, ``t`` transmission, ``F_s`` the dielectric
Fresnel of the specular layer, F0 = 0.08 x specular, ``F_g`` the glass Fresnel of ``ior``, ``F_m`` Schlick
with F0 = base color): diffuse ``(1-m)(1-t)(1-F_s) base``, specular layer ``(1-m)(1-t) F_s``, metal
``m F_m``, glass ``(1-m) t (F_g + (1-F_g) base)``; the last three are specular-like when roughness^2 <= 0.075.

Limits: objects with a roughness or metallic *texture* are treated as rough (their raster guides stay);
instanced geometry (Mitsuba shape groups, :mod:`hybridgen.render.pathtrace.mitsuba_instances`) is not looked through (its
hit shape is the group's mesh, not one object), and a branch that hits it writes its features there. JIT
variants only (``scalar_rgb`` keeps the raster guides).

Cost (materials scene of tools/color_quality.py, 160x120, guides 3 x 3 supersampled, ~16k of 173k sub-pixels
deferred, 4 ray launches): guide CPU 0.017 -> 0.09 s per frame on the loaded 2-core machine, against ~3.5 s
for the whole default color process; scenes without smooth specular materials run no ray. Dr.Jit compiles
each launch size once per process (its kernel cache on disk keeps them across processes).
"""
from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any, TypeVar

import numpy as np

from ...scene.camera import Intrinsics
from ...scene.scene import Scene
from .material_emission import emitted_radiance
from .surface_split import (NONSPECULAR_SHARE, SPECULAR_ALPHA, SurfaceLobes, SurfaceSplit, can_be_specular_like,
                            dielectric_fresnel, f0_to_eta, schlick, split_surface)

__all__ = ["NONSPECULAR_SHARE", "SPECULAR_ALPHA", "SpecularGuideTracer", "SurfaceLobes", "SurfaceSplit",
           "can_be_specular_like", "dielectric_fresnel", "f0_to_eta", "schlick", "split_surface"]

MIN_LAUNCH = 1024
"""Ray batches are padded to a power of two of at least this many rays, so that Dr.Jit, which compiles a
kernel per batch size, reuses a few kernels across bounces and keypoints (~0.1 s per new size)."""
MIN_BRANCH_WEIGHT = 0.01
"""Branches whose mean throughput falls below this are dropped (their share of the guide is lost): Cycles
follows one sampled path down to a throughput of 1e-4; following every branch, a glass sphere's second internal
reflection (~0.04^2) is not worth its rays."""


@dataclass
class _Branches:
    """Feature paths in flight: the guide sub-pixel each belongs to, ray, throughput, sampling probability,
    the bounces it has used (reflections, transmissions) and whether it went past a per-lobe bounce limit
    (``final``: the path tracer still adds what it hits next if that emits - the world or an emitter - and ends;
    Cycles likewise adds that emission to its denoising albedo, and writes no features there)."""

    pixel: np.ndarray
    origin: np.ndarray
    direction: np.ndarray
    weight: np.ndarray
    probability: np.ndarray
    reflections: np.ndarray
    transmissions: np.ndarray
    final: np.ndarray


@dataclass(frozen=True)
class _Hits:
    valid: np.ndarray
    point: np.ndarray
    normal: np.ndarray  # shading normal (unit)
    geometric: np.ndarray
    base: np.ndarray  # (N, 3)
    row: np.ndarray  # material row of the hit shape (-1: not one of the scene's plain meshes)


class SpecularGuideTracer:
    """Traces the guide sub-pixels that see a specular-like object through ``mi_scene`` (the color's Mitsuba
    scene, built from ``scene`` by :func:`hybridgen.render.pathtrace.mitsuba_scene.scene_dict`), with Cycles' bounce
    limits ``max_bounces`` / ``glossy_bounces`` / ``transmission_bounces`` (None: ``max_bounces``)."""

    def __init__(self, scene: Scene, mi_scene: Any, max_bounces: int, glossy_bounces: int | None = None,
                 transmission_bounces: int | None = None) -> None:
        import drjit as dr
        import mitsuba as mi

        self.scene, self.mi_scene = scene, mi_scene
        self.max_bounces = int(max_bounces)
        self.max_reflections = self.max_bounces if glossy_bounces is None else int(glossy_bounces)
        self.max_transmissions = self.max_bounces if transmission_bounces is None else int(transmission_bounces)
        objects = list(scene.objects)
        self.lobes = SurfaceLobes.of([obj.material for obj in objects])
        self.candidates = np.array(sorted(obj.instance_id for obj, ok in zip(objects, self.lobes.specular_like) if ok),
                                   dtype=np.int64)
        row_of_key = {f"object_{obj.instance_id}": row for row, obj in enumerate(objects)}
        shape_rows: dict[int, int] = {}  # Dr.Jit registry id of a plain mesh shape -> its object's row
        for shape in mi_scene.shapes():
            key = shape.id().removesuffix("_back")
            if key in row_of_key and isinstance(shape, mi.Mesh):
                shape_rows[int(dr.reinterpret_array(mi.UInt32, mi.ShapePtr(shape))[0])] = row_of_key[key]
        self._shape_lut = np.full(max(shape_rows, default=0) + 1, -1, dtype=np.int64)
        for shape_id, row in shape_rows.items():
            self._shape_lut[shape_id] = row
        self._row_lut = np.full(max((o.instance_id for o in objects), default=0) + 1, -1, dtype=np.int64)
        for row, obj in enumerate(objects):
            self._row_lut[obj.instance_id] = row
        self.world_color = np.asarray(scene.world.color, dtype=np.float64)[:3]
        self.emissive = np.array([bool(np.any(emitted_radiance(obj) > 0)) for obj in objects] + [False])  # [-1]: none

    @property
    def active(self) -> bool:
        """Whether any object can be specular-like (otherwise :meth:`apply` changes nothing)."""
        return len(self.candidates) > 0

    def apply(self, cam2world: np.ndarray, fine: Intrinsics, instance_ids: np.ndarray, albedo: np.ndarray,
              normals: np.ndarray) -> int:
        """Replace, in place, the supersampled raster ``albedo`` and camera-space ``normals`` (fine H x W x 3,
        ``instance_ids`` fine H x W) where the first surface defers its features; returns how many sub-pixels
        were replaced.

        Which sub-pixels defer is decided from the raster's own first surface (object, base color, normal), so
        the others are untouched bit for bit and cost no ray; deferred ones are traced from the camera."""
        if not self.active:
            return 0
        ids = instance_ids.reshape(-1).astype(np.int64)
        pixels = np.flatnonzero(np.isin(ids, self.candidates))
        if len(pixels) == 0:
            return 0
        cam2world = np.asarray(cam2world, dtype=np.float64)
        rotation, centre = cam2world[:3, :3], cam2world[:3, 3]
        u, v = pixels % fine.width + 0.5, pixels // fine.width + 0.5
        rays = np.linalg.solve(fine.K, np.stack([u, v, np.ones_like(u)])).T  # OpenCV camera axes, z = 1
        base = albedo.reshape(-1, 3)[pixels].astype(np.float64)
        facing = normals.reshape(-1, 3)[pixels].astype(np.float64) @ rotation.T  # world axes, towards the camera
        direction = rays @ rotation.T
        direction /= np.linalg.norm(direction, axis=1, keepdims=True)
        rows = self._row_lut[np.clip(ids[pixels], 0, len(self._row_lut) - 1)]
        split = split_surface(_take(self.lobes, rows), base,
                              np.clip(-np.einsum("ij,ij->i", direction, facing), 1e-6, 1.0), np.zeros(len(rows), bool))
        deferred = ~split.features_here
        pixels, direction, rows = pixels[deferred], direction[deferred], rows[deferred]
        n = len(pixels)
        if n == 0:
            return 0
        paths = _Branches(np.arange(n), np.tile(centre, (n, 1)), direction, np.ones((n, 3)), np.ones(n),
                          np.zeros(n, np.int64), np.zeros(n, np.int64), np.zeros(n, bool))
        # Traced again from the camera: a raster normal and depth are float32, and a refraction through a curved
        # surface magnifies their rounding into visible steps.
        hits = self._intersect(paths.origin, paths.direction)
        same = hits.valid & (hits.row == rows)  # else (a silhouette sub-pixel) the raster values stay
        cos_signed = -np.einsum("ij,ij->i", paths.direction, hits.normal)
        facing = np.where((cos_signed < 0)[:, None], -hits.normal, hits.normal)
        split = split_surface(_take(self.lobes, np.maximum(hits.row, 0)), hits.base, np.abs(cos_signed), cos_signed < 0)
        keep = same & ~split.features_here
        pixels, paths, hits, split, facing = (pixels[keep], _take(paths, keep), _take(hits, keep),
                                              _take(split, keep), facing[keep])
        n = len(pixels)
        paths.pixel = np.arange(n)
        paths = self._children(paths, hits, split, facing)
        out_albedo, out_normal = np.zeros((n, 3)), np.zeros((n, 3))
        while len(paths.pixel):
            hits = self._intersect(paths.origin, paths.direction)
            escaped = ~hits.valid
            add_at(out_albedo, paths.pixel[escaped], paths.weight[escaped] * self.world_color)
            paths, hits = _take(paths, ~escaped), _take(hits, ~escaped)
            glowing = paths.final & self.emissive[hits.row]  # past a lobe limit: only an emitter still shows
            add_at(out_albedo, paths.pixel[glowing], paths.weight[glowing] * hits.base[glowing])
            paths, hits = _take(paths, ~paths.final), _take(hits, ~paths.final)
            lobes = _take(self.lobes, np.maximum(hits.row, 0))
            lobes = SurfaceLobes(lobes.metallic, lobes.transmission, lobes.specular_f0, lobes.ior,
                                 lobes.specular_like & (hits.row >= 0))
            cos_signed = -np.einsum("ij,ij->i", paths.direction, hits.normal)
            inside = cos_signed < 0
            facing = np.where(inside[:, None], -hits.normal, hits.normal)
            split = split_surface(lobes, hits.base, np.abs(cos_signed), inside)
            here = split.features_here
            add_at(out_albedo, paths.pixel[here], paths.weight[here] * hits.base[here])
            add_at(out_normal, paths.pixel[here], paths.probability[here, None] * (facing[here] @ rotation))
            go = ~here
            paths, hits, split, facing = (_take(paths, go), _take(hits, go), _take(split, go), facing[go])
            paths = self._children(paths, hits, split, facing)
        albedo.reshape(-1, 3)[pixels] = out_albedo
        normals.reshape(-1, 3)[pixels] = out_normal
        return n

    def _children(self, paths: _Branches, hits: _Hits, split: SurfaceSplit, facing: np.ndarray) -> _Branches:
        """Reflected and refracted continuations of ``paths`` (each within its bounce limits and weight)."""
        d = paths.direction
        cos_i = -np.einsum("ij,ij->i", d, facing)
        mirror = d + 2 * cos_i[:, None] * facing
        refracted = d / split.eta[:, None] + (cos_i / split.eta - split.cos_t)[:, None] * facing
        refracted /= np.maximum(np.linalg.norm(refracted, axis=1, keepdims=True), 1e-12)
        total = split.reflect.mean(1) + split.refract.mean(1)
        bounces = paths.reflections + paths.transmissions
        parts = []
        for factor, new_dir, reflected in ((split.reflect, mirror, True), (split.refract, refracted, False)):
            weight = paths.weight * factor
            reflections = paths.reflections + int(reflected)
            transmissions = paths.transmissions + int(not reflected)
            ok = (weight.mean(1) > MIN_BRANCH_WEIGHT) & (bounces < self.max_bounces)
            final = (reflections > self.max_reflections) | (transmissions > self.max_transmissions)
            side = np.where(np.einsum("ij,ij->i", new_dir, hits.geometric) >= 0, 1.0, -1.0)
            scale = 1e-4 * (1.0 + np.abs(hits.point).max(axis=1))
            origin = hits.point + (side * scale)[:, None] * hits.geometric
            share = np.where(total > 0, factor.mean(1) / np.where(total > 0, total, 1.0), 0.0)
            parts.append(_Branches(paths.pixel[ok], origin[ok], new_dir[ok], weight[ok],
                                   (paths.probability * share)[ok], reflections[ok], transmissions[ok], final[ok]))
        return _Branches(**{f.name: np.concatenate([getattr(p, f.name) for p in parts]) for f in fields(_Branches)})

    def _intersect(self, origin: np.ndarray, direction: np.ndarray) -> _Hits:
        import drjit as dr
        import mitsuba as mi

        if len(origin) == 0:
            empty = np.zeros((0, 3))
            return _Hits(np.zeros(0, bool), empty, empty, empty, empty, np.zeros(0, np.int64))
        count = len(origin)
        size = max(MIN_LAUNCH, 1 << (count - 1).bit_length())  # padded: Dr.Jit compiles a kernel per size
        origin, direction = (np.concatenate([x, np.repeat(x[:1], size - count, axis=0)]).T.astype(np.float32)
                             for x in (origin, direction))
        ray = mi.Ray3f(mi.Point3f(*origin), mi.Vector3f(*direction))
        si = self.mi_scene.ray_intersect(ray)
        base, valid = si.bsdf().eval_diffuse_reflectance(si), si.is_valid()
        shapes = dr.reinterpret_array(mi.UInt32, si.shape)
        dr.eval(base, valid, shapes, si.p, si.n, si.sh_frame.n)  # one kernel (each read would launch its own)
        valid = np.array(valid, dtype=bool)
        shape_ids = np.array(shapes, dtype=np.int64)
        known = shape_ids < len(self._shape_lut)  # else an instanced shape's mesh (-1); a miss is id 0 (-1)
        row = np.where(known, self._shape_lut[np.where(known, shape_ids, 0)], -1)
        as_rows = lambda value: np.array(value, dtype=np.float64).T.reshape(-1, 3)[:count]  # noqa: E731
        normal, geometric = as_rows(si.sh_frame.n), as_rows(si.n)
        return _Hits(valid[:count], as_rows(si.p), normal, geometric, np.clip(as_rows(base), 0.0, None), row[:count])


def add_at(target: np.ndarray, index: np.ndarray, values: np.ndarray) -> None:
    """``target[index] += values`` with repeated indices summed."""
    if len(index):
        np.add.at(target, index, values)


_Rows = TypeVar("_Rows", "SurfaceLobes", "SurfaceSplit", "_Branches", "_Hits")


def _take(record: _Rows, keep: np.ndarray) -> _Rows:
    """The lanes ``keep`` (a mask or indices) of every per-lane array field of ``record``."""
    return type(record)(**{f.name: getattr(record, f.name)[keep] for f in fields(record)})
