"""``bproc.types``: BlenderProc 2's object model over hybridgen's scene model (one module per type).

Stable interface for the other ``hybridgen.bproc`` modules (sampler, math, postprocessing):

- :class:`Struct` - ``get_name()/set_name()``, custom properties ``set_cp/get_cp/has_cp/del_cp/get_all_cps``,
  ``get_attr(name)``.
- :class:`Entity` - Blender object pose: ``get_location/set_location``, ``get_rotation_euler/set_rotation_euler``
  (Blender XYZ Euler, rad), ``get_scale``, ``get_local2world_mat()/set_local2world_mat(4x4)``, parents,
  ``world_matrix(frame)``, ``hide()``; keyable with ``frame=``.
- :class:`MeshObject` - an Entity with ``parts`` (hybridgen meshes in the object's local frame, metres),
  ``local_vertices()``, ``get_bound_box(local_coords=False)`` (8x3, Blender's corner order), material slots.
- :class:`Light` - an Entity with type, energy (W), color, radius.
- :class:`Material` - a Principled material (``blender_obj`` is the hybridgen material).
"""
from .entity import Entity
from .light import Light
from .material import Material
from .mesh_object import MeshObject
from .struct import Struct
from .unsupported import module_getattr

__all__ = ["Entity", "Light", "Material", "MeshObject", "Struct"]

__getattr__ = module_getattr("types", ["Armature"], namespace=globals(),
                             lazy={"URDFObject": "urdf_object", "Link": "urdf_link", "Inertial": "urdf_link"})
"""``URDFObject`` (``bproc.loader.load_urdf``'s robots) and its ``Link`` / ``Inertial`` parts (BlenderProc's
``LinkUtility`` / ``InertialUtility``) are imported on first use. ``Armature`` (Blender's bone objects) is a stand-in:
one line for a BlenderProc call hybridgen does not implement, ``bproc.<area>.<name> is not supported by hybridgen
yet``. Never a silent no-op: such a call would change BlenderProc's output, so it stops the script (exit status 2
under ``hybridgen run``)."""
