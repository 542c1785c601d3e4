"""The GL resources of each scene object in the raster view: vertex and index buffers, the vertex array of the
label program, cut-out textures, triangle clusters and face planes - uploaded once per view, released by the view
(:meth:`hybridgen.render.raster.raster_view.RasterView.release`)."""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..shared_geometry import geometry_key
from .alpha_cutout import Cutout, upload_cutout
from .cluster_cache import mesh_clusters
from .face_planes import mesh_face_planes
from .triangle_clusters import TriangleClusters


@dataclass
class GpuObject:
    """GL resources of one scene object (vertex positions and indices are shared with other passes)."""

    instance_id: int
    vao: Any  # drawn by the default label program (or its cut-out variant)
    content: list[tuple[Any, str, str]]  # (buffer, format, attribute) of every vertex attribute
    positions: Any
    indices: Any
    buffers: list[Any]
    vertex_order: np.ndarray | None  # mesh vertex of each GPU vertex (flat meshes), None: the same order
    closed: bool
    bounds: np.ndarray  # (2, 3) local box
    cutout: Cutout | None = None  # alpha cut-out of a CLIP material (render/raster/alpha_cutout.py)
    packed_vaos: dict[Any, Any] = dataclasses.field(default_factory=dict)  # (LabelTargets, cutout) -> vao
    clusters: TriangleClusters | None = None  # large meshes: culled per keypoint (render/raster/triangle_clusters.py)
    indirect: Any = None  # the draw-command buffer of the kept clusters
    planes: Any = None  # storage buffer of the triangles' planes (exact depth: render/raster/face_planes.py)


def upload_objects(ctx: Any, objects: list[Any], program_for: Callable[[bool], Any], triangle_bases: Any,
               cull_clusters: bool) -> list[GpuObject]:
    """GPU objects of ``objects``; placements of shared geometry (render/shared_geometry.py) draw from the
    buffers of its first placement. ``program_for(cutout)`` gives the label program an object is drawn with (the
    view builds the cut-out variant on first use); ``triangle_bases``: the exact-depth index buffer, or None."""
    uploaded: list[GpuObject] = []
    first: dict[Any, GpuObject] = {}
    for obj in objects:
        key = geometry_key(obj)
        if key in first:  # shares the first placement's vertex arrays (packed ones included)
            uploaded.append(dataclasses.replace(first[key], instance_id=obj.instance_id, buffers=[],
                                                packed_vaos=first[key].packed_vaos))
            continue
        uploaded.append(upload_object(ctx, obj, program_for, triangle_bases, cull_clusters))
        if key is not None:
            first[key] = uploaded[-1]
    return uploaded

def upload_object(ctx: Any, obj: Any, program_for: Callable[[bool], Any], triangle_bases: Any,
              cull_clusters: bool) -> GpuObject:
    """GPU buffers of ``obj``: smooth meshes as they are; flat ones with a vertex per face corner that
    carries the face normal (``vertex_order`` maps GPU vertices back to mesh vertices)."""
    if obj.vertex_normals is not None:
        vertex_order = None
        vertices, normals, faces = obj.vertices, obj.vertex_normals, obj.faces
    else:
        vertex_order = obj.faces.ravel()
        vertices = obj.vertices[vertex_order]
        normals = np.repeat(obj.face_normals, 3, axis=0)
        faces = np.arange(len(vertex_order)).reshape(-1, 3)
    positions = ctx.buffer(vertices.astype(np.float32).tobytes())
    normal_buffer = ctx.buffer(normals.astype(np.float32).tobytes())
    indices = ctx.buffer(faces.astype(np.uint32).tobytes())
    cutout = upload_cutout(ctx, obj, vertex_order)
    content = [(positions, "3f", "in_position"), (normal_buffer, "3f", "in_normal")]
    planes = None
    if triangle_bases is not None:  # each triangle's plane, indexed from the draw's first triangle
        planes = ctx.buffer(mesh_face_planes(obj.vertices, obj.faces).tobytes())
        content.append((triangle_bases, "1u/i", "in_triangle_base"))
    program = program_for(cutout is not None)
    if cutout is not None:
        if cutout.uv_buffer is not None:
            content.append((cutout.uv_buffer, "2f", "in_uv"))
    vao = ctx.vertex_array(program, content, index_buffer=indices, index_element_size=4)
    extra = cutout.resources() if cutout is not None else []
    if planes is not None:
        extra.append(planes)
    # the clusters of obj's triangles (those of a flat mesh's corner vertices are the same), built once
    clusters, indirect = (mesh_clusters(obj.vertices, obj.faces) if cull_clusters else None), None
    if clusters is not None:
        indirect = ctx.buffer(reserve=20 * clusters.size)
        extra.append(indirect)
    # a cut-out volume shows its inside through its holes: never culled
    return GpuObject(obj.instance_id, vao, content, positions, indices, [positions, normal_buffer, indices, *extra],
                     vertex_order, obj.is_closed and cutout is None, obj.bounds_local, cutout,
                     clusters=clusters if indirect is not None else None, indirect=indirect, planes=planes)
