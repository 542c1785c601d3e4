"""hybridgen's Filmic view (hybridgen/render/filmic_view.py, Blender's own tables read at run time) against Blender
4.2 writing the same scene-linear values through its Filmic view (tools/filmic_blender.py, in
``.venv-blenderproc``).

    .venv/bin/python tools/filmic_vs_blender.py [--store tests/render/data/filmic_blender.json]

The values: gray ramps over 30 stops (2^-16 .. 2^14, negative and zero included) and random colors, log-uniform
per channel over the same range. Printed: the largest difference in 8-bit codes and in 16-bit codes, and the share
of the 8-bit codes that are equal. ``--store`` writes a table (linear RGB -> Blender's 8-bit codes) that
tests/render/test_filmic_view.py checks hybridgen against where Blender's tables are installed.
"""
from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
sys.path.insert(0, str(REPO / "tools"))
STORED = 256


def test_values(seed: int = 7) -> np.ndarray:
    """(64, 64, 3) float32 scene-linear values: gray ramps, then random log-uniform colors."""
    rng = np.random.default_rng(seed)
    gray = np.concatenate([[-1.0, 0.0], 2.0 ** np.linspace(-16.0, 14.0, 64 * 8 - 2)])
    ramps = np.repeat(gray[:, None], 3, axis=1)
    colors = 2.0 ** rng.uniform(-16.0, 14.0, size=(64 * 64 - len(gray), 3))
    return np.concatenate([ramps, colors]).reshape(64, 64, 3).astype(np.float32)


def blender(values: np.ndarray, view: str, work: Path) -> tuple[np.ndarray, np.ndarray]:
    """Blender's 8- and 16-bit PNG codes of ``values`` through ``view``."""
    from PIL import Image

    from blender_side import run_blender_side

    np.save(work / "values.npy", values)
    run_blender_side("filmic_blender.py", [str(work / "values.npy"), view, str(work)], work)
    import mitsuba as mi

    if mi.variant() is None:
        mi.set_variant("scalar_rgb")
    sixteen = np.asarray(mi.Bitmap(str(work / "16.png")))  # PIL reads 48-bit PNGs as 8-bit
    return np.asarray(Image.open(work / "8.png").convert("RGB")), sixteen.astype(np.int64)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--store", type=Path, default=None)
    ns = parser.parse_args()
    from hybridgen.render.filmic_view import find_colormanagement, load_filmic

    view = load_filmic()
    if view is None:
        raise SystemExit("Blender's color tables were not found: run `make bpy-venv` or set "
                         "HYBRIDGEN_BLENDER_COLORMANAGEMENT")
    print(f"tables: {find_colormanagement()}")
    values = test_values()
    with tempfile.TemporaryDirectory(prefix="filmic-") as temp:
        codes8, codes16 = blender(values, "Filmic", Path(temp))
    mine8, mine16 = view.to_uint8(values).astype(np.int64), view.to_uint16(values).astype(np.int64)
    diff8, diff16 = np.abs(mine8 - codes8), np.abs(mine16 - codes16) if codes16.ndim == 3 else None
    print(f"8-bit: max |difference| {diff8.max()} codes, equal {np.mean(diff8 == 0):.4f}")
    if diff16 is not None:
        print(f"16-bit: max |difference| {diff16.max()} codes, mean {diff16.mean():.2f}")
    if ns.store:
        flat_values, flat_codes = values.reshape(-1, 3), codes8.reshape(-1, 3)
        chosen = np.linspace(0, len(flat_values) - 1, STORED).round().astype(int)
        rows = ",\n  ".join(json.dumps([[float(v) for v in flat_values[i]], [int(c) for c in flat_codes[i]]])
                            for i in chosen)
        ns.store.write_text('{"view": "Filmic", "blender": "4.2", "rows": [\n  ' + rows + "\n]}\n")
        print(f"stored {ns.store}")


if __name__ == "__main__":
    main()
