"""Renderer-agnostic scene model: meshes, materials, lights, camera and frame conventions."""
from .camera import Camera, Intrinsics
from .light import Light
from .material import Material
from .mesh_object import MeshObject
from .scene import Scene, World

__all__ = ["Camera", "Intrinsics", "Light", "Material", "MeshObject", "Scene", "World"]
