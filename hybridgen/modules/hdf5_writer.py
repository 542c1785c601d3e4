"""``writer.Hdf5Writer``: the run's outputs as one HDF5 file (docs/conventions.md section 4)."""
from __future__ import annotations

from pathlib import Path
from typing import Any

from ..config.options import from_config, option_params
from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..io.hdf5_blenderproc import BlenderProcHdf5Writer
from ..io.hdf5_single import Hdf5Options, Hdf5SingleFileWriter
from ..run.context import RunContext
from ..run.staged_output import DEFAULT_CHUNK_KEYPOINTS, DEFAULT_LABEL_CHUNK_KEYPOINTS, JournalingWriter
from ..run.units import SHARD_FOLDER
from ..scene.scene import Scene
from .base import Module, Role, SingleFile


def _file_name_check(value: str) -> str | None:
    if "/" in value or value in ("", ".", ".."):
        return f"must be a plain file name inside output_dir, got {value!r}"
    return None if value.endswith((".hdf5", ".h5")) else f"must end in .hdf5 or .h5, got {value!r}"


def scene_records(scene: Scene) -> dict[str, list[dict[str, Any]]]:
    """The scene-level JSON records of an output: ``object_states`` and ``light_states``."""
    return {"object_states": [o.state() for o in scene.objects],
            "light_states": [{"name": light.name, "type": light.type, "energy": light.energy,
                              "color": list(light.color), "local2world": light.local2world.tolist()}
                             for light in scene.lights]}


@register_module("writer.Hdf5Writer")
class Hdf5Writer(Module):
    """Collects every renderer's keypoints (streamed while they render) and commits the file at this step."""

    role = Role.WRITER
    writes_unit_files = True

    params = (
        Param("output_dir", "path", doc="folder of the output file (usually from global.all)"),
        Param("file_name", "str", "data.hdf5", doc="file name inside output_dir", check=_file_name_check),
        Param("layout", "str", "single", choices=("single", "blenderproc"),
              doc="single: one file, keypoint axis first; blenderproc: one <i>.hdf5 per keypoint, BlenderProc's keys"),
        Param("append_to_existing_output", "bool", False,
              doc="blenderproc layout: number the files after the highest <i>.hdf5 already in output_dir"),
        Param("key_versions", "dict", {}, doc="blenderproc layout: a '<key>_version' dataset beside each pass, "
              "as BlenderProc 1.x's Hdf5Writer writes ({key: version}; '*' for every other key)"),
        Param("untrimmed_keys", "list", [], doc="blenderproc layout: single-channel float passes (depth, distance) "
              "stored H x W x 3, as BlenderProc 1.x stores them without postprocessing.TrimRedundantChannels"),
        Param("stereo_separate_keys", "bool", False, doc="blenderproc layout: a stereo pass as <key>_0 (left) and "
              "<key>_1 instead of one array with a leading axis of 2 (BlenderProc's option)"),
        Param("key_dtypes", "dict", {}, doc="blenderproc layout: keys stored as another NumPy dtype ({key: "
              "dtype}; BlenderProc 1.x's segmap is float64)"),
        *option_params(Hdf5Options),
        Param("resume_chunk_keypoints", "int", -1,
              doc="single layout, run without sharding as the only writer: render this many keypoints per "
              "verified part in the hidden folder .<file_name>.parts, merged at the end into the same bytes a "
              "direct write gives, so a killed run resumes; the scene is built once and each part renders its "
              "keypoints. 0: write directly (a killed run starts over); -1: "
              f"{DEFAULT_CHUNK_KEYPOINTS} when the config path-traces color, else {DEFAULT_LABEL_CHUNK_KEYPOINTS} "
              "(merging copies the parts' stored chunks once, without compressing them again)",
              check=lambda v: None if v >= -1 else f"must be >= -1, got {v}"),
    )

    def single_file(self) -> SingleFile | None:
        cfg = self.config
        if cfg["layout"] != "single":
            return None
        return SingleFile(Path(cfg["output_dir"]) / cfg["file_name"], cfg["resume_chunk_keypoints"])

    def prepare(self, context: RunContext) -> None:
        cfg = self.config
        options = from_config(Hdf5Options, cfg)
        self.writer: Hdf5SingleFileWriter | BlenderProcHdf5Writer
        if cfg["layout"] == "blenderproc":
            if options.compression == "blosc2":  # BlenderProc's tools (plain h5py) cannot read Blosc2 chunks
                raise ConfigError("'blosc2' is for the single layout; layout: blenderproc stores gzip (or lzf, "
                                  "none) for BlenderProc's tools", key="compression")
            self.writer = BlenderProcHdf5Writer(cfg["output_dir"], options, append=cfg["append_to_existing_output"],
                                                versions={str(k): str(v) for k, v in cfg["key_versions"].items()},
                                                untrimmed=tuple(str(k) for k in cfg["untrimmed_keys"]),
                                                stereo_separate_keys=cfg["stereo_separate_keys"],
                                                dtypes={str(k): str(v) for k, v in cfg["key_dtypes"].items()})
        elif context.unit is not None:  # one work unit of a sharded run (or part of a staged one): its own file
            plain = context.unit.folder == SHARD_FOLDER or context.unit.whole  # whole: a staged run's only part
            writer_class = Hdf5SingleFileWriter if plain else JournalingWriter
            self.writer = writer_class(context.unit.shard_path(cfg["output_dir"]), options)
        else:
            self.writer = Hdf5SingleFileWriter(Path(cfg["output_dir"]) / cfg["file_name"], options)
        context.sinks.append(self.writer)
        context.cleanups.append(self.writer.abort)

    def run(self, context: RunContext) -> None:
        context.outputs += self.writer.finalize(scene_records(context.scene), context.run_attributes())
