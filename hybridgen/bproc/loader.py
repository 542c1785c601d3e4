"""``bproc.loader``: files and datasets into ``bproc.types`` objects (BlenderProc's loaders), one file per
family, every name re-exported here: :mod:`~hybridgen.bproc.loader_object` (``load_obj``),
:mod:`~hybridgen.bproc.loader_blend` (``load_blend``), :mod:`~hybridgen.bproc.loader_bop` (``load_bop_objs``,
``load_bop_scene``, ``load_bop_intrinsics``), :mod:`~hybridgen.bproc.loader_datasets` (ShapeNet, Pix3D, IKEA,
AMASS, Replica, SceneNet, 3D-FRONT, Matterport3D), :mod:`~hybridgen.bproc.loader_materials` (CC and Poly Haven
materials, textures, Haven HDRIs) and :mod:`~hybridgen.bproc.loader_urdf` (``load_urdf``). SUNCG (withdrawn by
its authors) and Replica's segmented meshes raise one line naming the call.
"""
from __future__ import annotations

from .loader_blend import load_blend
from .loader_datasets import (load_AMASS, load_front3d, load_ikea, load_matterport3d, load_pix3d, load_replica,
                              load_scenenet, load_shapenet)
from .loader_materials import (get_random_world_background_hdr_img_path_from_haven, load_ccmaterials, load_haven_mat,
                               load_texture)
from .loader_object import load_obj
from .types.unsupported import module_getattr

__all__ = ["get_random_world_background_hdr_img_path_from_haven", "load_AMASS", "load_blend", "load_bop_intrinsics",
           "load_bop_objs", "load_bop_scene", "load_ccmaterials", "load_front3d", "load_haven_mat", "load_ikea",
           "load_matterport3d", "load_obj", "load_pix3d", "load_replica", "load_replica_segmented_mesh",
           "load_scenenet", "load_shapenet",
           "load_texture", "load_urdf"]

# BOP's and URDF's loaders pull in hybridgen's BOP module and the URDF stack (~70 ms): imported when first used
__getattr__ = module_getattr("loader", ["load_suncg"],
                             lazy={"load_bop_intrinsics": "loader_bop", "load_bop_objs": "loader_bop",
                                   "load_replica_segmented_mesh": "loader_replica_segmented",
                                   "load_bop_scene": "loader_bop", "load_urdf": "loader_urdf"}, namespace=globals())
