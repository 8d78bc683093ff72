"""One call into a long-running library function: its thz_context (threads, progress,
warnings), Ctrl-C, and turning the outcome into a value or an exception.

Cancellation. The library calls the progress callback on the thread that started the
run, between batches of work; a non-zero return cancels the run, which then returns
THZ_ERR_CANCELLED having freed everything and written nothing. A callback can also
raise: the exception is kept, the run cancelled, and the exception re-raised once the
C call has returned (an exception must never cross the C frames).

Ctrl-C. Python's default SIGINT handler raises KeyboardInterrupt at whatever bytecode
runs next; inside a ctypes callback that may be before any `try` (the function's entry),
and ctypes would then print and drop it. So while a run started from the main thread is
in C, SIGINT only sets a flag (if the default handler is in place); the progress
callback sees it and cancels, and KeyboardInterrupt is raised after the C call returns.
Runs on other threads are not interrupted by Ctrl-C (Python delivers it to the main
thread only).
"""
import ctypes
import numbers
import os
import signal
import sys
import threading
import warnings

from . import _lib
from .errors import ArgumentError, from_status
from .progress import Progress, make_reporter


class RunWarning(UserWarning):
    """A warning of a run (also recorded in its summary)."""


# The most threads a run may use: the C library's THZ_MAX_THREADS (thzmap.h), which
# refuses more; the thzmap program's --threads takes 1 to this too.
MAX_THREADS = 4096


def _warn_threads_beyond_cpus(threads):
    """A RuntimeWarning when `threads` exceed the CPUs this process may run on (its
    affinity: mpirun binds each rank to a core or socket by default, srun to its
    --cpus-per-task), as the thzmap program warns: the threads would share them
    unseen (they ran so, and nothing said it)."""
    try:
        cpus = len(os.sched_getaffinity(0))
    except (AttributeError, OSError):
        return
    if 0 < cpus < threads:
        warnings.warn(
            f"threads={threads}, but this process may run on only {cpus} CPU"
            f"{'' if cpus == 1 else 's'} (its affinity: mpirun binds each rank to one core "
            f"or socket unless given --bind-to none or --map-by slot:PE={threads}, srun to "
            f"its --cpus-per-task); the threads will share {'it' if cpus == 1 else 'them'}",
            RuntimeWarning, stacklevel=_outside_stacklevel())


def _outside_stacklevel():
    """The stacklevel, for warnings.warn in the function that calls this one, of the
    first caller outside the package (the calls in between differ from one entry point
    to another)."""
    def inside(frame):
        return os.path.dirname(os.path.abspath(frame.f_code.co_filename)) == package

    package = os.path.dirname(os.path.abspath(__file__))
    frame, level = sys._getframe(1), 1
    while frame is not None and inside(frame):
        frame, level = frame.f_back, level + 1
    return level


class Call:
    """Use as `with Call(threads, progress) as call: status = call.run(fn, ...)`."""

    # the RunWarnings point at the caller of the function whose `with` this is
    _stacklevel = 3

    def __init__(self, threads=None, progress=None, report_warnings=True):
        if threads is not None:
            if (isinstance(threads, bool) or not isinstance(threads, numbers.Integral)
                    or not 1 <= threads <= MAX_THREADS):
                raise ArgumentError(
                    f"threads: expected a whole number from 1 to {MAX_THREADS}, got {threads!r}")
            threads = int(threads)
            if report_warnings:
                _warn_threads_beyond_cpus(threads)
        self._report = make_reporter(progress)
        self._exc = None
        self._interrupted = False
        self._cancelled = False
        self._warnings = []
        self._keep_warnings = report_warnings  # False: an MPI rank other than 0 (rank 0 says them)
        self._old_handler = None
        self.error = _lib.ThzError()
        self.ctx = _lib.lib.thz_context_create()
        if not self.ctx:
            raise MemoryError("thzmap: out of memory for a context")
        _lib.lib.thz_context_set_threads(self.ctx, threads or 0)
        # Keep the ctypes callbacks alive as long as the context may call them.
        self._progress_cb = _lib.PROGRESS_FN(self._on_progress)
        self._warning_cb = _lib.WARNING_FN(self._on_warning)
        _lib.lib.thz_context_set_progress(self.ctx, self._progress_cb, None)
        _lib.lib.thz_context_set_warning(self.ctx, self._warning_cb, None)

    # -- callbacks (run on the calling thread, with the GIL, inside the C call) ------------
    def _on_progress(self, user, p):
        return self.guarded(self._report_progress, p)

    def _report_progress(self, p):
        if self._report is None:
            return False
        c = p.contents
        return self._report(Progress(_lib.text(c.stage), c.channel, c.n_channels, c.done,
                                     c.total))

    def guarded(self, report, *args):
        """The body of a C progress callback: calls report(*args) unless Ctrl-C was
        pressed (a true return value cancels), keeps any exception it raises for check()
        (and cancels), and returns what the library expects: 1 to cancel, else 0."""
        try:
            if not self._interrupted and report(*args):
                self._cancelled = True
        except BaseException as e:  # noqa: B902 - every exception must stop at this frame
            if self._exc is None:
                self._exc = e
        return 1 if (self._exc is not None or self._cancelled or self._interrupted) else 0

    def _on_warning(self, user, message):
        try:
            if self._keep_warnings:
                self._warnings.append(_lib.text(message))
        except BaseException as e:  # noqa: B902
            if self._exc is None:
                self._exc = e

    def _on_sigint(self, signum, frame):
        self._interrupted = True

    @property
    def takes_sigint(self):
        """Whether this call, entered, has taken SIGINT (Python's default handler was in
        place): Ctrl-C then cancels it."""
        return self._old_handler is not None

    # -- the call ----------------------------------------------------------------------------
    def __enter__(self):
        if threading.current_thread() is threading.main_thread():
            try:
                if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
                    self._old_handler = signal.signal(signal.SIGINT, self._on_sigint)
            except ValueError:  # not the main interpreter
                self._old_handler = None
        return self

    def __exit__(self, exc_type, exc, tb):
        if self._old_handler is not None:
            signal.signal(signal.SIGINT, self._old_handler)
            self._old_handler = None
        if self._report is not None and hasattr(self._report, "close"):
            self._report.close()
        _lib.lib.thz_context_set_progress(self.ctx, _lib.PROGRESS_FN(), None)
        _lib.lib.thz_context_set_warning(self.ctx, _lib.WARNING_FN(), None)
        _lib.lib.thz_context_destroy(self.ctx)
        self.ctx = None
        for w in self._warnings:
            warnings.warn(w, RunWarning, stacklevel=self._stacklevel)
        return False

    def check(self, status, scene_label=None):
        """Raises what the call's outcome calls for: the callback's exception,
        KeyboardInterrupt after Ctrl-C, CancelledError, or the library's error."""
        if self._exc is not None:
            exc, self._exc = self._exc, None
            raise exc
        if self._interrupted:
            raise KeyboardInterrupt
        if status != _lib.OK:
            raise from_status(status, _lib.text(self.error.message), scene_label)

    @property
    def err(self):
        return ctypes.byref(self.error)
