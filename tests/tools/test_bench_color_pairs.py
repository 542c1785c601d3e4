"""tools/bench_color_quality.py's timing: Cycles' timed renders interleave with hybridgen's warm runs (ABBA) and the
reported ratios are the medians of the pairs' ratios, each pair's hybridgen run divided by its own Cycles render."""
from __future__ import annotations

from pathlib import Path
from types import SimpleNamespace
from typing import Any

import numpy as np
import pytest
from PIL import Image

REPO = Path(__file__).resolve().parents[2]


@pytest.fixture
def color_quality() -> Any:
    import bench_color_quality  # tools/ is on sys.path (tests/tools/conftest.py)

    return bench_color_quality


def _png(path: Path, value: int) -> None:
    Image.fromarray(np.full((2, 3, 3), value, np.uint8)).save(path)


class FakeSession:
    """Stands in for CyclesSession: answers the timed renders with given times, logging the order of events."""

    def __init__(self, times: list[tuple[float, float]], log: list[str]) -> None:
        self.times, self.log = list(times), log

    def render(self, seed: int, png: Path, **request: Any) -> dict[str, Any]:
        _png(png, 7)
        if "sample_counts" in request:
            np.save(request["sample_counts"], np.full((2, 3), 104.0, np.float32))
            self.log.append("cycles counts")
            return {"seconds": 99.0, "cpu_s": 99.0}
        self.log.append("cycles")
        seconds, cpu = self.times.pop(0)
        return {"seconds": seconds, "cpu_s": cpu}


def test_pairs_alternate_and_ratios_are_medians_of_pairs(color_quality: Any, tmp_path: Path,
                                                         monkeypatch: pytest.MonkeyPatch) -> None:
    log: list[str] = []
    settings: list[tuple[float | None, int | None]] = []  # (threshold, max_samples) of every hybridgen process
    hg_times = iter([(9.0, 9.0), (4.0, 8.0), (5.0, 9.0), (3.0, 7.0)])  # cold, then three warm runs

    class FakeRuns:
        def __init__(self, *args: Any) -> None:
            pass

        def run(self, png: Path, threshold: float | None = None, max_samples: int | None = None) -> dict[str, Any]:
            settings.append((threshold, max_samples))
            wall, cpu = next(hg_times)
            log.append("cold" if "cold" in png.name else "hybridgen")
            _png(png, 5)
            return {"wall": wall, "cpu": cpu, "mean_spp": 140.0, **{k: 0.0 for k in color_quality.PHASES}}

        def close(self) -> None:
            pass

    monkeypatch.setattr(color_quality, "DefaultRuns", FakeRuns)
    args = SimpleNamespace(warm_runs=3, hg_threshold=None, hg_max_samples=512, try_thresholds=[], threads=2,
                           lobes=None, blenderproc_lobes=False)
    cycles = color_quality.CyclesTimes("s", FakeSession([(8.0, 16.0), (10.0, 20.0), (6.0, 12.0)], log), tmp_path)
    row: dict[str, Any] = {}
    image = color_quality.time_hybridgen("s", "3x2", tmp_path, args, np.full((2, 3, 3), 5, np.uint8), row, cycles)
    frame = cycles.finish(tmp_path, row)

    assert log == ["cold", "hybridgen", "cycles", "cycles", "hybridgen", "hybridgen", "cycles", "cycles counts"]
    assert settings == [(None, 512)] * 4  # --hg-max-samples reaches every timed process
    assert row["pair_wall_ratios"] == pytest.approx([4 / 8, 5 / 10, 3 / 6])
    assert row["pair_cpu_ratios"] == pytest.approx([8 / 16, 9 / 20, 7 / 12])
    assert row["wall_ratio"] == pytest.approx(0.5) and row["cpu_ratio"] == pytest.approx(0.5)
    assert (row["hg_s"], row["cycles_s"], row["cycles_cpu_s"]) == (4.0, 8.0, 16.0)
    assert row["cycles_mean_spp"] == 104.0 and row["hg_psnr"] == float("inf")
    assert int(image[0, 0, 0]) == 5 and int(frame[0, 0, 0]) == 7
