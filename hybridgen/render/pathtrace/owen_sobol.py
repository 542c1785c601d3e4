"""Shuffled, Owen-scrambled Sobol samples (Burley 2020, "Practical Hash-based Owen Scrambling"), as Cycles'
"Sobol-Burley" pattern: an unbiased low-discrepancy sampler for hybridgen's Python integrators.

Every call of :meth:`OwenSobol.next_2d` (or ``next_1d``) is its own *dimension set*: the first two dimensions
of the Sobol sequence (a (0, 2)-sequence in base 2) at a shuffled sample index, each dimension Owen-scrambled
with its own hash of the sequence's seed and the set. Per set:

- the index is shuffled by a nested uniform scramble of its bits (reversed, hashed as Laine and Karras with
  Vegdahl's constants, reversed back): the first 2^m samples of a pattern are a whole block of 2^m
  consecutive Sobol points (the index's bits from m up are the same for all of them), so every power-of-two
  prefix of a pattern, and both halves adaptive sampling compares, stay (0, m, 2)-nets;
- the point's digits are scrambled as Owen's nested uniform scramble (digit k flipped by a hash of the digits
  before it), so each sample is uniform on the unit square and the pattern keeps its stratification.

Sets are decorrelated by their own seeds (a full-avalanche hash of the sequence seed and the set index:
:func:`mix`), so the joint distribution of any two sets is uniform in expectation - unlike Mitsuba 3.9's
``ldsampler``, whose dimensions share one XOR scramble and permutation seeds one apart (two rounds of TEA), which
rendered the window room of tools/color_quality.py 0.69 % too bright (docs/color_quality.md). Only the low
:data:`INDEX_BITS` bits of the index are turned into Sobol digits (after the shuffle, the bits above are a
constant per block: a digital shift the Owen scramble absorbs); each further block of ``2^INDEX_BITS`` samples of
a sequence is a pattern of its own (the seed hashed with the block's number).

The fields are Dr.Jit state (``DRJIT_STRUCT``), so a symbolic loop carries the set counter from one iteration
to the next.
"""
from __future__ import annotations

from typing import Any

INDEX_BITS = 16
"""Bits of the (shuffled) sample index turned into Sobol digits: blocks of 65536 samples are one pattern each."""
MAX_SAMPLES = 1 << INDEX_BITS
"""Samples of one pattern; a sequence's next samples come from a pattern of their own."""


def sobol_direction_numbers() -> list[int]:
    """Direction numbers (32-bit, most significant digit first) of Sobol's second dimension, the Pascal matrix
    mod 2: v_0 = 2^31, v_k = v_(k-1) xor (v_(k-1) >> 1)."""
    out, v = [], 1 << 31
    for _ in range(32):
        out.append(v)
        v ^= v >> 1
    return out


_DIRECTIONS = sobol_direction_numbers()


def mix(x: Any) -> Any:
    """A full-avalanche 32-bit integer hash ("lowbias32", C. Wellons), Dr.Jit UInt32 or Python int."""
    if isinstance(x, int):
        x &= 0xFFFFFFFF
        x ^= x >> 16
        x = (x * 0x7FEB352D) & 0xFFFFFFFF
        x ^= x >> 15
        x = (x * 0x846CA68B) & 0xFFFFFFFF
        return x ^ (x >> 16)
    x = x ^ (x >> 16)  # (no in-place operators: they would change the caller's Dr.Jit array)
    x = x * 0x7FEB352D
    x = x ^ (x >> 15)
    x = x * 0x846CA68B
    return x ^ (x >> 16)


def reverse_bits(x: Any) -> Any:
    """The 32 bits of Dr.Jit UInt32 ``x`` in reverse order."""
    x = ((x >> 1) & 0x55555555) | ((x & 0x55555555) << 1)
    x = ((x >> 2) & 0x33333333) | ((x & 0x33333333) << 2)
    x = ((x >> 4) & 0x0F0F0F0F) | ((x & 0x0F0F0F0F) << 4)
    x = ((x >> 8) & 0x00FF00FF) | ((x & 0x00FF00FF) << 8)
    return (x >> 16) | (x << 16)


def reversed_owen(x: Any, seed: Any) -> Any:
    """Owen's nested uniform scramble in the bit-reversed domain (bit k of the result depends on bits <= k of
    ``x``): Laine-Karras' hash with Vegdahl's improved constants, as Cycles' ``reversed_bit_owen``."""
    x = x ^ (x * 0x3D20ADEA)
    x = x + seed
    x = x * ((seed >> 16) | 1)
    x = x ^ (x * 0x05526C56)
    return x ^ (x * 0x53A22864)


def _sobol_reversed(index: Any) -> tuple[Any, Any]:
    """Sobol's first two dimensions at ``index`` (its low :data:`INDEX_BITS` bits), bit-reversed (least
    significant = first digit): dimension 0 is the index itself (van der Corput)."""
    import drjit as dr
    import mitsuba as mi

    y = mi.UInt32(0)
    for bit in range(INDEX_BITS):
        direction = reverse_bits_int(_DIRECTIONS[bit])
        y = y ^ dr.select(((index >> bit) & 1) != 0, mi.UInt32(direction), mi.UInt32(0))
    return index & (MAX_SAMPLES - 1), y


def reverse_bits_int(x: int) -> int:
    """The 32 bits of Python int ``x`` in reverse order."""
    return int(f"{x & 0xFFFFFFFF:032b}"[::-1], 2)


def _to_unit(reversed_digits: Any) -> Any:
    """A float in [0, 1) from bit-reversed digits (24 of them: float32's mantissa, never rounded up to 1)."""
    import mitsuba as mi

    return mi.Float(reverse_bits(reversed_digits) >> 8) * (1.0 / (1 << 24))


def sample_2d(index: Any, seed: Any) -> tuple[Any, Any]:
    """The shuffled, Owen-scrambled Sobol point number ``index`` of the pattern ``seed`` (UInt32 each): two
    floats in [0, 1)."""
    seed = mix(seed ^ (index >> INDEX_BITS))  # each block of MAX_SAMPLES samples: a pattern of its own
    shuffled = reverse_bits(reversed_owen(reverse_bits(index & (MAX_SAMPLES - 1)), mix(seed ^ 0xBFF95BFE)))
    x, y = _sobol_reversed(shuffled)
    return _to_unit(reversed_owen(x, mix(seed ^ 0x2B9C3E1D))), _to_unit(reversed_owen(y, mix(seed ^ 0x68E31DA4)))


class OwenSobol:
    """A sampler for hybridgen's Python integrators (``next_1d`` / ``next_2d``, as a Mitsuba sampler is
    called): sample ``index`` (UInt32, per lane: the sample's number in its sequence) of the sequence ``seed``
    (UInt32, per lane: one per pixel and keypoint); each call is the next dimension set (module docstring)."""

    DRJIT_STRUCT = {"index": object, "seed": object, "dimension": object}

    def __init__(self, index: Any = None, seed: Any = None, dimension: Any = None) -> None:
        import mitsuba as mi

        self.index, self.seed = index, seed
        self.dimension = mi.UInt32(0) if dimension is None else dimension

    def _next(self) -> tuple[Any, Any]:
        self.dimension = self.dimension + 1
        return sample_2d(self.index, mix(self.seed ^ mix(self.dimension)))

    def next_1d(self, active: Any = True) -> Any:
        return self._next()[0]

    def next_2d(self, active: Any = True) -> Any:
        import mitsuba as mi

        x, y = self._next()
        return mi.Point2f(x, y)
