"""``main.Initializer``: the run's root seed and defaults."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param
from ..run.context import DEFAULT_SEED, RunContext
from .base import Module, Role, SceneUnits


def _color_check(value: list) -> str | None:
    ok = len(value) == 3 and all(isinstance(c, (int, float)) and not isinstance(c, bool) and c >= 0 for c in value)
    return None if ok else f"must be 3 numbers >= 0, got {value!r}"


@register_module("main.Initializer")
class Initializer(Module):
    """Sets the root seed every random draw of the run derives from, and run-wide defaults."""

    role = Role.SETUP

    params = (
        Param("seed", "int", DEFAULT_SEED, doc="root seed; same config + seed = same bytes",
              check=lambda v: None if 0 <= v < 2**63 else f"must be in [0, 2**63) (stored as int64), got {v}"),
        Param("default_category_id", "int|null", None,
              doc="category_id for objects that have none (otherwise class segmentation fails naming them)"),
        Param("horizon_color", "list", [0.05, 0.05, 0.05], doc="world background radiance, linear RGB",
              check=_color_check),
        Param("world_strength", "float", 1.0, doc="multiplies the world background (color or HDRI)",
              check=lambda v: None if v >= 0 else "must be >= 0"),
        Param("hdri_path", "path|null", None, doc="HDRI file (.exr/.hdr): the environment map lighting the scene"),
        Param("hdri_rotation", "float", 0.0, "rad", "rotation of the environment map about world +Z"),
        Param("number_of_scenes", "int", 1, doc="scene variations: every module runs once per scene, each scene "
              "with its own seed (SeedSequence(seed).spawn); more than 1 writes shards (see README)",
              check=lambda v: None if v >= 1 else "must be >= 1"),
        Param("keypoints_per_chunk", "int", 0, doc="split each scene's keypoints into work units of this many "
              "(0: one unit per scene); units run in parallel with --workers and resume independently",
              check=lambda v: None if v >= 0 else "must be >= 0"),
    )

    def scene_units(self) -> SceneUnits:
        return SceneUnits(self.config["number_of_scenes"], self.config["keypoints_per_chunk"])

    def run(self, context: RunContext) -> None:
        cfg = self.config
        context.set_seed(cfg["seed"])
        context.default_category_id = cfg["default_category_id"]
        world = context.scene.world
        world.color = tuple(float(c) for c in cfg["horizon_color"])  # type: ignore[assignment]
        world.strength = float(cfg["world_strength"])
        world.hdri_path = cfg["hdri_path"]
        world.hdri_rotation = float(cfg["hdri_rotation"])

