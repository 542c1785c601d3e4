"""Blender's Noise Texture (3D, fBM) as array code: Perlin gradient noise on the integer lattice, hashed with Bob
Jenkins' lookup3 ``final`` mix (public domain), quintic fade, 12 edge gradients, Blender's output scale 0.982,
optional domain distortion and fractal detail.

The node's parameters mean what Blender's mean (Blender 4.2, "3D", "fBM", Normalize on): the texture is
evaluated at ``vector x scale``; ``detail`` is the number of extra octaves (fractional detail blends the last
one in), each octave ``lacunarity`` times finer and ``roughness`` times weaker; ``distortion`` shifts the point
by ``distortion`` x three independent signed noises first. The value is ``0.5 + 0.5 x fbm / amplitude sum``:
in [0, 1], 0.5 on lattice points, cells of 1 / scale. Written with plain operators over an :class:`ArrayOps`
(``NUMPY`` here; the path tracer passes Dr.Jit's), so the renderer and the tests run the same code.
"""
from __future__ import annotations

import struct
from typing import Any, Protocol

import numpy as np

NOISE_SCALE_3D = 0.982
"""Blender's scale of 3D Perlin noise into about [-1, 1]."""
_SEED3 = 0xDEADBEEF + (3 << 2) + 13  # lookup3 hashword's start value for 3 words, initval 13
_SEED2 = 0xDEADBEEF + (2 << 2) + 13
_MASK = 0xFFFFFFFF
TILE = 100000.0
"""Blender repeats the noise every 1e5 units on each axis (float precision); coordinates here are far below."""


class ArrayOps(Protocol):
    """The few array functions the noise needs beyond operators (float32 and uint32 arrays)."""

    def floor(self, x: Any) -> Any: ...
    def trunc(self, x: Any) -> Any: ...
    def select(self, mask: Any, a: Any, b: Any) -> Any: ...
    def abs(self, x: Any) -> Any: ...
    def clip(self, x: Any, low: float, high: float) -> Any: ...
    def power(self, x: Any, y: float) -> Any: ...
    def float(self, x: Any) -> Any: ...
    def lattice(self, x: Any) -> Any:
        """The float array ``x`` of whole numbers as uint32 (two's complement of its int32 value)."""


class _NumpyOps:
    """:class:`ArrayOps` over NumPy float32 / uint32 arrays."""

    def floor(self, x: Any) -> Any:
        return np.floor(x)

    def trunc(self, x: Any) -> Any:
        return np.trunc(x)

    def select(self, mask: Any, a: Any, b: Any) -> Any:
        return np.where(mask, a, b)

    def abs(self, x: Any) -> Any:
        return np.abs(x)

    def clip(self, x: Any, low: float, high: float) -> Any:
        return np.clip(x, np.float32(low), np.float32(high))

    def power(self, x: Any, y: float) -> Any:
        return np.power(x, np.float32(y))

    def float(self, x: Any) -> Any:
        return np.asarray(x, dtype=np.float32)

    def lattice(self, x: Any) -> Any:
        return np.asarray(x).astype(np.int32).view(np.uint32)


NUMPY = _NumpyOps()


def _rot(x: Any, k: int) -> Any:
    return (x << k) | (x >> (32 - k))


def _final(a: Any, b: Any, c: Any) -> Any:
    """lookup3's final mix of three uint32 words; its third word."""
    c = c ^ b
    c = c - _rot(b, 14)
    a = a ^ c
    a = a - _rot(c, 11)
    b = b ^ a
    b = b - _rot(a, 25)
    c = c ^ b
    c = c - _rot(b, 16)
    a = a ^ c
    a = a - _rot(c, 4)
    b = b ^ a
    b = b - _rot(a, 14)
    c = c ^ b
    c = c - _rot(b, 24)
    return c


def hash_uint3(kx: Any, ky: Any, kz: Any) -> Any:
    """lookup3 hash of three uint32 arrays (wrapping arithmetic; NumPy scalars wrap too, without a warning)."""
    with np.errstate(over="ignore"):
        return _final(kx + _SEED3, ky + _SEED3, kz + _SEED3)


