"""Renderer-agnostic scene model: meshes, materials, lights, camera and frame conventions.

May import: the top-level helpers (errors, input paths), the notice channel (``config.notices``) and, for
displacement maps, render's material-map decoding (``render.material_textures``); every other package builds on it.
"""
from .camera import Camera, Intrinsics
from .light import Light
from .material import Material
from .mesh_object import MeshObject
from .scene import Scene, World

__all__ = ["Camera", "Intrinsics", "Light", "Material", "MeshObject", "Scene", "World"]
