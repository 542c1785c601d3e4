"""A SIGTERM whose SystemExit is swallowed by a finalizer still stops the run (hybridgen/stop_request.py)."""
from __future__ import annotations

import gc
import signal
from typing import Any

import numpy as np
import pytest

import hybridgen as hg
from hybridgen import stop_request
from hybridgen.io.frame_sink import PassLayout
from hybridgen.render.keypoint_loop import run_keypoints
from hybridgen.run import signals


class _Counter:
    """A producer of one number per keypoint (its index)."""

    def layouts(self) -> list[PassLayout]:
        return [PassLayout("value", "float32", (1,))]

    def attributes(self) -> dict[str, Any]:
        return {}

    def records(self) -> dict[str, np.ndarray]:
        return {}

    def produce(self, index: int, cam2world: np.ndarray, eye: int = 0) -> dict[str, Any]:
        return {"value": np.array([index], np.float32)}

    def close(self) -> None:
        pass


class _SignalledInFinalizer:
    """Runs the run's SIGTERM handler inside ``__del__``, where Python reports and drops the SystemExit."""

    def __del__(self) -> None:
        signals._terminate(signal.SIGTERM, None)


class _Sink(hg.MemorySink):
    """Keeps what it was given; at keypoint ``at`` a SIGTERM arrives inside a finalizer."""

    def __init__(self, at: int) -> None:
        super().__init__()
        self.at, self.written, self.ended = at, [], False

    def write(self, index: int, values: dict[str, Any]) -> None:
        super().write(index, values)
        self.written.append(index)
        if index == self.at:
            _SignalledInFinalizer()  # dropped at once: the handler's SystemExit is "ignored"
            gc.collect()

    def end(self) -> None:
        self.ended = True


def _scene(keypoints: int) -> hg.Scene:
    scene = hg.Scene()
    scene.camera.intrinsics = hg.Intrinsics.from_fov(0.8, 8, 6)
    for i in range(keypoints):
        scene.camera.add_keypoint(hg.look_at([0.0, -2.0 - i, 1.0], [0.0, 0.0, 0.0]))
    return scene


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_swallowed_sigterm_stops_at_the_next_keypoint_and_nothing_is_finished():
    sink = _Sink(at=1)
    with pytest.raises(SystemExit) as stopped:
        with signals.stop_on_signals():
            run_keypoints(_scene(6), [sink], [_Counter()])
    assert stopped.value.code == signals.EXIT_SIGTERM
    assert sink.written == [0, 1]  # keypoint 2 never started
    assert not sink.ended  # the sinks were not finished (a file would not be sealed)
    stop_request.raise_if_requested()  # the request ended with its block


@pytest.mark.filterwarnings("ignore::pytest.PytestUnraisableExceptionWarning")
def test_swallowed_sigterm_at_the_last_keypoint_still_keeps_the_sinks_unfinished():
    sink = _Sink(at=2)
    with pytest.raises(SystemExit):
        with signals.stop_on_signals():
            run_keypoints(_scene(3), [sink], [_Counter()])
    assert sink.written == [0, 1, 2] and not sink.ended


def test_without_a_request_the_run_finishes():
    sink = _Sink(at=-1)
    with signals.stop_on_signals():
        assert run_keypoints(_scene(3), [sink], [_Counter()]) == 3
    assert sink.written == [0, 1, 2] and sink.ended
    assert [float(f["value"][0]) for f in sink.frames] == [0.0, 1.0, 2.0]


SIGNAL_IN_PROGRAM_CALLBACK = """
import os, signal, sys
import _moderngl
import hybridgen as hg
from hybridgen.run.signals import stop_on_signals

original = _moderngl.make_attribute


def make_attribute(*args):  # moderngl's C code calls this while it makes a program, and uses the result unchecked
    os.kill(os.getpid(), getattr(signal, sys.argv[1]))  # the handler runs at the next bytecode: in this callback
    return original(*args)


_moderngl.make_attribute = make_attribute
scene = hg.Scene()
scene.add(hg.make_primitive("sphere", 1.0, name="ball", category_id=1))
scene.camera.intrinsics = hg.Intrinsics.from_fov(0.8, 16, 12)
scene.camera.add_keypoint(hg.look_at([0.0, -4.0, 1.0], [0.0, 0.0, 0.0]))
with stop_on_signals():
    hg.render_labels(scene, [hg.MemorySink()], hg.LabelRequest(depth=True))
    print("not stopped", flush=True)
"""


@pytest.mark.parametrize("signame,status", [("SIGTERM", 143), ("SIGINT", -signal.SIGINT)])
def test_signal_while_moderngl_makes_a_program_stops_the_run_instead_of_crashing(gl_context, signame, status):
    """A SystemExit/KeyboardInterrupt raised inside moderngl's callback crashed the process with SIGSEGV (exit
    -11; measured in about 1 of 15 SIGTERMed runs); the request now waits for the program to be made. Python
    ends an uncaught KeyboardInterrupt by dying of SIGINT."""
    import subprocess
    import sys

    from tests.conftest import REPO

    result = subprocess.run([sys.executable, "-c", SIGNAL_IN_PROGRAM_CALLBACK, signame], cwd=REPO,
                            capture_output=True, text=True, timeout=120)
    assert result.returncode == status, result.stderr[-2000:]
    assert "not stopped" not in result.stdout


def test_a_request_inside_a_deferred_block_is_raised_when_the_block_ends():
    import os

    reached = []
    with pytest.raises(SystemExit) as stopped:
        with signals.stop_on_signals():
            with stop_request.deferred():
                with stop_request.deferred():
                    os.kill(os.getpid(), signal.SIGTERM)
                    reached.append("inner")  # the handler has run (between bytecodes) and only recorded
                reached.append("outer")
            reached.append("after")
    assert stopped.value.code == signals.EXIT_SIGTERM and reached == ["inner", "outer"]
    with pytest.raises(KeyboardInterrupt):
        with signals.stop_on_signals():
            with stop_request.deferred():
                os.kill(os.getpid(), signal.SIGINT)
                reached.append("interrupted")
    assert reached[-1] == "interrupted"
