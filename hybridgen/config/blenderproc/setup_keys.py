"""BlenderProc ``setup`` and ``global`` keys that only configure Blender: what hybridgen ignores (with a notice)."""
from __future__ import annotations

BLENDER_SETUP_KEYS = ("blender_install_path", "blender_version", "custom_blender_path", "blender_url",
                      "custom_blender_path_env")
"""``setup`` keys that locate or download Blender: hybridgen renders without Blender, so they are ignored."""


BLENDER_PYTHON_PACKAGES = frozenset({
    "h5py", "imageio", "pypng", "scikit-image", "scipy", "matplotlib", "pytz", "torch", "scikit-learn",
    "python-dateutil", "numpy", "pillow", "opencv-contrib-python", "opencv-python", "pyyaml", "smplx",
    "human_body_prior", "trimesh", "pyrender", "numba", "chumpy", "tqdm",
})
"""Packages BlenderProc configs install into Blender's own Python; hybridgen's modules do not import them
through the config, so a missing one is a notice, not an error."""


GLOBAL_IGNORED = {
    "sys_paths": "Blender's Python import paths; hybridgen needs none",
    "transparency_bounces": "Cycles' limit on alpha-transparent surfaces; hybridgen's materials are opaque or "
                            "refractive (transmission_bounces)",
    "volume_bounces": "hybridgen renders no volumes",
    "output_is_temp": "hybridgen keeps no temporary per-frame files; writers write the final files",
    "pixel_aspect_x": "not applied from here: set it in a camera module's intrinsics (BlenderProc 1.12) or in "
                      "global.renderer (1.0)",
    "pixel_aspect_y": "not applied from here: set it in a camera module's intrinsics (BlenderProc 1.12)",
    "avoid_rendering": "hybridgen always renders what the config's renderers ask",
}
"""``global`` keys that only configure Blender or BlenderProc internals: ignored with a notice."""


FAMILY_READ = {"renderer": ("pixel_aspect_x",)}
"""BlenderProc 1.0 ``global.<family>`` keys that this family's modules read, although the same key in
``global.all`` configures nothing: its renderers set ``pixel_aspect_x`` when they render (translated into a
``camera.PixelAspect`` before the renderer, :func:`hybridgen.config.blenderproc.renderers.render_pixel_aspect`)."""
