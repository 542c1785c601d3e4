"""Config text that the benchmarks and the tests share (plain YAML, so callers can still edit it with
``str.replace``): a ``camera.CameraSampler`` entry with cameras sampled on a shell around a point."""
from __future__ import annotations


def shell_cameras(*, width: int, height: int, count: int | str, fov: float | None = None,
                  radius: tuple[float, float] = (2, 4), elevation: tuple[float, float] | None = (20, 60),
                  look_at: str = "[0, 0, 0]") -> str:
    """The module entry's lines (indented for the ``modules`` list, no trailing newline): ``count`` cameras
    (a number, or a placeholder a caller replaces) of ``width`` x ``height`` pixels (horizontal ``fov`` in
    radians, default the camera's) on the shell of ``radius`` (m) and ``elevation`` (degrees; None: any)
    around the origin, looking at ``look_at`` (a point or a getter, as YAML)."""
    intrinsics = f"resolution_x: {width}, resolution_y: {height}" + ("" if fov is None else f", fov: {fov}")
    location = f"provider: sampler.Shell, center: [0, 0, 0], radius_min: {radius[0]}, radius_max: {radius[1]}"
    if elevation is not None:
        location += f",\n                     elevation_min: {elevation[0]}, elevation_max: {elevation[1]}"
    return f"""  - name: camera.CameraSampler
    config:
      intrinsics: {{{intrinsics}}}
      cam_poses:
        - number_of_samples: {count}
          location: {{{location}}}
          rotation: {{format: look_at, value: {look_at}}}"""
