"""``bproc.utility.LabelIdMapping`` (labels <-> category ids, for the dataset loaders and the COCO writer) and
``bproc.utility.resolve_resource`` (a file of BlenderProc's ``resources`` folder).

A mapping is one-to-one: adding a label or an id a second time is an error. ``num_ids`` is one more than the
largest id (ids need not be contiguous), as BlenderProc counts it. :meth:`LabelIdMapping.from_csv` reads a CSV
with a header row (columns ``name`` and ``id`` by default), as the files of BlenderProc's
``resources/id_mappings`` and ``resources/front_3D`` are laid out.
"""
from __future__ import annotations

import csv
import os
from pathlib import Path
from typing import Any, Iterator, Mapping

from ..errors import InputError

RESOURCES_ENV = "HYBRIDGEN_BPROC_RESOURCES"
"""A folder laid out as BlenderProc's ``blenderproc/resources`` (searched first by :func:`resolve_resource`)."""


class LabelIdMapping:
    """A one-to-one mapping between label names and integer ids."""

    def __init__(self) -> None:
        self._id_label_map: dict[int, str] = {}
        self._label_id_map: dict[str, int] = {}
        self._num_ids = 0
        self.source_path: str | None = None
        """The CSV file :meth:`from_csv` read (None for a mapping built otherwise)."""

    @staticmethod
    def from_csv(path: str, label_col_name: str = "name", id_col_name: str = "id") -> "LabelIdMapping":
        """The mapping of a CSV file's ``label_col_name`` and ``id_col_name`` columns (header row first)."""
        file = Path(path)
        if not file.is_file():
            raise InputError(f"LabelIdMapping.from_csv: no such file '{file}'")
        mapping = LabelIdMapping()
        with open(file, encoding="utf-8", newline="") as handle:
            reader = csv.DictReader(handle)
            missing = [c for c in (label_col_name, id_col_name) if c not in (reader.fieldnames or [])]
            if missing:
                raise InputError(f"LabelIdMapping.from_csv: '{file}' has no column {missing[0]!r} "
                                 f"(columns: {', '.join(reader.fieldnames or [])})")
            for line, row in enumerate(reader, start=2):
                try:
                    value = int(row[id_col_name])
                except (TypeError, ValueError):
                    raise InputError(f"LabelIdMapping.from_csv: '{file}' line {line}: id {row[id_col_name]!r} is "
                                     "not an integer") from None
                mapping.add(row[label_col_name], value)
        mapping.source_path = str(file)
        return mapping

    @staticmethod
    def from_dict(label_to_id: Mapping[str, int]) -> "LabelIdMapping":
        """The mapping of ``{label: id}``."""
        mapping = LabelIdMapping()
        for label, id_value in label_to_id.items():
            mapping.add(label, id_value)
        return mapping

    def add(self, label: str, id_value: int) -> None:
        """Add the pair; a label or id already present is an error (as in BlenderProc)."""
        id_value = int(id_value)
        if self.has_id(id_value):
            raise InputError(f"There already exists a label-id mapping for the id {id_value}")
        if self.has_label(label):
            raise InputError(f"There already exists a label-id mapping for the label {label}")
        self._id_label_map[id_value] = label
        self._label_id_map[label] = id_value
        self._num_ids = max(self._num_ids, id_value + 1)
        self.source_path = None  # no longer what the file says

    def id_from_label(self, label: str) -> int:
        if label not in self._label_id_map:
            raise KeyError(label)
        return self._label_id_map[label]

    def label_from_id(self, id_value: int) -> str:
        return self._id_label_map[int(id_value)]

    def has_label(self, label: str) -> bool:
        return label in self._label_id_map

    def has_id(self, id_value: int) -> bool:
        return int(id_value) in self._id_label_map

    @property
    def num_ids(self) -> int:
        """One more than the largest id."""
        return self._num_ids

    def label_to_id(self) -> dict[str, int]:
        """``{label: id}`` (a copy)."""
        return dict(self._label_id_map)

    def __iter__(self) -> Iterator[tuple[str, int]]:
        return iter(self._label_id_map.items())

    def __len__(self) -> int:
        return len(self._label_id_map)

    def __repr__(self) -> str:
        return f"<LabelIdMapping {len(self)} labels>"


def resolve_resource(relative_resource_path: str) -> str:
    """The absolute path of ``relative_resource_path`` in BlenderProc's resource folder. hybridgen ships none of
    BlenderProc's resource files; the first existing of these is returned: ``$HYBRIDGEN_BPROC_RESOURCES/<path>``,
    ``<cwd>/blenderproc/resources/<path>`` (a script run from a BlenderProc checkout, as its examples are),
    ``<cwd>/resources/<path>`` (BlenderProc 1's layout). When none exists, the checkout path (as BlenderProc
    returns its path whether or not the file is there)."""
    relative = str(relative_resource_path)
    candidates: list[str] = []
    given = os.environ.get(RESOURCES_ENV)
    if given:
        candidates.append(os.path.join(given, relative))
    candidates += [os.path.join(os.getcwd(), "blenderproc", "resources", relative),
                   os.path.join(os.getcwd(), "resources", relative)]
    for candidate in candidates:
        if os.path.exists(candidate):
            return candidate
    return candidates[-2]


def as_label_mapping(value: Any, call: str) -> LabelIdMapping:
    """``value`` if it is a :class:`LabelIdMapping` (or has ``id_from_label``), else one line naming ``call``."""
    if not hasattr(value, "id_from_label") or not hasattr(value, "has_label"):
        raise InputError(f"{call}: label_mapping must be a bproc.utility.LabelIdMapping, got {type(value).__name__}")
    return value
