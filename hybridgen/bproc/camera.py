"""``bproc.camera``: camera poses per frame and intrinsics (BlenderProc's CameraUtility).

Poses are Blender-axes ``cam2world`` 4x4 matrices (x right, y up, looking along -z; metres), keyed per frame
as BlenderProc keys them: ``add_camera_pose(M)`` without a frame appends one at ``frame_end`` and extends the
rendered range. Intrinsics are Blender's lens, sensor, resolution, pixel aspect, shift and clip range
(:mod:`hybridgen.bproc.blender_camera`)."""
from __future__ import annotations

from typing import Any, Sequence

import numpy as np

from ..errors import InputError
from ..scene.frames import blender_to_opencv, forward_to_rotation_blender
from .session import SESSION, current_intrinsics
from .types.entity import matrix4
from .types.unsupported import fail


def add_camera_pose(cam2world_matrix: Any, frame: int | None = None) -> int:
    """Key the camera's Blender-axes cam2world at ``frame`` (default: ``frame_end``, a new frame); returns the
    frame."""
    pose = matrix4(cam2world_matrix, "cam2world_matrix")
    if frame is None:
        frame = SESSION.frame_end
    frame = int(frame)
    SESSION.frame_end = max(SESSION.frame_end, frame + 1)
    SESSION.camera.pose.set(pose, frame)
    return frame


def get_camera_pose(frame: int | None = None) -> np.ndarray:
    """The Blender-axes cam2world at ``frame`` (None: the current pose)."""
    return np.array(SESSION.camera.pose.at(frame))


def rotation_from_forward_vec(forward_vec: Sequence[float], up_axis: str = "Y",
                              inplane_rot: float | None = None) -> np.ndarray:
    """The 3x3 camera rotation (Blender axes) looking along ``forward_vec``, its image up as close to world
    +Z as possible (Blender's ``to_track_quat('-Z', 'Y')``), then turned by ``inplane_rot`` rad about the view
    axis."""
    if str(up_axis).upper() != "Y":
        raise InputError(f"bproc.camera.rotation_from_forward_vec(up_axis={up_axis!r}) is not supported by "
                         "hybridgen yet (only 'Y')")
    forward = np.asarray(forward_vec, dtype=np.float64).reshape(3)
    if not np.all(np.isfinite(forward)) or not np.any(forward):
        raise InputError(f"forward_vec must be a finite non-zero 3-vector, got {forward.tolist()}")
    return forward_to_rotation_blender(forward, float(inplane_rot or 0.0))


def set_resolution(image_width: int | None = None, image_height: int | None = None) -> None:
    """The render resolution in pixels (the lens is kept)."""
    set_intrinsics_from_blender_params(None, image_width, image_height)


def set_intrinsics_from_blender_params(lens: float | None = None, image_width: int | None = None,
                                       image_height: int | None = None, clip_start: float | None = None,
                                       clip_end: float | None = None, pixel_aspect_x: float | None = None,
                                       pixel_aspect_y: float | None = None, shift_x: float | None = None,
                                       shift_y: float | None = None, lens_unit: str | None = None) -> None:
    """Blender's camera parameters; ``lens`` is a focal length in mm (``lens_unit`` ``MILLIMETERS``) or a
    field of view in rad (``FOV``, BlenderProc's default unit)."""
    camera = SESSION.camera.blender
    unit = str(lens_unit or camera.lens_unit).upper()
    if unit not in ("FOV", "MILLIMETERS"):
        raise InputError(f"no such lens unit: {lens_unit!r} (FOV or MILLIMETERS)")
    camera.lens_unit = unit
    if lens is not None:
        if unit == "MILLIMETERS":
            if lens < 1:
                raise InputError(f"the focal length is smaller than 1 mm, which Blender does not allow: {lens}")
            camera.lens = float(lens)
        else:
            camera.set_fov(float(lens))
    for name, value in (("resolution_x", image_width), ("resolution_y", image_height)):
        if value is not None:
            setattr(camera, name, int(value))
    for name, value in (("clip_start", clip_start), ("clip_end", clip_end), ("pixel_aspect_x", pixel_aspect_x),
                        ("pixel_aspect_y", pixel_aspect_y), ("shift_x", shift_x), ("shift_y", shift_y)):
        if value is not None:
            setattr(camera, name, float(value))
    camera.intrinsics()  # one line now for values no camera can have


