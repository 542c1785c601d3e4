"""hybridgen's Principled BSDF against Cycles values stored by tools/principled_vs_cycles.py --store (Blender 4.2,
4096 spp): the small test views' spheres rendered here at low spp must match each object's mean linear radiance
within what the noise allows. ``test_view``: dielectrics and metals (Mitsuba's Disney principled missed them by
7-55 %); ``test_view_layers``: sheen (over a near-black base, over a dielectric), subsurface without a
radius (Cycles' diffuse fallback) and an anisotropic metal (Blender's radial default tangent)."""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from tools.principled_vs_cycles import TEST_VIEWS, build_scene, object_masks, object_means

TABLE = Path(__file__).parent / "data" / "principled_cycles.json"
SPP = 64


@pytest.mark.parametrize("group", sorted(TEST_VIEWS))
def test_test_view_matches_cycles(jit_variant: str, tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
                                  group: str) -> None:
    from hybridgen.render.pathtrace.path_trace import PathTraceView
    from hybridgen.render.pathtrace.principled_material import ENV_VARIABLE
    from tools.principled_vs_cycles import hybridgen_settings

    key, objects = TEST_VIEWS[group]
    stored = json.loads(TABLE.read_text())[key]
    assert tuple(stored["objects"]) == objects
    monkeypatch.setenv(ENV_VARIABLE, "blender")
    scene = build_scene(stored["lighting"], *stored["res"], tmp_path, objects)
    masks = object_masks(scene, objects)
    assert {name: int(mask.sum()) for name, mask in masks.items()} == stored["pixels"]
    view = PathTraceView(scene, hybridgen_settings(stored["bounces"]), variant=jit_variant)
    means = object_means(view.render(scene.camera.keypoints[0], seed=0, spp=SPP), masks)
    for name in ("floor", *objects):
        # 2 % per channel: hybridgen's per-object noise at 64 spp is below 0.5 % (seeds 0-2 within 0.45 % of
        # Cycles; the second view within 0.7 %); Mitsuba's principled was 4.5-64 % off on every sphere of the first
        # view, hybridgen without sheen 5-19 % (a channel) on the sheen spheres, without the radial tangent 3-5 %
        np.testing.assert_allclose(means[name], stored["cycles"][name], rtol=0.02, err_msg=name)
