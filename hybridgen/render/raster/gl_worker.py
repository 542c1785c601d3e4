"""One thread that owns a headless GL context and an object built on it, and runs jobs on that object.

A GL context is current on one thread at a time, so whatever draws with it must run there: the label threads
(:mod:`hybridgen.render.raster.threaded_labels`) and the denoiser's guide thread (:mod:`hybridgen.render.guide_worker`)
each hand their work to a :class:`GLWorker`. The thread is a daemon (a hung driver cannot keep the process
from exiting); the context is the worker's own (:func:`~hybridgen.render.raster.gl_context.create_context`, never the
process's shared one, which other threads use).
"""
from __future__ import annotations

import queue
import threading
from concurrent.futures import Future
from typing import Any, Callable, Generic, TypeVar

from ...errors import SystemSetupError
from .gl_context import create_context

DEFAULT_TIMEOUT_S = 600.0
"""Longest wait for one job (or for a worker's context and upload) before giving up, seconds."""
T = TypeVar("T")
R = TypeVar("R")


class GLWorker(Generic[T]):
    """A daemon thread named ``name`` that creates its own GL context, builds ``build(ctx)`` on it (the
    *owned* object, :attr:`ready` once built) and runs the jobs given to :meth:`submit` on it in order. On
    :meth:`close` it calls ``release(owned)`` and releases the context, on its own thread. An exception of a job
    is set on its future, unchanged; one of ``build`` on :attr:`ready` and on every job's future."""

    def __init__(self, build: Callable[[Any], T], release: Callable[[T], None], name: str,
                 timeout: float) -> None:
        self.timeout = float(timeout)
        self.hung = False  # a wait ran out of time: the thread may never end, so close() does not wait for it
        self.jobs: queue.Queue[tuple[Callable[[T], Any], Future] | None] = queue.Queue()
        self.ready: Future = Future()
        self.thread = threading.Thread(target=self._run, args=(build, release), name=name, daemon=True)
        self.thread.start()

    def _run(self, build: Callable[[Any], T], release: Callable[[T], None]) -> None:
        ctx = None
        owned: T | None = None
        failed: BaseException | None = None  # building's exception: every job gets it too
        try:
            ctx = create_context()
            owned = build(ctx)
            self.ready.set_result(owned)
        except BaseException as exc:  # noqa: BLE001 - handed to the thread that waits for it
            failed = exc
            self.ready.set_exception(exc)
        try:
            while True:
                job = self.jobs.get()
                if job is None:
                    break
                work, result = job
                if not result.set_running_or_notify_cancel():
                    continue
                try:
                    if failed is not None:
                        raise failed
                    result.set_result(work(owned))  # type: ignore[arg-type]
                except BaseException as exc:  # noqa: BLE001
                    result.set_exception(exc)
        finally:
            if failed is None:
                release(owned)  # type: ignore[arg-type]
            if ctx is not None:
                ctx.release()

    def submit(self, work: Callable[[T], R]) -> Future:
        """Queues ``work(owned)`` on the worker; its future holds the result."""
        result: Future = Future()
        self.jobs.put((work, result))
        return result

    def wait(self, result: Future, what: str) -> Any:
        """The value of ``result`` (raised again if it is an exception), or a SystemSetupError naming ``what``
        when the worker gives no answer within the timeout - at once once a job has outlived it (a hung worker
        answers no later job: jobs queued ahead cost one timeout, not one each)."""
        try:
            return result.result(timeout=0 if self.hung else self.timeout)
        except TimeoutError as exc:
            self.hung = True
            raise SystemSetupError(f"a raster thread gave no answer for {what} within {self.timeout:g} s") from exc

    def close(self) -> None:
        """Ends the thread after the jobs queued so far (releasing what it owns) and waits for it, unless a job
        already outlived the timeout in :meth:`wait`: the daemon thread is then left behind, so a hung driver costs
        one timeout, not two."""
        self.jobs.put(None)
        if not self.hung:
            self.thread.join(timeout=self.timeout)
