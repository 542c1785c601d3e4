"""Key translation of BlenderProc's writers (postprocessing modules, BOP/COCO output places) and the effects one
module has on others once every module is translated (:func:`finish`)."""
from __future__ import annotations

from typing import Any, Callable

from ...errors import ConfigError
from .common import Note, pop_ignored
from .image_options import apply_image_types


def postprocessing(cfg: dict[str, Any], note: Note, state: dict[str, Any]) -> set[str]:
    """Take ``postprocessing_modules`` out of a writer's ``cfg``; the output keys whose channels are trimmed
    (TrimRedundantChannels, or Dist2Depth, which trims too)."""
    modules = cfg.pop("postprocessing_modules", None)
    trimmed: set[str] = set()
    if not modules:
        return trimmed
    if not isinstance(modules, dict):
        raise ConfigError("must map an output key to a list of {module: postprocessing.X}",
                          key="postprocessing_modules")
    for output, steps in modules.items():
        for step in steps or []:
            name = step.get("module") or step.get("name") if isinstance(step, dict) else step
            if name == "postprocessing.Dist2Depth":
                state["dist2depth"] = True  # depth is rendered exactly instead of converted from distance
                trimmed.add(str(output))
            elif name == "postprocessing.TrimRedundantChannels":
                trimmed.add(str(output))  # hybridgen's depth/distance are single-channel already
            elif name == "postprocessing.OilPaintFilter":
                note("the oil-paint filter is not implemented", f"postprocessing_modules.{output}")
            else:
                raise ConfigError(f"unknown postprocessing module {name!r}; hybridgen knows "
                                  "postprocessing.Dist2Depth and postprocessing.TrimRedundantChannels",
                                  key=f"postprocessing_modules.{output}")
    return trimmed


def writer(kind: str) -> Callable[[dict[str, Any], Note, dict[str, Any]], list[tuple[str, dict[str, Any]]]]:
    def translate(config: dict[str, Any], note: Note, state: dict[str, Any]) -> list[tuple[str, dict[str, Any]]]:
        cfg = dict(config)
        trimmed = postprocessing(cfg, note, state)
        if kind == "writer.Hdf5Writer" and state.get("blenderproc"):
            cfg.setdefault("layout", "blenderproc")  # BlenderProc's <i>.hdf5 files, its keys and encodings
            state.setdefault("trimmed", {})[id(cfg)] = trimmed
            pop_ignored(cfg, "delete_temporary_files_afterwards", note, "hybridgen keeps no temporary files")
        pop_ignored(cfg, "write_alpha_channel", note, "hybridgen images carry no alpha channel")
        pop_ignored(cfg, "output_file_prefix", note, "hybridgen names its own files")
        if kind == "writer.BopWriter":
            if "m2mm" in cfg:
                cfg["annotation_unit"] = "mm" if cfg.pop("m2mm") else "m"
            if state.get("blenderproc") and "output_dir" not in cfg:
                state.setdefault("subdirs", {})[id(cfg)] = "bop_data"
        if kind == "writer.CocoAnnotationsWriter" and state.get("blenderproc"):
            if "output_dir" not in cfg:
                state.setdefault("subdirs", {})[id(cfg)] = "coco_data"
            cfg.setdefault("image_names", "blenderproc")  # rgb_%04d.png next to the JSON, as BlenderProc
            if cfg.pop("segmap_output_key", "segmap") != "segmap":
                note("hybridgen's COCO writer reads the instance segmentation of the renderers before it "
                     "(instance_segmaps: the instance channel of the segmap, whatever its name)", "segmap_output_key")
        return [(kind, cfg)]

    return translate


def _as_list(value: Any) -> list[Any]:
    return [] if value is None else [value] if isinstance(value, str) else list(value)


