"""The one raster view of a scene and what is drawn with its buffers (albedo, diffuse color): shared by the label producer,
the denoising guides and the silhouette passes, so that the geometry is uploaded once per renderer."""
from __future__ import annotations

from ...scene.scene import Scene
from .albedo_pass import AlbedoPass
from .raster_view import RasterView


class SceneRaster:
    """The raster view of ``scene`` (built here, or ``view`` reused and left open) and its albedo and
    diffuse-color passes (each built on first use)."""

    def __init__(self, scene: Scene, *, normals_space: str = "camera", depth_background: float = float("inf"),
                 view: RasterView | None = None) -> None:
        self._own_view = view is None
        self.view = view or RasterView(scene, normals_space=normals_space, depth_background=depth_background)
        self._albedo: AlbedoPass | None = None
        self._diffuse_color: AlbedoPass | None = None

    @property
    def scene(self) -> Scene:
        return self.view.scene

    @property
    def albedo(self) -> AlbedoPass:
        if self._albedo is None:
            self._albedo = AlbedoPass(self.view)
        return self._albedo

    @property
    def diffuse_color(self) -> AlbedoPass:
        """Cycles' Diffuse Color pass (:mod:`.principled_diffuse`)."""
        if self._diffuse_color is None:
            self._diffuse_color = AlbedoPass(self.view, diffuse_color=True)
        return self._diffuse_color

    def release(self) -> None:
        for drawn in (self._albedo, self._diffuse_color):
            if drawn is not None:
                drawn.release()
        self._albedo = self._diffuse_color = None
        if self._own_view:
            self.view.release()
            self._own_view = False
