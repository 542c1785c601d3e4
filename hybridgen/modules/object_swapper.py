"""``object.ObjectSwapper``: replace selected objects by random others of the same category, sized to the
original's box, at its pose, collision-free. A thin layer over :func:`hybridgen.sampling.swapping.swap_objects`
(its module doc defines sizing, alignment and what happens to instance ids)."""
from __future__ import annotations

import numpy as np

from ..input_paths import resolve_input
from ..config.registry import register_module
from ..config.schema import Param, positive
from ..errors import InputError
from ..io.mesh_loader import LOADERS, load_objects
from ..run.context import RunContext
from ..sampling.getters import parse_selector
from ..sampling.swapping import ALIGN_MODES, SCALE_MODES, swap_objects
from ..scene.frames import euler_xyz_to_matrix
from ..scene.mesh_object import MeshObject
from .base import Role
from .selecting import SelectingModule

POOL_KEYS = ("path", "category_id", "name", "up_axis", "attributes")


def _check_pool(value: list) -> str | None:
    for index, entry in enumerate(value):
        if not isinstance(entry, dict):
            return f"pool[{index}] must be a mapping with keys {list(POOL_KEYS)}, got {entry!r}"
        unknown = [k for k in entry if k not in POOL_KEYS]
        if unknown:
            return f"pool[{index}]: unknown key(s) {unknown}; known: {list(POOL_KEYS)}"
        if not isinstance(entry.get("path"), str) or not entry["path"]:
            return f"pool[{index}] needs a mesh 'path' ({', '.join(LOADERS)})"
        category = entry.get("category_id")
        if category is not None and (not isinstance(category, int) or isinstance(category, bool)):
            return f"pool[{index}].category_id must be an integer, got {category!r}"
        if entry.get("up_axis", "auto") not in ("auto", "Y", "Z"):
            return f"pool[{index}].up_axis must be auto, Y or Z, got {entry['up_axis']!r}"
        if not isinstance(entry.get("attributes", {}), dict):
            return f"pool[{index}].attributes must be a mapping"
    return None


