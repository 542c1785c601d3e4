"""Runs a BlenderProc 2 script in this process on one engine, with render settings overridden at render time and,
for hybridgen, the time of each stage recorded. Used by tools/compare_with_blenderproc.py and
tools/bench_blenderproc.py; the script itself is unchanged.

    python tools/bproc_launch.py blenderproc|hybridgen [OPTIONS] SCRIPT [ARGS...]

``blenderproc`` runs in the BlenderProc venv (tools/blenderproc_reference.py: its Python, BlenderProc's source on
PYTHONPATH, ``USE_EXTERNAL_BPY_MODULE=1``) and needs nothing of hybridgen; ``hybridgen`` runs
``hybridgen run SCRIPT ARGS`` in this checkout's venv. The overrides are applied each time the script calls
``bproc.renderer.render()``, just before it renders, so they win over the script's own settings:

- ``--samples N``, ``--noise-threshold X`` (0: no adaptive sampling), ``--no-denoiser``: a converged reference;
- ``--view-transform NAME``: both engines' view (``Standard`` for pixel comparisons of linear light);
- ``--add-labels``: the outputs the script did not enable among depth (``activate_antialiasing=False``, unless
  it asked for distance), normals and instance segmentation mapped by ``instance`` and ``name``
  (``instance_segmaps`` and ``instance_attribute_maps``), for pixel and per-object comparisons;
- ``--frames N``: only the first N frames are rendered (``set_keyframe_render_interval``);
- ``--seed N``: the path tracer's seed (Cycles' ``scene.cycles.seed``, 0 unless set; hybridgen's render seed, 0):
  another independent noise pattern, e.g. a second reference to measure a reference's own noise.

``--scene-dump PATH`` writes, at each render, what the camera and objects are: a JSON list with one object per
render, ``{"K": 3x3, "cam2world": [4x4 per frame, Blender camera axes], "objects": {name: 4x4 local2world}}``
(m; the objects' matrices at the moment ``render()`` is called).

``--profile PATH`` (hybridgen only) writes a JSON object of wall seconds per stage: ``imports`` (hybridgen and
its bproc layer), ``scene_load`` (``bproc.loader.*``), ``render`` (``bproc.renderer.render`` as a whole) and, within
it, ``mitsuba_scene`` (building Mitsuba's scene), ``sampling`` (path tracing, split by Dr.Jit's kernel history into
``kernel_compile`` and the rest), ``labels`` (raster label passes), ``denoise_guides`` (drawing, filtering or
waiting for the guides on the render loop's thread), ``denoise`` (beside the render loop, on other threads: Open
Image Denoise, the guide worker's draws and the guides' filtering, overlapping sampling), ``denoise_wait`` (the render loop waiting for a keypoint's denoised colors), then ``write``
(``bproc.writer.*``) and ``in_process`` (everything after the interpreter started, to exit).
"""
from __future__ import annotations

import argparse
import atexit
import json
import os
import sys
import threading
import time
from typing import Any

from harness import accumulating  # stdlib only: importable in the BlenderProc venv too

STARTED = time.perf_counter()
SEGMENTATION_MAP_BY = ["instance", "name"]
LABEL_KINDS = ("depth", "distance", "normals", "segmentation")


