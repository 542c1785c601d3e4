"""The benchmarks' one harness: wall and CPU timing (in this process and of whole child processes), alternating
(ABBA) orders, medians, ratios against a baseline measured in the same run, and tables.

Every benchmark of tools/ (tools/README.md) measures with these, so that "CPU seconds", "median" and "ratio" mean
one thing everywhere. Units: seconds (wall: ``time.perf_counter``; CPU: user + system of every thread of the
process measured), MiB for memory. On a shared machine wall seconds move with the load; CPU seconds, and ratios
of runs that alternate, are steadier: that is why the benchmarks interleave what they compare.
"""
from __future__ import annotations

import json
import os
import re
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass
from functools import lru_cache
from pathlib import Path
from typing import Any, TypeVar

T = TypeVar("T")


# ------------------------------------------------------------------------------------- in this process
class Stopwatch:
    """Wall and CPU seconds since it was made (CPU / wall = the cores this process got). ``cpu_clock``:
    ``time.process_time`` (this process, every thread) or ``time.thread_time`` (this thread)."""

    def __init__(self, cpu_clock: Callable[[], float] = time.process_time) -> None:
        self.cpu_clock = cpu_clock
        self.wall, self.cpu = time.perf_counter(), cpu_clock()

    def read(self) -> tuple[float, float]:
        """(wall seconds, CPU seconds) since the stopwatch was made."""
        return time.perf_counter() - self.wall, self.cpu_clock() - self.cpu


def cpu_seconds() -> float:
    """User + system CPU seconds of this process so far (``getrusage``: every thread)."""
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def accumulating(spent: dict[str, float], name: str, function: Callable[..., T],
                 clock: Callable[[], float] = time.perf_counter) -> Callable[..., T]:
    """``function`` wrapped so that every call adds its ``clock`` seconds to ``spent[name]`` (what it returns and
    raises is unchanged): the time of one part of a larger call, measured without changing the code around it."""

    def wrapper(*args: Any, **kwargs: Any) -> T:
        start = clock()
        try:
            return function(*args, **kwargs)
        finally:
            spent[name] = spent.get(name, 0.0) + clock() - start

    return wrapper


def rss_mib() -> tuple[float, float]:
    """(current, peak) resident set size of this process, MiB (Linux ``/proc/self/status``)."""
    values = {}
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(("VmRSS:", "VmHWM:")):
                values[line.split(":")[0]] = int(line.split()[1]) / 1024
    return values["VmRSS"], values["VmHWM"]


# ------------------------------------------------------------------------------------- whole processes
@dataclass(frozen=True)
class Finished:
    """A finished child process: its output lines (stdout and stderr together), wall seconds from spawn to reaping
    and CPU seconds (user + system from its own rusage: every thread, and its children once it waited for them)."""

    lines: list[str]
    wall: float
    cpu: float

    @property
    def report(self) -> dict[str, Any] | None:
        """The last output line that is a JSON object (how a timed child reports), or None."""
        return next((json.loads(line) for line in reversed(self.lines) if line.startswith("{")), None)


def run_process(command: Sequence[str], env: dict[str, str] | None = None, cwd: Path | str | None = None,
                crash_after: str | None = None) -> Finished:
    """Runs ``command`` to its end and times it; raises RuntimeError with its output's tail if it fails - unless it
    was killed by a signal after printing a line containing ``crash_after`` (a process that crashes on its way out,
    its work done: it is counted, with a notice)."""
    with tempfile.TemporaryFile() as output:
        start = time.perf_counter()
        child = subprocess.Popen(list(command), stdout=output, stderr=subprocess.STDOUT, env=env, cwd=cwd)
        _, status, usage = os.wait4(child.pid, 0)  # this child's own rusage (RUSAGE_CHILDREN mixes in others)
        wall = time.perf_counter() - start
        code = os.waitstatus_to_exitcode(status)
        output.seek(0)
        lines = output.read().decode(errors="replace").strip().splitlines()
    if code < 0 and crash_after is not None and any(crash_after in line for line in lines):
        print(f"notice: `{Path(str(command[-1])).name}`'s process died of signal {-code} after {crash_after!r}; "
              f"counted as finished", file=sys.stderr)
    elif code != 0:
        raise RuntimeError(f"`{' '.join(map(str, command))}` failed (exit {code}):\n  " + "\n  ".join(lines[-8:]))
    return Finished(lines, wall, usage.ru_utime + usage.ru_stime)


