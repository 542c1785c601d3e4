"""The Blender side of tools/filmic_vs_blender.py: Blender 4.2 writes scene-linear float pixels through a view
transform to PNG, as it writes a render (``Image.save_render`` with the scene's color management).

    .venv-blenderproc/bin/python tools/filmic_blender.py VALUES.npy VIEW OUT_DIR

VALUES.npy: (H, W, 3) float32 scene-linear Rec.709, rows top-down. Writes ``OUT_DIR/8.png`` and ``OUT_DIR/16.png``
(8- and 16-bit RGB) through the view ``VIEW`` (Standard, Filmic, ...; look None) with dithering off.
"""
from __future__ import annotations

import os
import sys

import bpy
import numpy as np


def main() -> None:
    values_path, view, out_dir = sys.argv[1:4]
    values = np.load(values_path).astype(np.float32)
    height, width = values.shape[:2]
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    scene.view_settings.view_transform = view
    scene.view_settings.look = "None"
    scene.view_settings.exposure, scene.view_settings.gamma = 0.0, 1.0
    scene.render.dither_intensity = 0.0
    image = bpy.data.images.new("linear", width, height, alpha=True, float_buffer=True)
    rgba = np.concatenate([values, np.ones((height, width, 1), np.float32)], axis=2)[::-1]  # Blender: bottom-up
    image.pixels.foreach_set(rgba.ravel())
    settings = scene.render.image_settings
    settings.file_format, settings.color_mode = "PNG", "RGB"
    for depth in ("8", "16"):
        settings.color_depth = depth
        image.save_render(os.path.join(out_dir, f"{depth}.png"), scene=scene)


if __name__ == "__main__":
    main()
    sys.stdout.flush()
    os._exit(0)