def _parse(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("engine", choices=("blenderproc", "hybridgen"))
    parser.add_argument("--samples", type=int)
    parser.add_argument("--noise-threshold", type=float)
    parser.add_argument("--no-denoiser", action="store_true")
    parser.add_argument("--view-transform")
    parser.add_argument("--add-labels", action="store_true")
    parser.add_argument("--frames", type=int)
    parser.add_argument("--seed", type=int)
    parser.add_argument("--profile")
    parser.add_argument("--scene-dump")
    parser.add_argument("script")
    parser.add_argument("args", nargs=argparse.REMAINDER)
    return parser.parse_args(argv)


# ------------------------------------------------------------------------------------------ the engines
class BlenderProcEngine:
    """The real BlenderProc (``blenderproc.api.*`` as the script sees it)."""

    def __init__(self) -> None:
        import blenderproc  # before the script, whose own import then gets this module

        self.bproc = blenderproc

    def enabled_outputs(self) -> set[str]:
        from blenderproc.python.utility.Utility import Utility

        keys = {output["key"] for output in Utility.get_registered_outputs()}
        return {kind for kind in LABEL_KINDS if kind in keys} | ({"segmentation"} if "segmap" in keys else set())

    def frame_start(self) -> int:
        import bpy

        return int(bpy.context.scene.frame_start)

    def set_seed(self, seed: int) -> None:
        import bpy

        bpy.context.scene.cycles.seed = seed

    def run(self, script: str, args: list[str]) -> int:
        import runpy

        sys.argv = [script, *args]
        sys.path.insert(0, os.path.dirname(os.path.abspath(script)))
        runpy.run_path(script, run_name="__main__")
        return 0


class HybridgenEngine:
    """hybridgen's bproc layer, run as ``hybridgen run`` runs it."""

    def __init__(self, spent: dict[str, float]) -> None:
        import hybridgen.bproc

        spent["imports"] = time.perf_counter() - STARTED
        self.bproc = hybridgen.bproc

    def enabled_outputs(self) -> set[str]:
        from hybridgen.bproc.session import SESSION

        return set(SESSION.renderer.outputs)

    def frame_start(self) -> int:
        from hybridgen.bproc.session import SESSION

        return int(SESSION.frame_start)

    def set_seed(self, seed: int) -> None:
        import hybridgen

        render_color = getattr(hybridgen.render_color, "unseeded", hybridgen.render_color)

        def seeded(*args: Any, **kwargs: Any) -> Any:
            return render_color(*args, **{**kwargs, "seed": seed})

        seeded.unseeded = render_color  # type: ignore[attr-defined]
        hybridgen.render_color = seeded

    def run(self, script: str, args: list[str]) -> int:
        from hybridgen.cli import main

        return main(["-q", "run", script, *args])


def instrument_hybridgen(spent: dict[str, float]) -> None:
    """Wraps hybridgen's stages (see the module documentation) to add their wall seconds to ``spent``."""
    import drjit as dr

    import hybridgen.bproc.loader as loader
    import hybridgen.bproc.writer as writer
    import hybridgen.render.render_color as render_color
    from hybridgen.render.denoise_guides import DenoiseGuides
    from hybridgen.render.guide_worker import GuideWorker
    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from hybridgen.render.raster.label_producer import LabelProducer

    for module, stage in ((loader, "scene_load"), (writer, "write")):
        for name in [n for n in dir(module) if n.startswith(("load_", "write_"))]:
            if callable(getattr(module, name)):
                setattr(module, name, accumulating(spent, stage, getattr(module, name)))
    PathTraceView.__init__ = accumulating(spent, "mitsuba_scene", PathTraceView.__init__)
    LabelProducer.produce = accumulating(spent, "labels", LabelProducer.produce)

    def guide_stage(call: Any) -> Any:
        """``call`` timed as ``denoise_guides`` on the render loop's thread, as ``denoise`` (beside) on others: the
        guide worker's draws, the filtering thread's filter and its waits for the worker."""
        def timed(*args: Any, **kwargs: Any) -> Any:
            stage = "denoise_guides" if threading.current_thread() is threading.main_thread() else "denoise"
            return accumulating(spent, stage, call)(*args, **kwargs)
        return timed

    DenoiseGuides.draw = guide_stage(DenoiseGuides.draw)
    DenoiseGuides.filtered = guide_stage(DenoiseGuides.filtered)
    GuideWorker.result = guide_stage(GuideWorker.result)
    render_color.oidn_denoise = accumulating(spent, "denoise", render_color.oidn_denoise)
    produce_later = render_color.ColorProducer.produce_later

    def later(*args: Any, **kwargs: Any) -> Any:  # the call that waits for the keypoint's denoised colors
        return accumulating(spent, "denoise_wait", produce_later(*args, **kwargs))

    render_color.ColorProducer.produce_later = later
    dr.set_flag(dr.JitFlag.KernelHistory, True)
    render = PathTraceView.render_with_counts

    def sampling(*args: Any, **kwargs: Any) -> Any:
        dr.kernel_history()  # cleared: what follows is this call's
        start = time.perf_counter()
        try:
            return render(*args, **kwargs)
        finally:
            spent["sampling"] = spent.get("sampling", 0.0) + time.perf_counter() - start
            compile_ms = sum(float(k.get("backend_time", 0.0)) + float(k.get("codegen_time", 0.0))
                             for k in dr.kernel_history())
            spent["kernel_compile"] = spent.get("kernel_compile", 0.0) + compile_ms / 1000.0

    PathTraceView.render_with_counts = sampling


def scene_state(bproc: Any, first: int) -> dict[str, Any]:
    """The camera's K and per-frame poses and every mesh object's matrix, as lists (see the module doc)."""
    frames = range(first, first + int(bproc.utility.num_frames()))
    return {"K": [list(map(float, row)) for row in bproc.camera.get_intrinsics_as_K_matrix()],
            "cam2world": [[list(map(float, row)) for row in bproc.camera.get_camera_pose(frame)] for frame in frames],
            "objects": {obj.get_name(): [list(map(float, row)) for row in obj.get_local2world_mat()]
                        for obj in bproc.object.get_all_mesh_objects()}}


def add_labels(renderer: Any, enabled: set[str]) -> None:
    """Enables depth, normals and instance segmentation where ``enabled`` (output kinds) lacks them."""
    if not enabled & {"depth", "distance"}:
        renderer.enable_depth_output(activate_antialiasing=False)
    if "normals" not in enabled:
        renderer.enable_normals_output()
    if "segmentation" not in enabled:
        renderer.enable_segmentation_output(map_by=list(SEGMENTATION_MAP_BY))


def apply_overrides(engine: Any, ns: argparse.Namespace, spent: dict[str, float]) -> None:
    """Wraps ``bproc.renderer.render`` so that the overrides are set just before each render (and the scene
    dumped)."""
    renderer = engine.bproc.renderer
    original = renderer.render
    dumps: list[dict[str, Any]] = []

    def render(*args: Any, **kwargs: Any) -> Any:
        if ns.samples is not None:
            renderer.set_max_amount_of_samples(ns.samples)
        if ns.noise_threshold is not None:
            renderer.set_noise_threshold(ns.noise_threshold)
        if ns.no_denoiser:
            renderer.set_denoiser(None)
        if ns.view_transform is not None:
            renderer.set_output_format(view_transform=ns.view_transform)
        if ns.add_labels:
            add_labels(renderer, engine.enabled_outputs())
        if ns.seed is not None:
            engine.set_seed(ns.seed)
        if ns.frames is not None:
            start = engine.frame_start()
            engine.bproc.utility.set_keyframe_render_interval(start, start + ns.frames)
        if ns.scene_dump:
            dumps.append(scene_state(engine.bproc, engine.frame_start()))
            with open(ns.scene_dump, "w") as out:
                json.dump(dumps, out)
        started = time.perf_counter()
        try:
            return original(*args, **kwargs)
        finally:
            spent["render"] = spent.get("render", 0.0) + time.perf_counter() - started

    renderer.render = render


def main(argv: list[str] | None = None) -> int:
    ns = _parse(sys.argv[1:] if argv is None else argv)
    spent: dict[str, float] = {}
    if ns.engine == "hybridgen":
        engine: Any = HybridgenEngine(spent)
        if ns.profile:
            instrument_hybridgen(spent)
    else:
        engine = BlenderProcEngine()
    if ns.profile:
        def dump() -> None:
            spent["in_process"] = time.perf_counter() - STARTED
            with open(ns.profile, "w") as out:
                json.dump(spent, out)

        atexit.register(dump)
    apply_overrides(engine, ns, spent)
    return engine.run(ns.script, ns.args)


if __name__ == "__main__":
    sys.exit(main())
