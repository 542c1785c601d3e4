"""``bproc.types.Light``: a Blender light object over hybridgen's :class:`~hybridgen.scene.light.Light`
(BlenderProc's LightUtility).

Values are Blender's: ``energy`` in W (POINT, SPOT, AREA) or W/m^2 (SUN strength), ``color`` linear RGB,
``radius`` the soft-shadow size (m, Blender's ``shadow_soft_size``). A new light has Blender's defaults
(energy 10, white, radius 0.25 m). SUN, SPOT and AREA lights shine along their local -z axis. Every value can
be keyed per frame (``frame=``), like the pose.
"""
from __future__ import annotations

from typing import Any, Callable

from ...errors import InputError
from ...scene.light import LIGHT_TYPES, Light as SceneLight
from ..session import Animated
from .entity import Entity
from .unsupported import unsupported_method

DEFAULT_ENERGY = 10.0
DEFAULT_RADIUS = 0.25


class Light(Entity):
    """A light; ``scene_light(frame)`` is what a render of that frame sees."""

    TYPE = "LIGHT"

    def __init__(self, light_type: str = "POINT", name: str = "light", blender_obj: Any = None) -> None:
        if blender_obj is not None:
            raise InputError("bproc.types.Light(blender_obj=...) is not supported by hybridgen yet "
                             "(there are no Blender objects)")
        super().__init__(name)
        self._type = Animated(self._checked_type(light_type))
        self._energy = Animated(DEFAULT_ENERGY)
        self._color = Animated((1.0, 1.0, 1.0))
        self._radius = Animated(DEFAULT_RADIUS)
        self._distance = Animated(40.0)

    @staticmethod
    def _checked_type(light_type: str) -> str:
        upper = str(light_type).upper()
        if upper not in LIGHT_TYPES:
            raise InputError(f"light type must be one of {', '.join(LIGHT_TYPES)}, got {light_type!r}")
        return upper

    def set_energy(self, energy: float, frame: int | None = None) -> None:
        """W (W/m^2 for SUN); keyed at ``frame`` if given."""
        if not float(energy) >= 0:
            raise InputError(f"light '{self.get_name()}': energy must be >= 0, got {energy}")
        self._energy.set(float(energy), frame)

    def set_radius(self, radius: float, frame: int | None = None) -> None:
        self._radius.set(float(radius), frame)

    def set_color(self, color: Any, frame: int | None = None) -> None:
        """Linear RGB (a fourth value is ignored, as Blender's light color has three)."""
        values = tuple(float(c) for c in list(color)[:3])
        if len(values) != 3:
            raise InputError(f"light color takes 3 numbers, got {list(color)}")
        self._color.set(values, frame)

    def set_distance(self, distance: float, frame: int | None = None) -> None:
        """Blender's light ``distance`` (Eevee only: Cycles ignores it, and so does hybridgen's color)."""
        self._distance.set(float(distance), frame)

    def set_type(self, light_type: str, frame: int | None = None) -> None:
        self._type.set(self._checked_type(light_type), frame)

    def get_energy(self, frame: int | None = None) -> float:
        return float(self._energy.at(frame))

    def get_radius(self, frame: int | None = None) -> float:
        return float(self._radius.at(frame))

    def get_color(self, frame: int | None = None) -> list[float]:
        return list(self._color.at(frame))

    def get_distance(self, frame: int | None = None) -> float:
        return float(self._distance.at(frame))

    def get_type(self, frame: int | None = None) -> str:
        return str(self._type.at(frame))

    setup_as_projector: Callable[..., Any] = unsupported_method("Light", "setup_as_projector")

    def clear_keyframes(self) -> None:
        super().clear_keyframes()
        for prop in (self._type, self._energy, self._color, self._radius, self._distance):
            prop.keys.clear()

    def scene_light(self, frame: int | None) -> SceneLight:
        """The hybridgen light of this light at ``frame`` (pose and every value as keyed)."""
        return SceneLight(self.get_name(), type=self.get_type(frame), color=tuple(self.get_color(frame)),  # type: ignore[arg-type]
                          energy=self.get_energy(frame), local2world=self.world_matrix(frame),
                          radius=self.get_radius(frame))

    def _copy_state_from(self, other: Entity) -> None:
        super()._copy_state_from(other)
        import copy

        assert isinstance(other, Light)
        for name in ("_type", "_energy", "_color", "_radius", "_distance"):
            setattr(self, name, copy.deepcopy(getattr(other, name)))
