"""The height Cycles takes from a scalar linked straight into a material output's Displacement socket:
:data:`PLUGIN_NAME`, a Mitsuba 3 texture over a 1-channel height texture, for Mitsuba's ``bumpmap``.

Cycles renders a material's displacement in "Bump Only" mode by dotting the displacement vector with the shading
normal N (``ShaderGraph::bump_from_displacement``: a Vector Math dot product with the Geometry node's Normal) and
bumping by that height. A scalar linked to the vector socket arrives as the vector (s, s, s), so the height is
``s (N.x + N.y + N.z)`` in world axes: BlenderProc's ``set_displacement_from_principled_shader_value`` (a Math
node's value) and v1's ``cf_color_link_to_displacement`` link one. A surface facing +z (or +x, +y) bumps by s, one
facing -y by -s - its bumps turned inside out - and one facing (1, 1, 1) by 1.73 s. Measured with bpy 4.2 under the
real BlenderProc (``tools/bump_vs_cycles.py --orientation minus_y | plus_x``: the same plane turned to face -y and
+x, Cycles' Normal pass turned back, correlates with the upward plane's at -1.00 and +1.00; hybridgen's radiance
facing -y was 17 % rms off Cycles' normals without the factor, 1.25 % with it). A Displacement node's vector is
N (h - mid) scale, whose dot product with N is the height itself: ambientCG / Poly Haven maps need no factor.

The texture's value and UV gradient are the nested texture's times that factor, N being the interpolated normal
at the point (``si.sh_frame.n``), held constant over the point's neighbourhood as Cycles holds it over its three
taps. JIT variants (a Python texture, traced into the kernel once).
"""
from __future__ import annotations

from functools import lru_cache
from typing import Any

PLUGIN_NAME = "hybridgen_linked_height"


def normal_factor(n: Any) -> Any:
    """``N . (1, 1, 1)``: what a scalar height becomes once Cycles dots (s, s, s) with the unit normal ``n``."""
    return n.x + n.y + n.z


@lru_cache(maxsize=None)
def register(variant: str) -> None:
    """Register :data:`PLUGIN_NAME` for ``variant`` (the active JIT variant). Property: ``height`` (a 1-channel
    texture)."""
    import mitsuba as mi

    class LinkedHeight(mi.Texture):  # type: ignore[misc, name-defined]
        def __init__(self, props: Any) -> None:
            super().__init__(props)
            self.height = props.get("height")

        def eval_1(self, si: Any, active: Any = True) -> Any:
            return normal_factor(si.sh_frame.n) * self.height.eval_1(si, active)

        def eval_1_grad(self, si: Any, active: Any = True) -> Any:
            return normal_factor(si.sh_frame.n) * self.height.eval_1_grad(si, active)

        def eval(self, si: Any, active: Any = True) -> Any:
            return mi.Color3f(self.eval_1(si, active))

        def mean(self) -> float:
            return float(self.height.mean())

        def is_spatially_varying(self) -> bool:
            return True

        def traverse(self, callback: Any) -> None:
            callback.put("height", self.height, mi.ParamFlags.Differentiable)

        def parameters_changed(self, keys: Any = None) -> None:
            pass

        def to_string(self) -> str:
            return f"HybridgenLinkedHeight[height={self.height}]"

    mi.register_texture(PLUGIN_NAME, lambda props: LinkedHeight(props))


def linked(height: dict[str, Any]) -> dict[str, Any]:
    """The ``mi.load_dict`` entry of ``height`` (a 1-channel texture's entry) read as a scalar link (the active
    variant must be a JIT one)."""
    import mitsuba as mi

    register(mi.variant())
    return {"type": PLUGIN_NAME, "height": height}