def set_intrinsics_from_K_matrix(K: Any, image_width: int, image_height: int, clip_start: float | None = None,
                                 clip_end: float | None = None) -> None:  # noqa: N802 - BlenderProc's name
    """Intrinsics from a 3x3 K (px); fx != fy becomes Blender's pixel aspect."""
    camera = SESSION.camera.blender
    camera.set_K(np.asarray(K, dtype=np.float64), int(image_width), int(image_height))
    camera.lens_unit = "MILLIMETERS"
    set_intrinsics_from_blender_params(clip_start=clip_start, clip_end=clip_end)


def get_intrinsics_as_K_matrix() -> np.ndarray:  # noqa: N802
    """The current 3x3 K (px)."""
    return SESSION.camera.blender.K()


def get_fov() -> tuple[float, float]:
    """(horizontal, vertical) field of view, rad."""
    return SESSION.camera.blender.fov()


def get_sensor_size(cam: Any = None) -> float:
    """The sensor side the lens is measured against (mm)."""
    return SESSION.camera.blender.sensor_size()


def get_view_fac_in_px(cam: Any = None, pixel_aspect_x: float | None = None, pixel_aspect_y: float | None = None,
                       resolution_x_in_px: int | None = None, resolution_y_in_px: int | None = None) -> float:
    """Pixels the sensor size spans (Blender's sensor fit) for the given or current values."""
    import copy

    camera = copy.copy(SESSION.camera.blender)
    for name, value in (("pixel_aspect_x", pixel_aspect_x), ("pixel_aspect_y", pixel_aspect_y),
                        ("resolution_x", resolution_x_in_px), ("resolution_y", resolution_y_in_px)):
        if value is not None:
            setattr(camera, name, value)
    return camera.view_factor()


def set_stereo_parameters(convergence_mode: str, convergence_distance: float, interocular_distance: float) -> None:
    """Stereo pair settings for ``bproc.renderer.toggle_stereo``: the left eye is the camera pose, the right eye
    ``interocular_distance`` m along its +x (Blender's pivot LEFT). ``PARALLEL`` (BlenderProc's default) is the
    mode hybridgen renders; ``OFFAXIS``/``TOE`` stop a stereo render with one line."""
    mode = str(convergence_mode).upper()
    if mode not in ("OFFAXIS", "PARALLEL", "TOE"):
        raise InputError(f"no such stereo convergence mode: {convergence_mode!r} (OFFAXIS, PARALLEL or TOE)")
    if not float(interocular_distance) > 0:
        raise InputError(f"interocular_distance must be > 0 m, got {interocular_distance}")
    camera = SESSION.camera
    camera.convergence_mode, camera.convergence_distance = mode, float(convergence_distance)
    camera.interocular_distance = float(interocular_distance)


def add_depth_of_field(focal_point_obj: Any, fstop_value: float, aperture_blades: int = 0,
                       aperture_rotation: float = 0.0, aperture_ratio: float = 1.0,
                       focal_distance: float = -1.0) -> None:
    """A thin lens of f-stop ``fstop_value`` (aperture radius = lens / (2 f-stop)) focused on the origin of
    ``focal_point_obj`` at every frame (it may move), or without one at ``focal_distance`` m along the view axis
    (:class:`hybridgen.scene.depth_of_field.DepthOfField`; color only, as in Cycles the labels stay sharp). The
    aperture is a round disk: polygonal blades (3 or more) and an anamorphic ratio other than 1 stop with one
    line."""
    if int(aperture_blades) >= 3:
        fail(f"bproc.camera.add_depth_of_field(aperture_blades={aperture_blades})", "the aperture is a round disk")
    if float(aperture_ratio) != 1.0:
        fail(f"bproc.camera.add_depth_of_field(aperture_ratio={aperture_ratio})", "the aperture is a round disk")
    if not float(fstop_value) > 0:
        raise InputError(f"fstop_value must be > 0, got {fstop_value}")
    if focal_point_obj is not None:
        SESSION.camera.depth_of_field = {"fstop": float(fstop_value), "focus": focal_point_obj}
    elif float(focal_distance) >= 0.0:
        SESSION.camera.depth_of_field = {"fstop": float(fstop_value), "distance": max(float(focal_distance), 1e-6)}
    else:
        raise InputError("Either a focal_point_obj have to be given or the focal_distance has to be higher than zero.")


