"""``Material.infuse_texture`` and ``infuse_material`` in the real BlenderProc against hybridgen: the same script
(written here, run by both) renders seven matte squares - a base-color image with an image infused by ``mix``,
``overlay``, ``set``, ``set`` inverted, ``mix`` over an unlinked base color, and a red material with a blue one
infused by ``infuse_material`` ``mix`` (0.3) and ``add`` - and saves Cycles' Diffuse Color pass (BlenderProc's
``diffuse`` output: the base color, as the squares have Specular IOR Level 0). Prints, per square, the median
color of each engine (8-bit sRGB), the share of pixels within 2 codes of each other and, inside the pattern's
blocks (away from its edges, where Cycles' pixel filter blends neighbouring texels), the share within 1 code.

    .venv/bin/python tools/infuse_vs_blenderproc.py [--work DIR]

BlenderProc renders with the Standard view transform (tools/bproc_launch.py ``--view-transform``), hybridgen's
only one; Filmic, BlenderProc's default, would compress the colors. Needs the BlenderProc venv (``tools/blenderproc_reference.py setup``). The infused image is a 4 x 4 pattern read
at UV / 0.5 (two repeats per square), so UV, scale and repeat are compared as well as the blends.
"""
from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from blenderproc_reference import execute, hybridgen_invocation, reference_invocation  # noqa: E402

FOV = 1.8
"""Horizontal field of view (rad): 15.4 m wide at the squares, 6 m away."""
SPACING, FIRST = 2.2, -6.6
"""The squares' spacing and the first one's x (m)."""
SCRIPT = '''
FOV, SPACING, FIRST = %r, %r, %r
import blenderproc as bproc
import sys
import numpy as np
bproc.init()
folder, out = sys.argv[1], sys.argv[2]
base = bproc.loader.load_texture(folder + "/base.png")[0]
pattern = bproc.loader.load_texture(folder + "/pattern.png")[0]
cases = [("mix", False, True), ("overlay", False, True), ("set", False, True), ("set", True, True),
         ("mix", False, False)]
for index, (mode, invert, linked) in enumerate(cases):
    square = bproc.object.create_primitive("PLANE", location=[SPACING * index + FIRST, 0, 0])
    material = square.new_material(f"case{index}")
    material.set_principled_shader_value("Specular IOR Level", 0.0)
    if linked:
        material.set_principled_shader_value("Base Color", base.image)
    else:
        material.set_principled_shader_value("Base Color", [0.3, 0.5, 0.1, 1.0])
    material.infuse_texture(pattern, mode=mode, texture_scale=0.5, strength=0.7, invert_texture=invert)
for index, mode in enumerate(["mix", "add"], start=len(cases)):
    square = bproc.object.create_primitive("PLANE", location=[SPACING * index + FIRST, 0, 0])
    material = square.new_material(f"case{index}")
    material.set_principled_shader_value("Specular IOR Level", 0.0)
    material.set_principled_shader_value("Base Color", [0.8, 0.1, 0.1, 1.0])
    blue = bproc.material.create(f"blue{index}")
    blue.set_principled_shader_value("Specular IOR Level", 0.0)
    blue.set_principled_shader_value("Base Color", [0.1, 0.2, 0.9, 1.0])
    material.infuse_material(blue, mode=mode, mix_strength=0.3)
light = bproc.types.Light()
light.set_location([0, 0, 5])
bproc.camera.set_resolution(620, 100)
bproc.camera.set_intrinsics_from_blender_params(lens=FOV, lens_unit="FOV")
pose = np.eye(4)
pose[:3, 3] = [0.0, 0.0, 6.0]
bproc.camera.add_camera_pose(pose)
bproc.renderer.set_max_amount_of_samples(4)
bproc.renderer.enable_diffuse_color_output()
data = bproc.renderer.render()
np.save(out, np.asarray(data["diffuse"][0]))
''' % (FOV, SPACING, FIRST)
CASES = ("mix (OVERLAY)", "overlay (MIX)", "set", "set, inverted", "mix, unlinked", "material mix", "material add")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--work", type=Path, default=None, help="folder for the script and images (default: temp)")
    args = parser.parse_args()
    from PIL import Image

    work = args.work or Path(tempfile.mkdtemp(prefix="infuse-"))
    work.mkdir(parents=True, exist_ok=True)
    Image.new("RGB", (8, 8), (200, 60, 30)).save(work / "base.png")
    rng = np.random.default_rng(7)
    Image.fromarray(rng.integers(0, 256, (4, 4, 3), dtype=np.uint8)).resize((64, 64), Image.NEAREST).save(
        work / "pattern.png")
    (work / "main.py").write_text(SCRIPT)
    images = {}
    for engine, invocation in (("blenderproc", reference_invocation), ("hybridgen", hybridgen_invocation)):
        out = work / f"{engine}.npy"
        launch = ["--view-transform", "Standard"] if engine == "blenderproc" else None  # hybridgen's only view
        status = execute(invocation("main.py", [str(work), str(out)], launch=launch, root=work),
                         log=work / f"{engine}.log")
        if status != 0:
            sys.exit(f"{engine} failed ({status}); see {work / (engine + '.log')}")
        images[engine] = np.load(out).astype(int)
    reference, ours = images["blenderproc"], images["hybridgen"]
    width = reference.shape[1]
    # pixels inside a block of the pattern (hybridgen's 5 x 5 neighbourhood uniform): Cycles' Diffuse Color pass is
    # filtered over the pixel (1.5 px Blackman-Harris, 4 samples), hybridgen's labels are at pixel centres
    padded = np.pad(ours, ((2, 2), (2, 2), (0, 0)), mode="edge")
    flat = np.ones(ours.shape[:2], bool)
    for dy in range(5):
        for dx in range(5):
            flat &= np.all(padded[dy:dy + ours.shape[0], dx:dx + ours.shape[1]] == ours, axis=-1)
    print(f"{'case':16s} {'BlenderProc median':>20s} {'hybridgen median':>20s} {'<=2 codes':>10s} "
          f"{'block px':>9s} {'<=1 there':>10s}")
    for index, name in enumerate(CASES):
        centre = int(width / 2 + (SPACING * index + FIRST) * width / (12.0 * np.tan(FOV / 2)))
        region = (slice(35, 65), slice(centre - 15, centre + 15))
        difference = np.abs(reference[region] - ours[region]).max(axis=-1)
        inside = flat[region]
        print(f"{name:16s} {str(np.median(reference[region].reshape(-1, 3), 0).astype(int)):>20s} "
              f"{str(np.median(ours[region].reshape(-1, 3), 0).astype(int)):>20s} "
              f"{np.mean(difference <= 2):10.3f} {int(inside.sum()):9d} {np.mean(difference[inside] <= 1):10.3f}")


if __name__ == "__main__":
    main()
