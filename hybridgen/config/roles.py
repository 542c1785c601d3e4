"""The roles a config's modules play in a run (declared by each module class, read by the parser and the planner)."""
from __future__ import annotations

import enum


class Role(enum.Enum):
    """What a module does to a run. Setup, loaders and manipulators build the scene; renderers render the
    scene's keypoints into the sinks; writers collect what the renderers before them made and commit files."""

    SETUP = "setup"  # run-wide settings: seed, defaults, number of scenes
    LOADER = "loader"  # adds objects, lights, cameras or materials
    MANIPULATOR = "manipulator"  # samples or changes what is there (poses, materials, cameras, visibility)
    RENDERER = "renderer"
    WRITER = "writer"

    @property
    def builds_scene(self) -> bool:
        """Whether modules of this role build the scene: the same for every work unit of a scene, so they run
        once per scene (and, run before the first renderer, once per process for consecutive units)."""
        return self not in (Role.RENDERER, Role.WRITER)