def set_lens_distortion(k1: float, k2: float, k3: float = 0.0, p1: float = 0.0, p2: float = 0.0,
                        use_global_storage: bool = False) -> np.ndarray:
    """Brown-Conrady distortion (undistorted-to-distorted, CalLab's p1/p2 order;
    :mod:`hybridgen.scene.lens_distortion`): the camera is enlarged (resolution, principal point) to the pinhole
    render the distorted image needs, and the (2, H * W) mapping (rows, columns in that render, per distorted
    pixel) is returned for ``bproc.postprocessing.apply_lens_distortion``."""
    from ..scene.lens_distortion import BrownConrady, plan_distortion

    plan = plan_distortion(current_intrinsics(), BrownConrady(float(k1), float(k2), float(k3), float(p1), float(p2)))
    camera = SESSION.camera.blender
    set_intrinsics_from_K_matrix(plan.render.K, plan.render.width, plan.render.height, camera.clip_start,
                                 camera.clip_end)
    return plan.mapping


def is_point_inside_camera_frustum(point: Sequence[float], clip_start: float | None = None,
                                   clip_end: float | None = None, frame: int | None = None) -> bool:
    """Whether the world point (m) is inside the view frustum of the camera pose at ``frame`` (None: the
    current pose): between the clip distances and inside the image (:mod:`hybridgen.scene.frustum`)."""
    from ..scene.frustum import inside_frustum

    pose = blender_to_opencv(get_camera_pose(frame))
    return bool(inside_frustum(np.asarray(point, dtype=np.float64), pose, current_intrinsics(), clip_start,
                               clip_end)[0])


def get_camera_frustum(clip_start: float | None = None, clip_end: float | None = None,
                       frame: int | None = None) -> np.ndarray:
    """(8, 3) world corners (m) of the view frustum of the camera pose at ``frame`` (None: the current pose)
    between the clip distances (default: the camera's), in normalized device coordinates' order:
    ``itertools.product((-1, 1), repeat=3)`` over (left/right, bottom/top, near/far)
    (:func:`hybridgen.scene.frustum.frustum_corners`)."""
    from ..scene.frustum import frustum_corners

    pose = blender_to_opencv(get_camera_pose(frame))
    return frustum_corners(pose, current_intrinsics(), clip_start, clip_end)


def get_camera_frustum_as_object(clip_start: float | None = None, clip_end: float | None = None,
                                 frame: int | None = None) -> Any:
    """A new mesh object "Camera Frustum": Blender's cube with each vertex moved to the frustum corner of its
    sign pattern (:func:`get_camera_frustum`), in world coordinates at an identity pose."""
    from .object import create_primitive

    corners = get_camera_frustum(clip_start, clip_end, frame)
    cube = create_primitive("CUBE")
    cube.set_name("Camera Frustum")
    part = cube.parts[0]
    signs = (part.vertices > 0).astype(int)  # Blender's cube: vertex (sx, sy, sz) is product's index 4x + 2y + z
    part.vertices = corners[signs @ np.array([4, 2, 1])]
    part.forget_derived()
    return cube


from .camera_validation import (decrease_interest_score, perform_obstacle_in_view_check,  # noqa: E402
                                scene_coverage_score, visible_objects)

from .camera_projection import (depth_at_points_via_raytracing, depth_via_raytracing,  # noqa: E402
                                pointcloud_from_depth, project_points, unproject_points)

from .camera_novelty import check_novel_pose  # noqa: E402


def set_camera_parameters_from_config_file(camera_intrinsics_file_path: str, read_the_extrinsics: bool = False,
                                           camera_index: int = 0) -> tuple[int, int, np.ndarray]:
    """Intrinsics, lens distortion and (with ``read_the_extrinsics``) a new camera pose from camera
    ``camera_index`` of a DLR-RMC calibration file (:mod:`.dlr_calibration`). Returns ``(width, height, mapping)``:
    the file's image size (px, the size ``apply_lens_distortion`` makes) and the (2, height * width) mapping of
    :func:`set_lens_distortion`."""
    from .dlr_calibration import read_camera_calibration

    calibration = read_camera_calibration(camera_intrinsics_file_path, read_the_extrinsics, camera_index)
    set_intrinsics_from_K_matrix(calibration.K, calibration.width, calibration.height)
    mapping = set_lens_distortion(*calibration.distortion)
    if calibration.cam2world is not None:
        add_camera_pose(calibration.cam2world)
    return calibration.width, calibration.height, mapping
