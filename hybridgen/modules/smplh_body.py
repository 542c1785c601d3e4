"""The SMPL-H body model in NumPy: shape blend shapes, pose blend shapes and linear blend skinning.

The published SMPL formulation (Loper et al. 2015; SMPL-H adds 30 hand joints, 52 in all) as the model npz
stores it (the file AMASS ships under ``body_models/smplh/<gender>/model.npz``):

- ``v_template`` (V, 3) rest vertices, metres, Y up; ``f`` (F, 3) faces;
- ``shapedirs`` (V, 3, B) shape directions (the first ``num_betas`` are used), optionally extended by a DMPL
  file's ``eigvec`` (V, 3, D) soft-tissue directions;
- ``posedirs`` (V, 3, 9 (J-1)) pose blend shapes on the flattened ``R_j - I`` of joints 1..J-1;
- ``J_regressor`` (J, V) joint positions from the shaped vertices; ``weights`` (V, J) skinning weights;
- ``kintree_table`` (2, J): row 0 the parent of each joint (the root's entry is ignored).

``pose`` is axis-angle per joint (radians, the rotation of a joint relative to its parent); vertices
``v = sum_j w_j G_j (v_posed - J_j)`` with ``G_j`` the joint's world rotation/translation along the chain.
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ConfigError

MODEL_KEYS = ("v_template", "f", "shapedirs", "posedirs", "J_regressor", "weights", "kintree_table")


def rodrigues(axis_angles: np.ndarray) -> np.ndarray:
    """(N, 3) axis-angle vectors (radians) -> (N, 3, 3) rotation matrices (identity for zero vectors)."""
    vectors = np.asarray(axis_angles, dtype=np.float64).reshape(-1, 3)
    angles = np.linalg.norm(vectors, axis=1)
    axes = np.divide(vectors, angles[:, None], out=np.zeros_like(vectors), where=angles[:, None] > 1e-12)
    x, y, z = axes.T
    zero = np.zeros_like(x)
    cross = np.stack([zero, -z, y, z, zero, -x, -y, x, zero], axis=1).reshape(-1, 3, 3)
    sin, cos = np.sin(angles)[:, None, None], np.cos(angles)[:, None, None]
    return np.eye(3) + sin * cross + (1.0 - cos) * (cross @ cross)


def _array(data: np.lib.npyio.NpzFile, path: Path, key: str, config_key: str) -> np.ndarray:
    if key not in data.files:
        raise ConfigError(f"'{path}' has no array '{key}' (an SMPL-H model npz holds {', '.join(MODEL_KEYS)})",
                          key=config_key)
    value = data[key]
    if value.dtype == object:  # a scipy sparse matrix pickled into the npz (some SMPL releases)
        value = value.item().toarray()
    return np.asarray(value, dtype=np.float64)


@dataclass(frozen=True)
class SmplhBody:
    """A loaded body model (see the module doc); ``dmpl_dirs`` (V, 3, D) or an empty (V, 3, 0)."""

    v_template: np.ndarray
    faces: np.ndarray
    shapedirs: np.ndarray
    dmpl_dirs: np.ndarray
    posedirs: np.ndarray
    joint_regressor: np.ndarray
    weights: np.ndarray
    parents: np.ndarray

    @classmethod
    def load(cls, model_path: Path, dmpl_path: Path | None, num_betas: int, num_dmpls: int,
             config_key: str) -> "SmplhBody":
        """Read the model npz (and the DMPL npz's ``eigvec``); errors name the file and ``config_key``."""
        with np.load(model_path, allow_pickle=True) as data:
            arrays = {key: _array(data, model_path, key, config_key) for key in MODEL_KEYS}
        dmpl = np.zeros(arrays["v_template"].shape + (0,))
        if dmpl_path is not None and num_dmpls > 0:
            with np.load(dmpl_path, allow_pickle=True) as data:
                dmpl = _array(data, dmpl_path, "eigvec", config_key)[:, :, :num_dmpls]
        body = cls(v_template=arrays["v_template"], faces=arrays["f"].astype(np.int64),
                   shapedirs=arrays["shapedirs"][:, :, :num_betas], dmpl_dirs=dmpl, posedirs=arrays["posedirs"],
                   joint_regressor=arrays["J_regressor"], weights=arrays["weights"],
                   parents=arrays["kintree_table"][0].astype(np.int64))
        body.check(model_path, config_key)
        return body

    @property
    def num_joints(self) -> int:
        return len(self.parents)

    def check(self, path: Path, config_key: str) -> None:
        """Consistent array shapes, parents before children; else one line naming the file."""
        count, joints = len(self.v_template), self.num_joints
        expected = {"shapedirs": (count, 3), "posedirs": (count, 3, 9 * (joints - 1)),
                    "J_regressor": (joints, count), "weights": (count, joints), "eigvec": (count, 3)}
        actual = {"shapedirs": self.shapedirs.shape[:2], "posedirs": self.posedirs.shape,
                  "J_regressor": self.joint_regressor.shape, "weights": self.weights.shape,
                  "eigvec": self.dmpl_dirs.shape[:2]}
        for key, shape in expected.items():
            if tuple(actual[key]) != shape:
                raise ConfigError(f"'{path}': '{key}' has shape {tuple(actual[key])}, expected {shape} "
                                  f"({count} vertices, {joints} joints)", key=config_key)
        if any(not 0 <= self.parents[j] < j for j in range(1, joints)) or self.faces.max(initial=0) >= count:
            raise ConfigError(f"'{path}': kintree_table must list each joint's parent before it and 'f' index "
                              f"the vertices", key=config_key)

    def shaped(self, betas: np.ndarray, dmpls: np.ndarray | None = None) -> np.ndarray:
        """(V, 3) rest vertices of the shape ``betas`` (missing ones 0) plus soft-tissue ``dmpls``."""
        directions = np.concatenate([self.shapedirs, self.dmpl_dirs], axis=2)
        coefficients = np.zeros(directions.shape[2])
        given = np.asarray(betas, dtype=np.float64).ravel()[:self.shapedirs.shape[2]]
        coefficients[:len(given)] = given
        if dmpls is not None:
            soft = np.asarray(dmpls, dtype=np.float64).ravel()[:self.dmpl_dirs.shape[2]]
            coefficients[self.shapedirs.shape[2]:self.shapedirs.shape[2] + len(soft)] = soft
        return self.v_template + directions @ coefficients

    def posed(self, pose: np.ndarray, betas: np.ndarray, dmpls: np.ndarray | None = None,
              translation: np.ndarray | None = None) -> np.ndarray:
        """(V, 3) vertices for ``pose`` ((J, 3) axis-angle, missing trailing joints 0) and the shape."""
        full = np.zeros((self.num_joints, 3))
        given = np.asarray(pose, dtype=np.float64).reshape(-1, 3)[:self.num_joints]
        full[:len(given)] = given
        rotations = rodrigues(full)
        v_shaped = self.shaped(betas, dmpls)
        joints = self.joint_regressor @ v_shaped
        v_posed = v_shaped + self.posedirs @ (rotations[1:] - np.eye(3)).ravel()
        world = np.zeros((self.num_joints, 4, 4))
        for j in range(self.num_joints):
            local = np.eye(4)
            local[:3, :3] = rotations[j]
            local[:3, 3] = joints[j] - (joints[self.parents[j]] if j > 0 else 0.0)
            world[j] = world[self.parents[j]] @ local if j > 0 else local
        skinning = world.copy()  # G_j with the rest joint position taken out: v -> G_j (v - J_j)
        skinning[:, :3, 3] -= np.einsum("jab,jb->ja", world[:, :3, :3], joints)
        blended = np.einsum("vj,jab->vab", self.weights, skinning)
        vertices = np.einsum("vab,vb->va", blended[:, :3, :3], v_posed) + blended[:, :3, 3]
        if translation is not None:
            vertices = vertices + np.asarray(translation, dtype=np.float64).reshape(3)
        return vertices
