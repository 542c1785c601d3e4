"""``writer.ObjectStateWriter``, ``writer.CameraStateWriter``, ``writer.LightStateWriter`` (BlenderProc names).

In BlenderProc these add object, camera and light states to the HDF5 files. hybridgen's
``writer.Hdf5Writer`` always writes them: ``object_states`` (per object: idx, name, category_id, custom
attributes, local2world), ``light_states`` and the cameras (``cam2world``/``cam_K``, and ``cam_states``
with Blender-axes ``cam2world`` in the BlenderProc layout). These modules check that a writer.Hdf5Writer
follows them and say once where the states are.
"""
from __future__ import annotations

from typing import ClassVar

from ..config.notices import notice
from ..config.registry import get_module, register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..run.context import RunContext
from .base import Module, Role
from .hdf5_writer import Hdf5Writer


class StateWriter(Module):
    """Checks for a following writer.Hdf5Writer, which writes ``written_as``."""

    role = Role.WRITER

    written_as: ClassVar[str] = ""
    params = (
        Param("attributes_to_write", "list|null", None, doc="BlenderProc's attribute list; hybridgen writes "
              "its full record"),
        Param("output_key", "str|null", None, doc="BlenderProc's dataset name; hybridgen's is fixed"),
        Param("selector", "dict|list|null", None, doc="BlenderProc's selection; hybridgen writes every object"),
    )

    def prepare(self, context: RunContext) -> None:
        config = context.config
        later = [e for e in (config.modules if config is not None else []) if e.index > self.index]
        writer = Hdf5Writer.module_name
        if config is not None and not any(issubclass(get_module(e.name), Hdf5Writer) for e in later):
            raise ConfigError(f"writes through {writer} ({self.written_as}); add one after this module")
        notice(f"hybridgen's {writer} writes {self.written_as}", module=self.module_name,
               index=self.index)

    def run(self, context: RunContext) -> None:
        """Nothing to do here: the Hdf5Writer records the states when it writes."""


@register_module("writer.ObjectStateWriter")
class ObjectStateWriter(StateWriter):
    """Object states (BlenderProc: 'object_states')."""

    written_as = "'object_states' (idx, name, category_id, attributes, local2world)"


@register_module("writer.CameraStateWriter")
class CameraStateWriter(StateWriter):
    """Camera states (BlenderProc: 'campose')."""

    written_as = "the cameras as 'cam2world'/'cam_K' (layout blenderproc: 'cam_states'), not 'campose'"


@register_module("writer.LightStateWriter")
class LightStateWriter(StateWriter):
    """Light states (BlenderProc: 'light_states')."""

    written_as = "'light_states'"
