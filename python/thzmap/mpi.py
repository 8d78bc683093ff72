"""MPI runs from Python (docs/python.md "MPI"): simulate, render and batch with mpi=True
share their work among the ranks of an MPI job as `mpirun thzmap simulate|render|batch`
does (docs/mpi.md), with the same results as one process (images, photon maps and every
file but summary.json's and batch.json's times, threads and ranks, byte for byte).

    mpirun -np 4 python3 -m mpi4py script.py

Every rank runs the same script: it loads the same scene (or sequence) and calls the same
function with the same arguments. Rank 0's call returns the result; the other ranks' calls
fire their shares of the photon phases and render their pixel tiles (a batch: their
frames), and return None when rank 0's run has ended.

MPI itself is mpi4py's (Debian's python3-mpi4py), imported on the first such call when a
launcher started the process (mpirun's OMPI_COMM_WORLD_SIZE, Slurm's PMI_SIZE or
PMIX_RANK), or whenever the program has imported it already; it must be the MPI that
libthzmap was built with. A process that no launcher started runs alone, without MPI.

The arguments every rank checks alike raise as without MPI, on every rank. Past them, once
the ranks work together, a failure on any rank (an error, a cancellation, Ctrl-C, also
while it waits for another rank) ends the whole job (MPI_Abort, exit status 1, 130 after
Ctrl-C) after printing the error on stderr: the other ranks would wait for it forever. A
script with a SIGINT handler of its own keeps Ctrl-C (as a Call does without MPI).
`python3 -m mpi4py` does the same for an exception anywhere else in the script.
"""
import ctypes
import os
import signal
import sys
import threading
import traceback
from ctypes import POINTER, c_int, c_uint64

from . import _lib
from .errors import Error, from_status

_PROTOTYPES = {
    "thz_mpi_supported": (c_int, []),
    "thz_mpi_interrupt": (None, []),
    "thz_context_set_mpi": (c_int, [_lib._P, _lib._ERR]),
    "thz_mpi_serve": (c_int, [_lib._P, _lib._P, POINTER(_lib.ThzRunSettings), _lib._ERR]),
    "thz_mpi_serve_batch": (c_int, [_lib._P, _lib._P, _lib._ERR]),
    "thz_context_mpi_bytes": (c_uint64, [_lib._P]),
}
_lib.bind(_PROTOTYPES)

# The variables MPI launchers set, as the thzmap program reads them (src/cli/cli_mpi.c).
_LAUNCHERS = ("OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK")


def supported():
    """Whether the libthzmap this package uses was built with MPI."""
    return bool(_lib.lib.thz_mpi_supported())


def world():
    """MPI_COMM_WORLD (an mpi4py communicator) when this process is one of several MPI
    ranks, else None (a process no launcher started, or a job of one rank)."""
    if "mpi4py.MPI" not in sys.modules and not any(os.environ.get(v) for v in _LAUNCHERS):
        return None
    try:
        from mpi4py import MPI
    except ImportError:
        raise ImportError("thzmap: mpi=True under an MPI launcher needs mpi4py (Debian: "
                          "python3-mpi4py)") from None
    comm = MPI.COMM_WORLD
    if comm.Get_size() == 1:
        return None
    if not supported():
        raise Error(f"this libthzmap ({_lib.path}) was built without MPI support; rebuild it "
                    "with an MPI library (libopenmpi-dev) or run one process", "bad input")
    level = MPI.Query_thread()
    if level < MPI.THREAD_FUNNELED:
        raise Error("the MPI library does not allow threads (MPI_THREAD_FUNNELED)",
                    "bad input")
    if level < MPI.THREAD_MULTIPLE and not MPI.Is_thread_main():
        raise Error("mpi=True: call from the thread that started MPI (it allows no other)",
                    "bad input")
    return comm


def end_job(comm, exc, interrupted=False):
    """Prints exc (with its traceback) naming this rank, and ends the MPI job: exit status
    130 after Ctrl-C (interrupted, or a KeyboardInterrupt), else 1."""
    try:
        print(f"thzmap (MPI rank {comm.Get_rank()}): the run failed; ending the MPI job",
              file=sys.stderr)
        traceback.print_exception(type(exc), exc, exc.__traceback__, file=sys.stderr)
        sys.stderr.flush()
    finally:
        comm.Abort(130 if interrupted or isinstance(exc, KeyboardInterrupt) else 1)


