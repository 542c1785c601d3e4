"""``loader.AMASSLoader``: one posed SMPL-H body from an AMASS motion sequence, as BlenderProc builds it.

Layout (``data_path``, BlenderProc's ``resources/AMASS``):

- ``taxonomy.json``: a list of blocks; those with ``sub_data_id`` map a sub-dataset (e.g. ``CMU``) to its
  folder ``path`` (relative to ``data_path``);
- ``<path>/<subject>/<subject up to its first '_'>_<sequence:02d>_poses.npz``: ``poses`` (frames, 156)
  axis-angle (root 3, body 63, hands 90) and ``betas`` (shape coefficients);
- ``body_models/smplh/<gender>/model.npz`` and ``body_models/dmpls/<gender>/model.npz`` (both required).

What BlenderProc does, and hybridgen with it: ``subject_id`` is zero-padded to two digits (empty: a random
subject folder), ``sequence_id`` -1 draws a sequence file of the subject, ``frame_id`` -1 a frame;
``body_model_gender`` unset draws male, female or neutral. Only the 21 body joints of the frame pose the
body (``poses[frame, 3:66]``): root orientation, hands, translation and DMPL coefficients stay 0; the first
10 betas of the sequence shape it (DMPL with 8 components, all 0). The Y-up mesh is read like Blender's OBJ
importer (Y up -> Z up: ``(x, y, z) -> (x, -z, y)``), smooth shaded, and its origin moved to the bottom
centre of its bounding box (so the body stands on z = 0 around the z axis). The material is a skin tone drawn
from BlenderProc's 18 tones, scaled by a uniform factor in [0, 1) (specular = mean(rgb) / 255 as in
BlenderProc; its subsurface 0.2 has no hybridgen counterpart). No category_id is set (``add_properties``
``cp_category_id`` sets one).

Differences: BlenderProc names the object after the time of loading (``%Y%m%d_%H%M``, its temporary OBJ);
hybridgen names it after the sequence file and frame (e.g. ``10_01_poses.600``) so that runs are
reproducible. BlenderProc's random frame may be one past the end (an error there); hybridgen draws a valid one.
Draws use the run's random generator.
"""
from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..config.registry import register_module
from ..config.schema import Param
from ..errors import ConfigError
from ..run.context import RunContext
from ..scene.material import Material
from ..scene.mesh_object import MeshObject
from ..scene.shading import shade
from .base import Module, Role
from .dataset_support import (ADD_PROPERTIES, add_properties, dataset_file, dataset_folder,
                              move_origin_to_bottom_centre, read_json)
from .obj_loader import add_with_blender_names
from .smplh_body import SmplhBody

GENDERS = ("male", "female", "neutral")
NUM_BETAS = 10  # BlenderProc's (the AMASS authors' recommendation)
NUM_DMPLS = 8
BODY_JOINTS = slice(3, 66)  # poses columns of joints 1..21
SKIN_TONES = ("2D221E", "3C2E28", "4B3932", "5A453C", "695046", "785C50", "87675A", "967264", "A57E6E",
              "B48A78", "C39582", "D2A18C", "E1AC96", "F0B8A0", "FFC3AA", "FFCEB4", "FFDABE", "FFE5C8")
"""BlenderProc's human skin tones (hex RGB, used as linear values in 0..1)."""


def _integer(value: Any, key: str) -> int:
    try:
        return int(value)
    except (TypeError, ValueError):
        raise ConfigError(f"must be an integer, got {value!r}", key=key) from None


def _gender_problem(value: Any) -> str | None:
    return None if value is None or value in GENDERS else f"{value!r} is not one of {', '.join(GENDERS)}"


def sub_datasets(data_path: Path) -> dict[str, Path]:
    """``taxonomy.json``'s sub-dataset id -> folder."""
    blocks = read_json(data_path / "taxonomy.json", "data_path", "AMASS taxonomy file")
    if not isinstance(blocks, list):
        raise ConfigError(f"'{data_path / 'taxonomy.json'}' must hold a list of blocks", key="data_path")
    return {str(b["sub_data_id"]): data_path / str(b.get("path", "")) for b in blocks
            if isinstance(b, dict) and "sub_data_id" in b}


def sequence_file(folder: Path, subject: str, sequence: int) -> Path:
    """``<folder>/<subject>/<subject before '_'>_<sequence:02d>_poses.npz``."""
    return folder / subject / f"{subject.split('_')[0]}_{sequence:02d}_poses.npz"


def skin_material(rng: np.random.Generator) -> Material:
    """A skin tone as BlenderProc draws it (tone, then a brightness factor)."""
    tone = SKIN_TONES[int(rng.integers(len(SKIN_TONES)))]
    factor = float(rng.uniform(0.0, 1.0))
    rgb = [channel / 255 * factor for channel in bytes.fromhex(tone)]
    return Material(name="skin", base_color=(rgb[0], rgb[1], rgb[2], 1.0), specular=float(np.mean(rgb)) / 255)


