"""``bproc.lighting``: none of BlenderProc's three lighting helpers is implemented yet (each raises one line);
lights are made with ``bproc.types.Light``."""
from __future__ import annotations

from .types.unsupported import module_getattr

__getattr__ = module_getattr("lighting", ["light_suncg_scene", "light_surface",
                                          "add_intersecting_spot_lights_to_camera_poses"])
