"""A module's input path parameters resolved as :mod:`hybridgen.input_paths` resolves paths named in a config."""
from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING, Iterable

from ..input_paths import locate_input

if TYPE_CHECKING:
    from .schema import Param

OUTPUT_KEYS = frozenset({"output_dir"})
"""Path parameters that name something a run writes: relative to the working directory only, never looked up."""


def resolve_module_paths(params: Iterable[Param], values: dict[str, object], config_path: str | Path) -> None:
    """Resolve, in place, every input path parameter of one module's validated ``values``.

    Parameters typed ``path`` (alone or in a union), other than :data:`OUTPUT_KEYS`, holding a string are
    inputs. One found in neither place stays as given: the code reading it reports it with
    :func:`~hybridgen.input_paths.not_found` (after its own checks, such as the file format).
    """
    for param in params:
        value = values.get(param.name)
        if param.name in OUTPUT_KEYS or "path" not in param.type.split("|") or not isinstance(value, str):
            continue
        values[param.name] = locate_input(value, config_path)