# The byte that tells _Interrupts' thread to end (Python's wakeup fd carries signal
# numbers, never 0).
_STOP = b"\0"


class _Interrupts:
    """While a shared run that took SIGINT (Call.takes_sigint) is in C: Ctrl-C also stops
    this process's waits for other ranks (thz_mpi_interrupt, as the thzmap program's
    handler does). Python runs its own handlers only between bytecodes, never while a
    call waits in C; its wakeup fd is written at once, and a thread reading it makes the
    call. The bytes are passed on to the wakeup fd in place before (asyncio's, say).
    `fired` says whether it did: the library's flag stays set for the rest of the process,
    so the job must end even when the run then returned."""

    def __init__(self):
        self._thread = None
        self.fired = False

    def __enter__(self):
        r, w = os.pipe()
        os.set_blocking(w, False)
        try:
            old = signal.set_wakeup_fd(w, warn_on_full_buffer=False)
        except ValueError:  # not the main thread, or not the main interpreter
            os.close(r)
            os.close(w)
            return self
        thread = threading.Thread(target=self._watch, args=(r, old), daemon=True,
                                  name="thzmap-mpi-interrupt")
        try:
            thread.start()
        except BaseException:
            signal.set_wakeup_fd(old)
            os.close(r)
            os.close(w)
            raise
        self._thread, self._old, self._pipe = thread, old, (r, w)
        return self

    def _watch(self, r, old):
        while True:
            data = os.read(r, 64)
            stop = not data or _STOP in data
            data = data.replace(_STOP, b"")
            if data and old != -1:
                try:
                    os.write(old, data)
                except OSError:  # full or closed: that fd's owner would drop them too
                    pass
            if signal.SIGINT in data and not self.fired:
                self.fired = True
                _lib.lib.thz_mpi_interrupt()
            if stop:
                return

    def __exit__(self, exc_type, exc, tb):
        if self._thread is not None:
            signal.set_wakeup_fd(self._old)
            r, w = self._pipe
            os.write(w, _STOP)  # the pipe is drained: there is room
            self._thread.join()
            os.close(w)
            os.close(r)
            self._thread = None
        return False


class Shared:
    """`with Shared(comm, call):` around a run on call's context, inside the Call (the
    job must end before the context is destroyed). comm None: nothing shared, failures
    raise. On rank 0 (lead=True) the context joins the other ranks (thz_context_set_mpi,
    collective with their serve); on every rank whose Call took SIGINT, Ctrl-C also stops
    waits for other ranks; and a failure inside (an interrupted wait too) ends the job."""

    def __init__(self, comm, call, lead=True):
        self._comm = comm
        self._call = call
        self._lead = lead
        self._interrupts = _Interrupts()

    def __enter__(self):
        if self._comm is None:
            return self
        try:
            if self._call.takes_sigint:
                self._interrupts.__enter__()
            if self._lead:
                status = _lib.lib.thz_context_set_mpi(self._call.ctx, self._call.err)
                if status != _lib.OK:
                    raise from_status(status, _lib.text(self._call.error.message))
        except BaseException as e:  # noqa: B902 - the other ranks wait: end the job
            self._interrupts.__exit__(None, None, None)
            end_job(self._comm, e, self._interrupts.fired)
        return self

    def bytes(self):
        """What this rank sent and received so far, in bytes (0 when not shared)."""
        if self._comm is None:
            return 0
        return int(_lib.lib.thz_context_mpi_bytes(self._call.ctx))

    def __exit__(self, exc_type, exc, tb):
        if self._comm is None:
            return False
        self._interrupts.__exit__(exc_type, exc, tb)
        if exc is None and self._interrupts.fired:
            exc = KeyboardInterrupt()
        if exc is not None:
            end_job(self._comm, exc, self._interrupts.fired)
        return False


def serve(comm, call, scene=None, settings=None, sequence=None):
    """A rank other than 0: serves rank 0's run on call's context (a Call that reports
    no warnings: rank 0 reports them) until it ends: a scene's runs with `settings`, or
    a batch of `sequence`. A failure ends the job."""
    with Shared(comm, call, lead=False):
        if sequence is not None:
            status = _lib.lib.thz_mpi_serve_batch(call.ctx, sequence._handle, call.err)
        else:
            status = _lib.lib.thz_mpi_serve(call.ctx, scene._handle, ctypes.byref(settings),
                                            call.err)
        call.check(status)
