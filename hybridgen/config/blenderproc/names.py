"""BlenderProc module names: the hybridgen module each one runs as, and those hybridgen cannot provide (why, and
what to do instead)."""
from __future__ import annotations

ALIASES = {
    "loader.ObjectLoader": "loader.ObjLoader",
    "loader.PlyLoader": "loader.ObjLoader",
    "renderer.NormalRenderer": "renderer.SegMapRenderer",
    "renderer.DepthRenderer": "renderer.SegMapRenderer",
    "renderer.DistanceRenderer": "renderer.SegMapRenderer",
    "renderer.FlowRenderer": "renderer.SegMapRenderer",
    "object.PositionSampler": "object.ObjectPoseSampler",
    "manipulators.ObjectManipulator": "manipulators.EntityManipulator",
    "manipulators.LightManipulator": "manipulators.EntityManipulator",
    "manipulators.FloorExtractor": "object.FloorExtractor",
    "object.ObjectReplacer": "object.ObjectSwapper",
    "constructor.BasicMeshInitializer": "loader.PrimitiveLoader",
    "writer.ShapeNetWriter": "writer.ObjectStateWriter",  # the ids are attributes in object_states
}
"""BlenderProc module name -> the hybridgen module that does its work (keys translated below)."""

_DATASET = "convert its meshes to OBJ/glTF/PLY and load them with loader.ObjLoader"
UNAVAILABLE = {
    "loader.SuncgLoader": f"the SUNCG dataset was withdrawn by its authors and is not distributed; {_DATASET}",
    "lighting.SuncgLighting": "lights SUNCG scenes, a dataset that was withdrawn; use lighting.SurfaceLighting "
                              "with a selector for the lamp objects",
    "camera.SuncgCameraSampler": "samples cameras inside SUNCG rooms (a withdrawn dataset); use "
                                 "camera.CameraSampler with proximity_checks",
    "writer.StereoGlobalMatchingWriter": "stereo depth by SGM is not implemented; renderer.RgbRenderer with "
                                         "stereo: true writes exact per-eye depth instead",
    "loader.VisNormalImage": "a debugging view of Blender's normal images; view hybridgen's normals with "
                             "'hybridgen vis'",
    "writer.MyWriter": "an example of a user plugin; write it as a hybridgen plugin (entry point "
                       "'hybridgen.modules')",
}
"""Modules hybridgen cannot provide: one line why, and what to do instead."""
