"""Cost of transparent shadows (hybridgen/render/pathtrace/transparent_shadows.py): color time of a scene with an alpha
cut-out, traced with transparent shadows (what hybridgen does for such scenes) and with opaque shadow rays
(Mitsuba's test-for-any-hit, what it did before), in the same process and run.

Run: .venv/bin/python tools/bench_transparent_shadows.py [--variant llvm_ad_rgb|scalar_rgb] [--res 320x240]
     [--spp 256] [--repeats 3]

Scene: a 6 m floor, a 2 m leaf at 1 m height whose alpha map is a 64 x 64 checker of 8-texel squares
(CLIP), a sun and a dim constant world; 3 bounces. JIT variants compare hybridgen's clamped path tracer with
and without ``transparent_shadows``; ``scalar_rgb`` compares Mitsuba's ``volpath`` with ``path``. Printed:
process CPU time (all threads) and wall time of each render after a compiling warm-up, and the CPU-time
ratio of the medians - steadier than wall time on a shared machine.
"""
from __future__ import annotations

import argparse
import statistics

import numpy as np
from harness import Stopwatch


def _scene(width: int, height: int):  # noqa: ANN202 - hybridgen imported lazily
    import hybridgen as hg

    scene = hg.Scene()
    scene.world.strength = 0.5

    def square(name: str, z: float, size: float, material: hg.Material) -> hg.MeshObject:
        h = size / 2
        return hg.MeshObject(name, [[-h, -h, z], [h, -h, z], [h, h, z], [-h, h, z]], [[0, 1, 2], [0, 2, 3]],
                             uvs=[[0, 0], [1, 0], [1, 1], [0, 1]], material=material)

    scene.add(square("floor", 0.0, 6.0, hg.Material(base_color=(0.5, 0.5, 0.5, 1))))
    alpha = (np.indices((64, 64)).sum(0) // 8 % 2 == 0).astype(np.uint8) * 255
    scene.add(square("leaf", 1.0, 2.0, hg.Material(base_color=(0.3, 0.6, 0.2, 1), alpha_texture=alpha,
                                                   alpha_mode="CLIP")))
    sun = hg.look_at([1.0, 1.0, 3.0], [0.0, 0.0, 0.0]) @ np.diag([1.0, -1.0, -1.0, 1.0])  # -z towards the origin
    scene.add_light(hg.Light("sun", "SUN", energy=2.0, local2world=sun))
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.9, width, height)
    return scene


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", default=None)
    parser.add_argument("--res", default="320x240")
    parser.add_argument("--spp", type=int, default=256)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    import hybridgen as hg
    from hybridgen.render.pathtrace import transparent_shadows
    from hybridgen.render.pathtrace.mitsuba_variant import choose_variant
    from hybridgen.render.pathtrace.path_trace import PathTraceSettings, PathTraceView

    variant = choose_variant(args.variant)
    width, height = (int(v) for v in args.res.split("x"))
    camera = hg.look_at([0.0, -3.0, 2.0], [0.0, 0.0, 0.3])
    detect = transparent_shadows.scene_has_masks
    cpu: dict[bool, list[float]] = {False: [], True: []}
    views = {}
    for on in (False, True):
        transparent_shadows.scene_has_masks = lambda scene, on=on: on  # type: ignore[assignment]
        views[on] = PathTraceView(_scene(width, height), PathTraceSettings(samples=args.spp, max_bounces=3),
                                  variant=variant)
        views[on].render(camera, seed=0, spp=4)  # compile
    transparent_shadows.scene_has_masks = detect  # type: ignore[assignment]
    for _ in range(args.repeats):
        for on in (False, True):
            watch = Stopwatch()
            views[on].render(camera, seed=1, spp=args.spp)
            wall, seconds = watch.read()
            cpu[on].append(seconds)
            print(f"{variant} {'transparent' if on else 'opaque     '} shadows: cpu {seconds:.2f} s, wall {wall:.2f} s")
    ratio = statistics.median(cpu[True]) / statistics.median(cpu[False])
    print(f"{variant}: transparent / opaque CPU time (medians) = {ratio:.2f}")


if __name__ == "__main__":
    main()
