"""Base class of config modules: a declared schema and a thin call into the Python API."""
from __future__ import annotations

from typing import TYPE_CHECKING, Any, ClassVar

from ..config.schema import Param

if TYPE_CHECKING:
    from ..run.context import RunContext


class Module:
    """A step of a config's ``modules`` list.

    Subclasses declare ``params`` once (type, default, unit, doc) and implement :meth:`run`. ``config`` holds
    validated values with defaults filled in. :meth:`prepare` runs for every module, in order, before any
    module runs (writers use it to accept frames from renderers that come earlier in the list).
    """

    module_name: ClassVar[str] = ""
    doc: ClassVar[str] = ""
    params: ClassVar[tuple[Param, ...]] = ()

    def __init__(self, config: dict[str, Any], index: int) -> None:
        self.config = config
        self.index = index

    @classmethod
    def param_table(cls) -> dict[str, Param]:
        """The declared parameters by name."""
        return {p.name: p for p in cls.params}

    def value(self, context: "RunContext", key: str) -> Any:
        """The config value ``key`` with its samplers drawn afresh, checked against its declared type."""
        from ..config.schema import ConfigError
        from ..sampling.registry import DrawContext, contains_sampled, draw

        raw = self.config[key]
        if not contains_sampled(raw):
            return raw
        drawn = draw(raw, DrawContext(context.rng, context.scene))
        try:
            return self.param_table()[key].check_value(drawn)
        except ConfigError as exc:
            raise ConfigError(f"a drawn value is invalid: {exc.detail}", key=key) from None

    def prepare(self, context: "RunContext") -> None:
        """Called for all modules before the first one runs."""

    def run(self, context: "RunContext") -> None:
        """Do this module's work on the run context (scene, camera, outputs)."""
        raise NotImplementedError
