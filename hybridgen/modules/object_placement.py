"""``object.ObjectPoseSampler`` and ``object.OnSurfaceSampler``: collision-free placement of selected
objects (exact mesh-mesh tests), poses from samplers drawn per try."""
from __future__ import annotations

from typing import Any

import numpy as np

from ..config.registry import register_module
from ..config.schema import Param, positive
from ..errors import InputError
from ..run.context import RunContext
from ..sampling.getters import parse_selector
from ..scene.frames import object_pose
from ..sampling.placement import (PlacementResult, SurfaceProbe, check_spacing, rest_on_surface, sample_poses,
                                  scale_of)
from .base import Role
from .selecting import SelectingModule

_COMMON = (
    Param("objects_to_sample", "dict|list", doc="which objects to place (getter.Entity conditions)"),
    Param("rot_sampler", "vec3", [0.0, 0.0, 0.0], "rad", "Euler XYZ rotation per try", sampleable=True),
    Param("max_iterations", "int", 1000, doc="tries per object", check=positive),
    Param("on_failure", "str", "error", choices=("error", "warn"),
          doc="an object without a valid pose: error, or warn and leave it where it was"),
)


class _Placer(SelectingModule):
    role = Role.MANIPULATOR
    selector_key = "objects_to_sample"

    def _report(self, context: RunContext, result: PlacementResult) -> None:
        message = f"{self.module_name}: placed {len(result.placed)} object(s) in {result.tries} tries"
        if result.failed:
            names = ", ".join(repr(o.name) for o in result.failed)
            detail = f"no collision-free pose for {names} in {self.config['max_iterations']} tries"
            if self.config["on_failure"] == "error":
                raise InputError(detail + "; enlarge the sampling region or raise max_iterations")
            context.log(f"{self.module_name}: {detail}; left where they were", "warning")
        context.log(message)


@register_module("object.ObjectPoseSampler")
class ObjectPoseSampler(_Placer):
    """Samples poses until each selected object intersects no other (nor those placed before it)."""

    params = (
        *_COMMON,
        Param("pos_sampler", "vec3", doc="location per try (usually a sampler)", sampleable=True),
        Param("objects_to_check_collisions", "dict|list|null", None,
              doc="obstacles (default: every other object)"),
    )

    def run(self, context: RunContext) -> None:
        objects = self.selected(context)
        obstacles = parse_selector(self.config["objects_to_check_collisions"], "objects_to_check_collisions") \
            .select(context.scene.objects, context.rng)

        def propose(obj: Any) -> np.ndarray:
            return object_pose(self.value(context, "pos_sampler"), self.value(context, "rot_sampler"), scale_of(obj))

        self._report(context, sample_poses(objects, obstacles, propose, self.config["max_iterations"]))


@register_module("object.OnSurfaceSampler")
class OnSurfaceSampler(_Placer):
    """Places selected objects resting on top of a surface object, apart from each other, without collisions."""

    params = (
        *_COMMON,
        Param("surface", "dict|list", doc="the one object to place on (getter.Entity conditions)"),
        Param("pos_sampler", "vec3|null", None, sampleable=True,
              doc="x, y per try (z is found by dropping onto the surface); default: uniform over its top face"),
        Param("min_distance", "float", 0.0, "m", "least XY distance to the nearest placed object"),
        Param("max_distance", "float", 1e9, "m", "greatest XY distance to the nearest placed object"),
    )

    def run(self, context: RunContext) -> None:
        surfaces = parse_selector(self.config["surface"], "surface").select(context.scene.objects, context.rng)
        if len(surfaces) != 1:
            raise InputError(f"surface must select exactly one object, got {len(surfaces)}")
        surface = surfaces[0]
        objects = [o for o in self.selected(context) if o is not surface]
        probe = SurfaceProbe(surface)
        corners = surface.world_vertices()
        low, high = corners.min(axis=0), corners.max(axis=0)

        def propose(obj: Any) -> np.ndarray | None:
            location = self.value(context, "pos_sampler")
            if location is None:
                location = [*context.rng.uniform(low[:2], high[:2]), high[2]]
            return rest_on_surface(obj, probe, np.asarray(location, float),
                                   np.asarray(self.value(context, "rot_sampler"), float))

        spacing = check_spacing(self.config["min_distance"], self.config["max_distance"])
        self._report(context, sample_poses(objects, context.scene.objects, propose,
                                           self.config["max_iterations"], extra_check=spacing))
