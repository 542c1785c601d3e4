"""Ending a finished command-line process without the interpreter's teardown.

After a color run, Python's own shutdown - clearing every module, the final garbage collections, then the C++
destructors of Dr.Jit, Mitsuba, LLVM and the GL driver and the threads they join - takes 0.1-0.2 s of wall time
that does nothing useful: the output is already committed. :func:`end_process` skips it when that is safe,
and otherwise leaves the exit to Python.

It is used by the ``hybridgen`` command's entry points only (``hybridgen.cli.console_main``), never by
:func:`hybridgen.cli.main`, which tests and applications call in-process.
"""
from __future__ import annotations

import atexit
import ctypes
import os
import sys
import threading


def unfinished_work() -> str | None:
    """Why the process must end through the interpreter's normal shutdown, or None when nothing depends on it:
    a non-daemon thread still running (the normal exit joins it), or an HDF5 file still open (the HDF5
    library closes and flushes it from a C ``atexit`` handler, which ``os._exit`` skips)."""
    running = [t.name for t in threading.enumerate()
               if t is not threading.main_thread() and not t.daemon and t.is_alive()]
    if running:
        return f"thread(s) still running: {running}"
    h5f = sys.modules.get("h5py.h5f")
    if h5f is not None and h5f.get_obj_count(h5f.OBJ_ALL, h5f.OBJ_FILE) > 0:
        return "an HDF5 file is still open"
    return None


def end_process(code: int) -> None:
    """End the process with exit status ``code``. For ``code`` 0 with no :func:`unfinished_work`: run the
    ``atexit`` handlers (logging's flush and close, Mitsuba's and Dr.Jit's cleanup, a Ray driver's
    shutdown ...), flush Python's and C's standard streams, then ``os._exit`` - the files written were
    closed by the command itself. Otherwise (an error status, where a traceback or a late message must
    come out, or work still in flight) ``sys.exit(code)``: the interpreter's normal shutdown."""
    if code != 0 or unfinished_work() is not None:
        sys.exit(code)
    atexit._run_exitfuncs()  # runs each handler once and clears them, as the interpreter's exit does
    for stream in (sys.stdout, sys.stderr):
        try:
            if stream is not None:
                stream.flush()
        except (OSError, ValueError):  # the reader went away / the stream was closed: nothing can go out
            pass
    if os.name == "posix":
        ctypes.CDLL(None).fflush(None)  # C stdio buffers (messages of C/C++ libraries on a piped stdout)
    os._exit(code)
