"""Rigid-body physics (PyBullet, headless): drop objects until they rest (``object.PhysicsPositioning``).

PyBullet and CoACD are optional (``pip install hybridgen[physics]``); they are imported when a simulation
or a decomposition first needs them, with an actionable error when missing.

May import: ``hybridgen.scene``, ``io.cache_folder`` (the decomposition cache) and the top-level helpers.
"""
from __future__ import annotations

from .shapes import CollisionGeometry, DecompositionSettings, cache_dir, collision_geometry, convex_decomposition
from .settings import PhysicsResult, PhysicsSettings
from .simulate import simulate_physics

__all__ = ["CollisionGeometry", "DecompositionSettings", "PhysicsResult", "PhysicsSettings", "cache_dir",
           "collision_geometry", "convex_decomposition", "simulate_physics"]