def _coco_reads_renamed(coco: dict[str, Any], renderers: list[dict[str, Any]]) -> None:
    """A COCO writer whose keys are not given (or BlenderProc's defaults) reads the passes under the names the
    renderers before it store them (their ``output_keys``)."""
    stored = {own: name for r in renderers for own, name in (r.get("output_keys") or {}).items()}
    for key, own, blenderproc_default in (("rgb_output_key", "colors", "colors"),
                                          ("segcolormap_output_key", "instance_attribute_maps", "segcolormap")):
        if coco.get(key, blenderproc_default) == blenderproc_default:
            coco[key] = stored.get(own, own)


def finish(entries: list[Any], state: dict[str, Any], output_dir: Any) -> None:
    """Cross-module effects: Dist2Depth renders depth where distance was rendered; writers' BlenderProc folders."""
    if not state.get("blenderproc"):
        return
    if state.get("dist2depth"):
        for entry in entries:
            if entry.name.startswith("renderer.") and entry.config.get("render_distance"):
                entry.config["render_distance"] = False
                entry.config["render_depth"] = True
    for position, entry in enumerate(entries):
        if entry.name not in ("writer.BopWriter", "writer.CocoAnnotationsWriter"):
            continue
        # BlenderProc's BOP writer renders its own masks and depth; hybridgen's writers take them from the
        # renderer before them, which is asked for them here
        renderers = [e for e in entries[:position] if e.name.startswith("renderer.")]
        if not renderers:
            continue
        last = renderers[-1].config
        if entry.name == "writer.CocoAnnotationsWriter":
            _coco_reads_renamed(entry.config, [e.config for e in renderers])
        else:  # BlenderProc's BOP writer renders its own: hybridgen's reads the passes under their stored names
            stored = {own: name for e in renderers for own, name in (e.config.get("output_keys") or {}).items()
                      if own in ("colors", "depth", "instance_segmaps")}
            if stored and entry.config.get("input_keys") is None:
                entry.config["input_keys"] = stored
        if not any("instance" in _as_list(e.config.get("map_by")) for e in renderers):
            last["map_by"] = [*_as_list(last.get("map_by")), "instance"]
        if entry.name == "writer.BopWriter" and not any(e.config.get("render_depth") for e in renderers):
            last["render_depth"] = True
    for position, entry in enumerate(entries):
        trimmed = state.get("trimmed", {}).get(id(entry.config))
        if trimmed is not None and entry.config.get("layout") == "blenderproc":
            _blenderproc_v1_hdf5(entry.config, [e.config for e in entries[:position] if e.name.startswith("renderer.")],
                                 trimmed, bool(state.get("dist2depth")))
    apply_image_types(entries, state.get("image_types", {}))
    subdirs = state.get("subdirs", {})
    if subdirs and isinstance(output_dir, str):
        for entry in entries:
            sub = subdirs.get(id(entry.config))
            if sub is not None:
                entry.config["output_dir"] = f"{output_dir.rstrip('/')}/{sub}"


def _blenderproc_v1_hdf5(writer: dict[str, Any], renderers: list[dict[str, Any]], trimmed: set[str],
                         dist2depth: bool) -> None:
    """What BlenderProc 1.x's Hdf5Writer adds to its files: ``<key>_version`` datasets ("2.0.0" for rendered
    passes, "1.0.0" for a Dist2Depth depth), depth/distance as H x W x 3 where no TrimRedundantChannels
    trimmed them (the EXR's three channels), and the SegMapRenderer's segmap as float64."""
    untrimmed = []
    for renderer in renderers:
        names = renderer.get("output_keys") or {}
        for flag, own in (("render_depth", "depth"), ("render_distance", "distance")):
            stored = str(names.get(own, own))
            if renderer.get(flag) and stored not in trimmed and not (dist2depth and own == "depth"):
                untrimmed.append(stored)
    writer.setdefault("untrimmed_keys", list(dict.fromkeys(untrimmed)))
    writer.setdefault("key_versions", {"*": "2.0.0", **({"depth": "1.0.0"} if dist2depth else {})})
    segmaps = [r["blenderproc_segmap"]["key"] for r in renderers if isinstance(r.get("blenderproc_segmap"), dict)]
    writer.setdefault("key_dtypes", {str(key): "float64" for key in segmaps})  # 1.x's np.empty-built segmap