def _hash_float2_to_float(x: float, y: float) -> float:
    """Hash of two float32 bit patterns as a float32 in [0, 1] (for the distortion offsets)."""
    words = [np.array([struct.unpack("<I", struct.pack("<f", v))[0]], np.uint32) for v in (x, y)]
    with np.errstate(over="ignore"):
        c = _final(words[0] + np.uint32(_SEED2), words[1] + np.uint32(_SEED2), np.array([_SEED2], np.uint32))
    return float(np.float32(c[0]) * np.float32(1.0 / _MASK))


def random_offset(seed: float) -> tuple[float, float, float]:
    """The per-noise offset Blender adds (100..200 on each axis) to decorrelate noises of one point."""
    return tuple(float(np.float32(100.0) + np.float32(_hash_float2_to_float(seed, float(i))) * np.float32(100.0))
                 for i in range(3))  # type: ignore[return-value]


def _fade(t: Any) -> Any:
    return t * t * t * (t * (t * 6.0 - 15.0) + 10.0)


def _grad(ops: ArrayOps, hashed: Any, x: Any, y: Any, z: Any) -> Any:
    """Dot product of the offset (x, y, z) with one of 12 edge gradients picked by the hash's low 4 bits."""
    h = hashed & 15
    u = ops.select(h < 8, x, y)
    vt = ops.select((h == 12) | (h == 14), x, z)
    v = ops.select(h < 4, y, vt)
    return ops.select((h & 1) != 0, -u, u) + ops.select((h & 2) != 0, -v, v)


def perlin(ops: ArrayOps, x: Any, y: Any, z: Any) -> Any:
    """Unscaled 3D Perlin noise (about [-1.02, 1.02]); 0 on lattice points."""
    fx, fy, fz = ops.floor(x), ops.floor(y), ops.floor(z)
    ix, iy, iz = ops.lattice(fx), ops.lattice(fy), ops.lattice(fz)
    x, y, z = x - fx, y - fy, z - fz
    u, v, w = _fade(x), _fade(y), _fade(z)
    corners = []
    for dz in (0, 1):
        for dy in (0, 1):
            for dx in (0, 1):
                corners.append(_grad(ops, hash_uint3(ix + dx, iy + dy, iz + dz), x - float(dx), y - float(dy),
                                     z - float(dz)))

    def mix(a: Any, b: Any, t: Any) -> Any:
        return (1.0 - t) * a + t * b

    lower = mix(mix(corners[0], corners[1], u), mix(corners[2], corners[3], u), v)
    upper = mix(mix(corners[4], corners[5], u), mix(corners[6], corners[7], u), v)
    return mix(lower, upper, w)


def signed_noise(ops: ArrayOps, x: Any, y: Any, z: Any) -> Any:
    """Blender's signed 3D noise: Perlin x 0.982, repeated every :data:`TILE`."""
    x, y, z = (c - TILE * ops.trunc(c * (1.0 / TILE)) for c in (x, y, z))
    return NOISE_SCALE_3D * perlin(ops, x, y, z)


def noise_texture(ops: ArrayOps, x: Any, y: Any, z: Any, scale: float = 5.0, detail: float = 2.0,
                  roughness: float = 0.5, lacunarity: float = 2.0, distortion: float = 0.0) -> Any:
    """Blender's Noise Texture "Fac" (= the red channel of "Color") at the point (x, y, z), in [0, 1]; defaults
    are the node's."""
    detail = min(max(float(detail), 0.0), 15.0)
    roughness = max(float(roughness), 0.0)
    x, y, z = x * scale, y * scale, z * scale
    if distortion != 0.0:
        shifts = [signed_noise(ops, x + o[0], y + o[1], z + o[2]) * distortion
                  for o in (random_offset(0.0), random_offset(1.0), random_offset(2.0))]
        x, y, z = x + shifts[0], y + shifts[1], z + shifts[2]
    octave_scale, amplitude, total_amplitude, total = 1.0, 1.0, 0.0, None
    for _ in range(int(detail) + 1):
        octave = signed_noise(ops, x * octave_scale, y * octave_scale, z * octave_scale) * amplitude
        total = octave if total is None else total + octave
        total_amplitude += amplitude
        amplitude *= roughness
        octave_scale *= lacunarity
    value = 0.5 * total * (1.0 / total_amplitude) + 0.5
    remainder = detail - int(detail)
    if remainder == 0.0:
        return value
    more = total + signed_noise(ops, x * octave_scale, y * octave_scale, z * octave_scale) * amplitude
    return (1.0 - remainder) * value + remainder * (0.5 * more * (1.0 / (total_amplitude + amplitude)) + 0.5)
