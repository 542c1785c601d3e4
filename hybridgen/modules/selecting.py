"""Base of modules that act on the objects a selector picks (BlenderProc's getter.Entity)."""
from __future__ import annotations

from typing import ClassVar

from ..errors import InputError
from ..run.context import RunContext
from ..scene.mesh_object import MeshObject
from ..sampling.getters import parse_selector
from .base import Module


class SelectingModule(Module):
    """Parses the selector parameter named ``selector_key`` before the run; :meth:`selected` applies it."""

    selector_key: ClassVar[str] = "selector"

    def prepare(self, context: RunContext) -> None:
        self.selector = parse_selector(self.config[self.selector_key], self.selector_key)

    def selected(self, context: RunContext) -> list[MeshObject]:
        """The objects the selector picks now (random subsets drawn from the run's generator); at least one,
        unless the selector says ``check_empty: false`` (BlenderProc's default: nothing selected, nothing done)."""
        chosen = self.selector.select(context.scene.objects, context.rng)
        if not chosen and not self.selector.check_empty:
            context.log(f"{self.module_name}: {self.selector_key} matches no object; nothing to do")
            return []
        if not chosen:
            raise InputError(f"{self.selector_key} matches no object ({self.selector.conditions!r})")
        return chosen