# ---------------------------------------------------------------------------------- orders and summaries
def alternating(items: Sequence[T], round_index: int) -> list[T]:
    """``items`` in their order in even rounds and reversed in odd ones (ABBA): over two rounds each item runs
    first once, so a drift in the machine's speed hits all alike."""
    return list(items) if round_index % 2 == 0 else list(items)[::-1]


def medians(rows: Iterable[dict[str, float]]) -> dict[str, float]:
    """Per key, the median of the rows' values (the rows share their keys)."""
    rows = list(rows)
    return {key: statistics.median(row[key] for row in rows) for key in rows[0]}


def paired_ratios(values: Sequence[float], baseline: Sequence[float]) -> list[float]:
    """Each measurement over the baseline measured beside it (same round, same position in the list)."""
    assert len(values) == len(baseline), "one baseline measurement per measurement"
    return [value / base for value, base in zip(values, baseline)]


def paired_ratio(values: Sequence[float], baseline: Sequence[float]) -> float:
    """The median of :func:`paired_ratios`: a ratio in which the machine's drift between rounds cancels."""
    return statistics.median(paired_ratios(values, baseline))


# ----------------------------------------------------------------------------------------- the machine
def load_average() -> float:
    """The machine's 1-minute load average (above the core count: other processes competed)."""
    return os.getloadavg()[0]


@lru_cache(maxsize=None)
def host_cpu() -> dict[str, Any]:
    """The CPU the timings come from: its model name and widest vector instruction set, and the float32 lanes
    Dr.Jit's LLVM backend generates for it (16 with AVX-512, 8 with AVX/AVX2, 4 otherwise: its native width)."""
    model, flags = "unknown", set()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            key, _, value = line.partition(":")
            if key.strip() == "model name" and model == "unknown":
                model = value.strip()
            elif key.strip() == "flags" and not flags:
                flags = set(value.split())
    except OSError:
        pass
    isa = "avx512f" if "avx512f" in flags else "avx2" if "avx2" in flags else "avx" if "avx" in flags else "sse"
    return {"model": model, "isa": isa, "drjit_llvm_lanes": {"avx512f": 16, "avx2": 8, "avx": 8}.get(isa, 4)}


# ---------------------------------------------------------------------------------------------- tables
class Table:
    """A table printed row by row (each row flushed as it is measured). ``columns``: (title, format spec) pairs,
    e.g. ``("fps", ">8.1f")``; the spec's alignment and width also lay out the title, and a value that is a string
    gets only them. ``markdown``: ``| a | b |`` rows under a ``|---|`` rule instead of aligned columns."""

    def __init__(self, columns: Sequence[tuple[str, str]], markdown: bool = False) -> None:
        self.columns, self.markdown = list(columns), markdown

    def _cells(self, values: Sequence[Any]) -> list[str]:
        assert len(values) == len(self.columns), f"{len(values)} values for {len(self.columns)} columns"
        cells = []
        for (_, spec), value in zip(self.columns, values):
            layout = re.match(r"[<>^]?\d*", spec).group(0)  # type: ignore[union-attr]
            cells.append(format(value, layout if isinstance(value, str) else spec))
        return cells

    def _line(self, cells: Sequence[str]) -> str:
        return "| " + " | ".join(cells) + " |" if self.markdown else " ".join(cells)

    def header(self) -> None:
        """Prints the titles (and the Markdown rule)."""
        print(self._line(self._cells([title for title, _ in self.columns])))
        if self.markdown:
            print("|" + "---|" * len(self.columns))

    def row(self, *values: Any) -> None:
        """Prints one row of values, one per column."""
        print(self._line(self._cells(values)), flush=True)