@register_module("object.ObjectSwapper")
class ObjectSwapper(SelectingModule):
    """Swaps each selected object for a random pool object of the same category_id: scaled to the original's
    bounding box (scale_mode), placed at its pose (align), accepted when it intersects no other object
    (exact FCL tests), else the next candidate, up to max_tries. The replacement takes the original's
    instance id and place in the scene (the original is removed) and records attribute swapped_from.
    The pool: mesh files (pool, each one single-part object) and/or scene objects (pool_objects; their local
    mesh is used, their pose ignored; removed from the scene afterwards unless remove_pool_objects is
    false - their ids are then unused, never reassigned). A replacement's attributes: the candidate's
    (without those pool_objects selects by), the original's (copy_attributes) and swapped_from."""

    role = Role.MANIPULATOR

    selector_key = "objects_to_swap"
    params = (
        Param("objects_to_swap", "dict|list", doc="objects to replace (getter.Entity conditions, random_samples)"),
        Param("pool", "list", [], check=_check_pool,
              doc="candidate meshes: [{path, category_id, name, up_axis, attributes}]"),
        Param("pool_objects", "dict|list|null", None, doc="scene objects that are candidates (getter.Entity)"),
        Param("remove_pool_objects", "bool", True, doc="remove pool_objects from the scene after swapping"),
        Param("same_category", "bool", True, doc="candidates must have the original's category_id"),
        Param("scale_mode", "str", "fit_largest", choices=SCALE_MODES,
              doc="fit_largest: uniform, largest extents equal; fit_inside: uniform, inside the original's box; "
                  "per_axis: boxes equal"),
        Param("align", "str", "bottom", choices=ALIGN_MODES,
              doc="bottom: box bottoms (local z) and x/y centres coincide; center: box centres coincide"),
        Param("relative_rotation", "vec3", [0.0, 0.0, 0.0], "rad",
              "Euler XYZ rotation of the candidate in the original's frame, drawn per try", sampleable=True),
        Param("swap_probability", "float", 1.0, doc="chance that a selected object is swapped at all",
              check=lambda v: None if 0 <= v <= 1 else f"must be in 0..1, got {v!r}"),
        Param("ignore_collision_with", "dict|list|null", None,
              doc="objects a replacement may touch (e.g. the support it stands on after physics)"),
        Param("copy_attributes", "bool", True, doc="the replacement inherits the original's custom attributes"),
        Param("max_tries", "int", 20, doc="candidates tried per object", check=positive),
        Param("on_failure", "str", "error", choices=("error", "warn"),
              doc="no collision-free replacement within max_tries: error, or warn and keep the original"),
    )

    def _pool(self, context: RunContext) -> tuple[list[MeshObject], list[MeshObject]]:
        """(candidates, the scene objects among them)."""
        candidates: list[MeshObject] = []
        for index, entry in enumerate(self.config["pool"]):
            path = resolve_input(entry["path"], f"pool[{index}].path", noun="mesh file")
            objects = load_objects(path, name=entry.get("name"), category_id=entry.get("category_id"),
                                   up_axis=entry.get("up_axis", "auto"), attributes=entry.get("attributes"))
            if len(objects) != 1:
                raise InputError(f"pool[{index}] '{entry['path']}' has {len(objects)} parts; the swapper replaces "
                                 "an object by one single-part mesh")
            candidates.append(objects[0])
        in_scene: list[MeshObject] = []
        if self.config["pool_objects"] is not None:
            in_scene = parse_selector(self.config["pool_objects"], "pool_objects") \
                .select(context.scene.objects, context.rng)
            if not in_scene:
                raise InputError("pool_objects matches no object")
            candidates += in_scene
        if not candidates:
            raise InputError("the pool is empty: give pool (mesh files) or pool_objects (scene objects)")
        return candidates, in_scene

    def _marker_keys(self) -> list[str]:
        """Attributes the pool_objects selector tests (``pool: true``): not copied to replacements, which
        would otherwise be selected as pool objects themselves."""
        selector = parse_selector(self.config["pool_objects"], "pool_objects")
        conditions = selector.conditions if isinstance(selector.conditions, list) else [selector.conditions or {}]
        keys = {k.removeprefix("cp_") for c in conditions for k in c}
        return sorted(keys - {"name", "category_id", "instance_id"})

    def run(self, context: RunContext) -> None:
        cfg = self.config
        candidates, in_scene = self._pool(context)
        originals = [o for o in self.selected(context) if all(o is not p for p in in_scene)]
        if not originals:
            raise InputError("objects_to_swap selects only pool objects")
        if cfg["swap_probability"] < 1:
            originals = [o for o in originals if context.rng.random() < cfg["swap_probability"]]
        ignore = parse_selector(cfg["ignore_collision_with"], "ignore_collision_with") \
            .select(context.scene.objects, context.rng) if cfg["ignore_collision_with"] is not None else []

        def rotation() -> np.ndarray:
            return euler_xyz_to_matrix(self.value(context, "relative_rotation"))

        result = swap_objects(context.scene, originals, candidates, context.rng, max_tries=cfg["max_tries"],
                              same_category=cfg["same_category"], scale_mode=cfg["scale_mode"], align=cfg["align"],
                              relative_rotation=rotation, ignore=ignore, copy_attributes=cfg["copy_attributes"],
                              drop_attributes=self._marker_keys())
        if in_scene and cfg["remove_pool_objects"]:
            context.scene.remove(*in_scene)
        context.log(f"{self.module_name}: swapped {len(result.swapped)} of {len(originals)} object(s) in "
                    f"{result.tries} tries")
        if result.failed:
            def candidates_of(obj: MeshObject) -> int:
                return sum(1 for c in candidates if not cfg["same_category"] or c.category_id == obj.category_id)

            lacking = [o for o in result.failed if candidates_of(o) == 0]
            blocked = [o for o in result.failed if candidates_of(o) > 0]
            parts = []
            if lacking:
                parts.append("no pool candidate of the same category for " + ", ".join(
                    f"'{o.name}' (category_id {o.category_id})" for o in lacking[:8]))
            if blocked:
                parts.append(f"no collision-free replacement in {cfg['max_tries']} tries (max_tries) for " + ", ".join(
                    f"'{o.name}' ({candidates_of(o)} candidate(s))" for o in blocked[:8]))
            detail = "; ".join(parts)
            if cfg["on_failure"] == "error":
                raise InputError(detail + "; add pool candidates of that category, raise max_tries or use "
                                 "ignore_collision_with")
            context.log(f"{self.module_name}: {detail}; kept the original(s)", "warning")
