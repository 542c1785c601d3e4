"""Euler XYZ and axis-angle rotations go through scipy's Rotation: checked against hand-built matrices."""
from __future__ import annotations

import numpy as np
import pytest

from hybridgen.scene.frames import euler_xyz_to_matrix, matrix_to_euler_xyz, rotation_about_axis


def _rx(a):
    return np.array([[1, 0, 0], [0, np.cos(a), -np.sin(a)], [0, np.sin(a), np.cos(a)]])


def _ry(b):
    return np.array([[np.cos(b), 0, np.sin(b)], [0, 1, 0], [-np.sin(b), 0, np.cos(b)]])


def _rz(c):
    return np.array([[np.cos(c), -np.sin(c), 0], [np.sin(c), np.cos(c), 0], [0, 0, 1]])


@pytest.mark.parametrize("seed", range(5))
def test_euler_xyz_is_blenders_order(seed):
    a, b, c = np.random.default_rng(seed).uniform(-np.pi, np.pi, 3)
    np.testing.assert_allclose(euler_xyz_to_matrix([a, b, c]), _rz(c) @ _ry(b) @ _rx(a), atol=1e-14)
    angles = matrix_to_euler_xyz(euler_xyz_to_matrix([a, b / 2, c]))
    np.testing.assert_allclose(euler_xyz_to_matrix(angles), euler_xyz_to_matrix([a, b / 2, c]), atol=1e-14)


def test_axis_angle_right_hand_rule():
    np.testing.assert_allclose(rotation_about_axis(np.array([0, 0, 2.0]), np.pi / 2) @ [1, 0, 0], [0, 1, 0],
                               atol=1e-15)
    axis = np.array([1.0, 2.0, -0.5])
    r = rotation_about_axis(axis, 0.7)
    np.testing.assert_allclose(r @ axis, axis, atol=1e-14)  # the axis is fixed
    np.testing.assert_allclose(np.trace(r), 1 + 2 * np.cos(0.7), atol=1e-14)
    with pytest.raises(ValueError):
        euler_xyz_to_matrix([0.1, 0.2])


def test_euler_xyz_is_scipys_matrix_bit_for_bit_without_importing_it():
    """euler_xyz_to_matrix computes SciPy's from_euler("xyz").as_matrix() itself (a process that poses objects
    need not import scipy.spatial): the same float64 bits for random, rounded and axis-aligned angles."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(7)
    angles = [*rng.uniform(-7.0, 7.0, (3000, 3)), *np.round(rng.uniform(-4.0, 4.0, (1000, 3)), 1),
              *(np.pi / 2 * rng.integers(-4, 5, (200, 3))), [0.0, 0.0, 1e-300], [-0.0, 0.0, 0.5], [1e6, -3e5, 2.0]]
    for values in angles:
        expected = Rotation.from_euler("xyz", values).as_matrix()
        assert np.array_equal(euler_xyz_to_matrix(values), expected), values


def test_posing_objects_imports_no_scipy():
    import subprocess
    import sys

    script = ("import sys, hybridgen as hg; hg.object_pose([1, 2, 3], [0.3, -0.2, 1.1]); "
              "print('scipy' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "False"


def test_matrix_to_euler_is_scipys_bit_for_bit() -> None:
    """hybridgen's own decomposition (no SciPy import) gives SciPy's angles to the last bit: random rotations,
    Euler-built ones, quarter turns, slightly non-unit ones, and the gimbal locks SciPy handles itself."""
    import warnings

    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(11)
    matrices = [np.eye(3), np.diag([1.0, -1, -1]), np.diag([-1.0, 1, -1]), np.diag([-1.0, -1, 1])]
    for _ in range(1500):
        matrices.append(Rotation.random(random_state=rng).as_matrix())
        matrices.append(euler_xyz_to_matrix(rng.uniform(-np.pi, np.pi, 3)))
        matrices.append(euler_xyz_to_matrix(rng.integers(-2, 3, 3) * np.pi / 2))
        matrices.append(euler_xyz_to_matrix(rng.uniform(-np.pi, np.pi, 3)) * (1 + 1e-9))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # SciPy's gimbal-lock warning
        for matrix in matrices:
            ours, scipys = matrix_to_euler_xyz(matrix), Rotation.from_matrix(matrix).as_euler("xyz")
            assert ours.tobytes() == scipys.tobytes(), matrix.tolist()


def test_matrix_to_euler_does_not_import_scipy() -> None:
    import subprocess
    import sys

    probe = ("import sys; from hybridgen.scene.frames import matrix_to_euler_xyz, euler_xyz_to_matrix; "
             "print(matrix_to_euler_xyz(euler_xyz_to_matrix([0.3, -0.2, 1.1])).round(12).tolist(), "
             "'scipy.spatial' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "[0.3, -0.2, 1.1] False"
