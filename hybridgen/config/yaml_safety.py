"""YAML parsed with bounds: input size, nesting depth, alias expansion (docs/conventions.md section 5).

A 700-byte YAML "billion laughs" document (aliases of aliases) expands to gigabytes as soon as anything
walks it (placeholder resolution, ``yaml.safe_dump`` of the resolved config); 600 nested brackets exhaust
Python's recursion. :func:`load_yaml` checks both before constructing Python objects:

- the nesting depth, counted on the parser's event stream (iterative, so any depth is counted safely);
- the *expanded* size - every node counted once per path that reaches it through aliases - on the
  composed node graph, memoised per node, so the check itself costs the size of the document;
- recursive aliases (a node that contains itself) are refused.

Unhashable mapping keys (``? [a, b]``) are a :class:`ConfigError` too, instead of a ``TypeError``.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import yaml

from ..errors import ConfigError

MAX_CONFIG_BYTES = 16 * 2**20
MAX_DEPTH = 64
MAX_EXPANDED_NODES = 1_000_000


def read_limited(path: str | Path, limit: int, what: str) -> bytes:
    """At most ``limit`` bytes of ``path`` (a regular file, pipe or device); ConfigError when it has more.
    ``/dev/zero`` and multi-gigabyte files cost ``limit`` bytes, not all of memory."""
    if "\0" in str(path):
        raise ConfigError(f"{what} path contains a NUL character", file=repr(str(path)))
    with open(path, "rb") as handle:
        data = handle.read(limit + 1)
    if len(data) > limit:
        raise ConfigError(f"{what} is larger than {limit // 2**20} MiB; refusing to read it", file=str(path))
    return data


def _check_depth(text: str, loader: type, file: str) -> None:
    depth = 0
    for event in yaml.parse(text, Loader=loader):
        if isinstance(event, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            if depth > MAX_DEPTH:
                line = event.start_mark.line + 1 if event.start_mark else "?"
                raise ConfigError(f"YAML nested deeper than {MAX_DEPTH} levels (at line {line})", file=file)
        elif isinstance(event, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1


def _expanded_size(node: yaml.Node, memo: dict[int, int], active: set[int], file: str) -> int:
    key = id(node)
    if key in memo:
        return memo[key]
    if key in active:
        raise ConfigError(f"recursive YAML alias at line {node.start_mark.line + 1}", file=file)
    active.add(key)
    total = 1
    if isinstance(node, yaml.SequenceNode):
        for child in node.value:
            total += _expanded_size(child, memo, active, file)
    elif isinstance(node, yaml.MappingNode):
        for key_node, value_node in node.value:
            total += _expanded_size(key_node, memo, active, file) + _expanded_size(value_node, memo, active, file)
    if total > MAX_EXPANDED_NODES:
        raise ConfigError(f"YAML expands to more than {MAX_EXPANDED_NODES} values through aliases (at line "
                          f"{node.start_mark.line + 1}); refusing a possible alias bomb", file=file)
    active.discard(key)
    memo[key] = total
    return total


def load_yaml(text: str, loader: type = yaml.SafeLoader, file: str = "<config>") -> Any:
    """Parse one YAML document with ``loader`` (a SafeLoader subclass) within the module's bounds.
    YAML syntax errors are raised as PyYAML raises them (callers format their marks); the bounds and
    unhashable keys raise :class:`ConfigError` naming ``file``."""
    if len(text) > MAX_CONFIG_BYTES:
        raise ConfigError(f"YAML text is larger than {MAX_CONFIG_BYTES // 2**20} MiB", file=file)
    _check_depth(text, loader, file)
    instance = loader(text)
    try:
        node = instance.get_single_node()
        if node is None:
            return None
        _expanded_size(node, {}, set(), file)
        try:
            return instance.construct_document(node)
        except TypeError as exc:  # an unhashable mapping key, e.g. "? [a, b]: 1"
            raise ConfigError(f"a YAML mapping key must be a plain value ({exc})", file=file) from None
    finally:
        instance.dispose()