@register_module("loader.AMASSLoader")
class AMASSLoader(Module):
    """Loads one body pose of an AMASS sequence (see the module doc)."""

    role = Role.LOADER
    params = (
        Param("data_path", "path", "resources/AMASS", doc="the AMASS folder holding taxonomy.json and "
              "body_models/"),
        Param("sub_dataset_id", "str", doc="a sub-dataset listed in taxonomy.json, e.g. CMU"),
        Param("body_model_gender", "str|null", None, check=_gender_problem, doc="male, female or neutral; unset: "
              "drawn"),
        Param("subject_id", "str|int", "", doc="subject folder number (zero-padded to 2 digits); empty: drawn"),
        Param("sequence_id", "int|str", -1, doc="sequence number of the subject; -1: drawn"),
        Param("frame_id", "int|str", -1, doc="frame of the sequence; -1: drawn"),
        ADD_PROPERTIES,
    )

    def _choose(self, context: RunContext, options: list[Path]) -> Path:
        return options[int(context.rng.integers(len(options)))]

    def _sequence(self, context: RunContext, root: Path) -> Path:
        """The sequence file."""
        datasets = sub_datasets(root)
        wanted = str(self.config["sub_dataset_id"])
        if wanted not in datasets:
            raise ConfigError(f"sub-dataset '{wanted}' is not in '{root / 'taxonomy.json'}' (listed: "
                              f"{', '.join(sorted(datasets)) or 'none'})", key="sub_dataset_id")
        folder = datasets[wanted]
        subject_id = str(self.config["subject_id"])
        if subject_id:
            subject = f"{_integer(subject_id, 'subject_id'):02d}"
        else:
            subjects = sorted(p for p in folder.glob("*") if p.is_dir())
            if not subjects:
                raise ConfigError(f"no subject folders in '{folder}'", key="subject_id")
            subject = self._choose(context, subjects).name
        sequence = _integer(self.config["sequence_id"], "sequence_id")
        if sequence < 0:
            files = sorted((folder / subject).glob("*_poses.npz"))
            if not files:
                raise ConfigError(f"no *_poses.npz sequences in '{folder / subject}'", key="subject_id")
            stem = self._choose(context, files).name
            sequence = _integer(stem[stem.find("_") + 1:stem.rfind("_")], "sequence_id")
        return dataset_file(sequence_file(folder, subject, sequence), "sequence_id",
                            f"AMASS sequence (subject {subject}, sequence {sequence})")

    def _frame(self, context: RunContext, path: Path) -> tuple[np.ndarray, np.ndarray, int]:
        """(63,) body pose, betas and the frame index."""
        with np.load(path) as data:
            for key in ("poses", "betas"):
                if key not in data.files:
                    raise ConfigError(f"AMASS sequence '{path}' has no array '{key}'", key="sequence_id")
            poses, betas = np.asarray(data["poses"], dtype=np.float64), np.asarray(data["betas"], dtype=np.float64)
        if poses.ndim != 2 or poses.shape[1] < BODY_JOINTS.stop:
            raise ConfigError(f"AMASS sequence '{path}': 'poses' has shape {poses.shape}, expected (frames, >= 66)",
                              key="sequence_id")
        frame = _integer(self.config["frame_id"], "frame_id")
        if frame < 0:
            frame = int(context.rng.integers(len(poses)))
        if frame >= len(poses):
            raise ConfigError(f"frame {frame} is beyond '{path}' (frames 0..{len(poses) - 1})", key="frame_id")
        return poses[frame, BODY_JOINTS], betas.ravel()[:NUM_BETAS], frame

    def run(self, context: RunContext) -> None:
        root = dataset_folder(self.config["data_path"], "data_path", "AMASS")
        gender = self.config["body_model_gender"]
        if gender is None:
            gender = GENDERS[int(context.rng.integers(len(GENDERS)))]
        path = self._sequence(context, root)
        body_pose, betas, frame = self._frame(context, path)
        models = root / "body_models"
        model_path = dataset_file(models / "smplh" / gender / "model.npz", "body_model_gender",
                                  "SMPL-H body model (see BlenderProc's AMASS example for the download)")
        dmpl_path = dataset_file(models / "dmpls" / gender / "model.npz", "body_model_gender",
                                 "DMPL model (see BlenderProc's AMASS example for the download)")
        body = SmplhBody.load(model_path, dmpl_path, NUM_BETAS, NUM_DMPLS, "body_model_gender")
        pose = np.concatenate([np.zeros(3), body_pose])  # root orientation 0, hands 0
        y_up = body.posed(pose, betas)
        z_up = np.stack([y_up[:, 0], -y_up[:, 2], y_up[:, 1]], axis=1)
        shaded = shade(z_up, body.faces, "SMOOTH")
        obj = MeshObject(name=f"{path.stem}.{frame}", vertices=shaded.vertices, faces=shaded.faces,
                         vertex_normals=shaded.vertex_normals, material=skin_material(context.rng))
        move_origin_to_bottom_centre([obj])
        add_properties([obj], self.config["add_properties"])
        add_with_blender_names(context, [obj], renamed=True)
