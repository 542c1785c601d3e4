"""BOP's JSON files: ``camera.json`` and the per-image ``scene_camera.json``, ``scene_gt.json``,
``scene_gt_info.json``, written as the BOP toolkit writes them, read back when a run appends to a chunk."""
from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import InputError


def camera_json_text(K: np.ndarray, depth_scale: float, height: int, width: int) -> str:
    """``camera.json``: the intrinsics ``K`` (px) of every image, ``depth_scale`` and the image size."""
    camera = {"cx": float(K[0, 2]), "cy": float(K[1, 2]), "depth_scale": depth_scale, "fx": float(K[0, 0]),
              "fy": float(K[1, 1]), "height": height, "width": width}
    return json.dumps(camera, sort_keys=True, indent=2)


def bop_json_text(content: dict[int, Any]) -> str:
    """BOP toolkit style: one line per image id, ids in numeric order, values with sorted keys."""
    lines = [f'  "{key}": {json.dumps(content[key], sort_keys=True)}' for key in sorted(content)]
    return "{\n" + ",\n".join(lines) + ("\n" if lines else "") + "}"


def load_bop_json(path: Path) -> dict[int, Any]:
    """A per-image BOP JSON file (``{"<im_id>": ...}``) with integer keys; InputError if it is not one."""
    try:
        content = json.loads(path.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(f"cannot append: '{path}' is missing (an incomplete BOP chunk?)") from None
    except (OSError, UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"cannot append to '{path}': {exc}") from None
    if not isinstance(content, dict) or not all(str(k).isdigit() for k in content):
        raise InputError(f"cannot append to '{path}': not a BOP per-image JSON object")
    return {int(k): v for k, v in content.items()}
