"""``main.Initializer``: the run's root seed and defaults."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param
from ..run.context import DEFAULT_SEED, RunContext
from .base import Module


@register_module("main.Initializer")
class Initializer(Module):
    """Sets the root seed every random draw of the run derives from, and run-wide defaults."""

    params = (
        Param("seed", "int", DEFAULT_SEED, doc="root seed; same config + seed = same bytes",
              check=lambda v: None if v >= 0 else "must be >= 0"),
        Param("default_category_id", "int|null", None,
              doc="category_id for objects that have none (otherwise class segmentation fails naming them)"),
    )

    def run(self, context: RunContext) -> None:
        context.set_seed(self.config["seed"])
        context.default_category_id = self.config["default_category_id"]
