"""``object.PhysicsPositioning``: active objects fall onto passive ones (PyBullet) until they rest; their
final poses replace the old ones. A thin layer over :func:`hybridgen.physics.simulate_physics`."""
from __future__ import annotations

from ..config.registry import register_module
from ..config.schema import Param, positive
from ..errors import ConfigError, InputError
from ..physics.shapes import SHAPES, DecompositionSettings
from ..physics.settings import PhysicsSettings
from ..physics.simulate import simulate_physics
from ..run.context import RunContext
from ..sampling.getters import parse_selector
from .base import Role
from .selecting import SelectingModule


def _non_negative(value: float) -> str | None:
    return None if value >= 0 else f"must be >= 0, got {value!r}"


def _optional_positive(value: float | None) -> str | None:
    return None if value is None else positive(value)


def _decomposition(value: dict) -> str | None:
    try:
        DecompositionSettings.from_dict(value)
    except (InputError, TypeError) as exc:
        return str(exc)
    return None


@register_module("object.PhysicsPositioning")
class PhysicsPositioning(SelectingModule):
    """Rigid-body simulation (PyBullet, headless): the selected active objects fall under gravity onto the
    passive ones (which never move) for at least min_simulation_time, then until every active object
    moved less than the thresholds during one check interval, or max_simulation_time. Logs
    'simulated X s, N objects at rest'. An object attribute collision_shape overrides the shape kind for
    that object (e.g. convex_decomposition for one concave mesh)."""

    role = Role.MANIPULATOR

    selector_key = "active_objects"
    params = (
        Param("active_objects", "dict|list", {"physics": True},
              doc="objects that fall (getter.Entity conditions); default: attribute physics == true"),
        Param("passive_objects", "dict|list|null", None,
              doc="static obstacles; default: every object that is not active"),
        Param("min_simulation_time", "float", 4.0, "s", "simulate at least this long", check=_non_negative),
        Param("max_simulation_time", "float", 40.0, "s", "stop here even if objects still move", check=positive),
        Param("check_object_interval", "float", 1.0, "s", "rest check every this many simulated seconds",
              check=positive),
        Param("object_stopped_location_threshold", "float", 0.01, "m",
              "at rest: centre of mass moved less than this during one check interval", check=positive),
        Param("object_stopped_rotation_threshold", "float", 0.1, "rad",
              "at rest: turned less than this during one check interval", check=positive),
        Param("collision_shape", "str", "convex_hull", choices=tuple(s for s in SHAPES if s != "mesh"),
              doc="active objects: convex_hull, convex_decomposition (CoACD, cached on disk) or auto "
                  "(hull if a closed mesh fills >= 95% of it)"),
        Param("passive_collision_shape", "str", "auto", choices=SHAPES,
              doc="passive objects: auto (convex hull if the mesh is convex and closed, else its triangles), "
                  "mesh (exact triangles) or a convex kind"),
        Param("decomposition", "dict", {}, check=_decomposition,
              doc="CoACD parameters: threshold, max_convex_hull, preprocess_mode, resolution, mcts_*, seed"),
        Param("mass", "float|null", None, "kg", "mass of every active object; null: density x collision volume",
              check=_optional_positive, sampleable=True),
        Param("density", "float", 1000.0, "kg/m^3", "used when mass is null", check=positive, sampleable=True),
        Param("friction", "float", 0.5, doc="Coulomb friction coefficient", check=_non_negative, sampleable=True),
        Param("restitution", "float", 0.0, doc="bounciness 0..1", check=_non_negative, sampleable=True),
        Param("rolling_friction", "float", 0.0, doc="Bullet rolling friction (stops balls)", check=_non_negative),
        Param("spinning_friction", "float", 0.0, doc="Bullet torsional friction", check=_non_negative),
        Param("linear_damping", "float", 0.04, check=_non_negative, doc="velocity damping per second"),
        Param("angular_damping", "float", 0.1, check=_non_negative, doc="angular velocity damping per second"),
        Param("collision_margin", "float", 1e-4, "m",
              "Bullet's contact margin around every shape: resting objects end ~2x this apart", check=_non_negative),
        Param("time_step", "float", 1.0 / 240.0, "s", "fixed simulation step", check=positive),
        Param("substeps", "int|null", None, check=_optional_positive,
              doc="solver substeps per time step; null: enough that no object moves more than 40% of its "
                  "thickness per substep when falling from its start (at most 16)"),
        Param("solver_iterations", "int", 50, doc="constraint solver iterations per step", check=positive),
        Param("gravity", "vec3", [0.0, 0.0, -9.81], "m/s^2", "acceleration of gravity (world Z up)"),
        Param("on_not_at_rest", "str", "warn", choices=("warn", "error"),
              doc="objects still moving at max_simulation_time or fallen off: warn (keep their last pose) or error"),
    )

    def selected(self, context: RunContext) -> list:
        chosen = self.selector.select(context.scene.objects, context.rng)
        if not chosen:
            raise InputError(f"active_objects matches no object ({self.selector.conditions!r}); mark the objects "
                             "to drop with attributes: {physics: true} or set active_objects")
        return chosen

    def settings(self, context: RunContext) -> PhysicsSettings:
        """The simulation settings from this module's config (sampled values drawn once per run)."""
        cfg = self.config
        if cfg["min_simulation_time"] > cfg["max_simulation_time"]:
            raise ConfigError(f"{cfg['min_simulation_time']} s > max_simulation_time {cfg['max_simulation_time']} s",
                              key="min_simulation_time")
        return PhysicsSettings(
            min_time=cfg["min_simulation_time"], max_time=cfg["max_simulation_time"],
            check_interval=cfg["check_object_interval"],
            position_threshold=cfg["object_stopped_location_threshold"],
            rotation_threshold=cfg["object_stopped_rotation_threshold"],
            time_step=cfg["time_step"], substeps=cfg["substeps"], solver_iterations=cfg["solver_iterations"],
            gravity=tuple(float(g) for g in cfg["gravity"]),
            collision_shape=cfg["collision_shape"], passive_shape=cfg["passive_collision_shape"],
            mass=self.value(context, "mass"), density=self.value(context, "density"),
            friction=self.value(context, "friction"), restitution=self.value(context, "restitution"),
            rolling_friction=cfg["rolling_friction"], spinning_friction=cfg["spinning_friction"],
            linear_damping=cfg["linear_damping"], angular_damping=cfg["angular_damping"],
            collision_margin=cfg["collision_margin"],
            decomposition=DecompositionSettings.from_dict(cfg["decomposition"]))

    def run(self, context: RunContext) -> None:
        active = self.selected(context)
        if self.config["passive_objects"] is None:
            passive = [o for o in context.scene.objects if all(o is not a for a in active)]
        else:
            passive = parse_selector(self.config["passive_objects"], "passive_objects") \
                .select(context.scene.objects, context.rng)
            passive = [o for o in passive if all(o is not a for a in active)]
        if not passive:
            raise InputError("passive_objects selects no object (other than the active ones) to fall onto")
        result = simulate_physics(active, passive, self.settings(context))
        context.log(f"{self.module_name}: {result.summary()} ({len(active)} active, {len(passive)} passive, "
                    f"{result.substeps} substep(s); {result.wall_seconds:.1f} s wall)")
        if result.moving or result.fallen:
            names = ", ".join(repr(o.name) for o in [*result.moving, *result.fallen][:8])
            detail = f"not at rest after {result.simulated_time:.2f} s: {names}"
            if self.config["on_not_at_rest"] == "error":
                raise InputError(detail + "; raise max_simulation_time or loosen the rest thresholds")
            context.log(f"{self.module_name}: {detail}; they keep their last simulated pose", "warning")
