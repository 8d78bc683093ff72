"""MPI runs from Python (docs/python.md "MPI"): simulate, render and batch with mpi=True
share their work among the ranks of an MPI job as `mpirun thzmap simulate|render|batch`
does (docs/mpi.md), with the same results, byte for byte, as one process.

    mpirun -np 4 python3 -m mpi4py script.py

Every rank runs the same script: it loads the same scene (or sequence) and calls the same
function with the same arguments. Rank 0's call returns the result; the other ranks' calls
fire their shares of the photon phases and render their pixel tiles (a batch: their
frames), and return None when rank 0's run has ended.

MPI itself is mpi4py's (Debian's python3-mpi4py), imported on the first such call when a
launcher started the process (mpirun's OMPI_COMM_WORLD_SIZE, Slurm's PMI_SIZE or
PMIX_RANK), or whenever the program has imported it already; it must be the MPI that
libthzmap was built with. A process that no launcher started runs alone, without MPI.

Once the ranks work together, a failure on any of them (an error, a cancellation, Ctrl-C)
ends the whole job (MPI_Abort, exit status 1, 130 after Ctrl-C) after printing the error on
stderr: the other ranks would wait for it forever. `python3 -m mpi4py` does the same for an
exception anywhere else in the script.
"""
import ctypes
import os
import sys
import traceback
from ctypes import POINTER, c_int, c_uint64

from . import _lib
from .errors import Error, from_status

_lib.bind({
    "thz_mpi_supported": (c_int, []),
    "thz_context_set_mpi": (c_int, [_lib._P, _lib._ERR]),
    "thz_mpi_serve": (c_int, [_lib._P, _lib._P, POINTER(_lib.ThzRunSettings), _lib._ERR]),
    "thz_mpi_serve_batch": (c_int, [_lib._P, _lib._P, _lib._ERR]),
    "thz_context_mpi_bytes": (c_uint64, [_lib._P]),
})

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
    if MPI.Query_thread() < MPI.THREAD_FUNNELED:
        raise Error("the MPI library does not allow threads (MPI_THREAD_FUNNELED)",
                    "bad input")
    return comm


def end_job(comm, exc):
    """Prints exc (with its traceback) naming this rank, and ends the MPI job."""
    try:
        print(f"thzmap (MPI rank {comm.Get_rank()}): the run failed; ending the MPI job",
              file=sys.stderr)
        traceback.print_exception(type(exc), exc, exc.__traceback__, file=sys.stderr)
        sys.stderr.flush()
    finally:
        comm.Abort(130 if isinstance(exc, KeyboardInterrupt) else 1)


class Lead:
    """`with Lead(comm, call):` on rank 0 around a run on call's context: the context
    joins the other ranks (thz_context_set_mpi, collective with their serve), and a
    failure inside ends the job. comm None: nothing is shared, failures raise."""

    def __init__(self, comm, call):
        self._comm = comm
        self._call = call

    def __enter__(self):
        if self._comm is not None:
            status = _lib.lib.thz_context_set_mpi(self._call.ctx, self._call.err)
            if status != _lib.OK:
                end_job(self._comm, from_status(status, _lib.text(self._call.error.message)))
        return self

    def bytes(self):
        """What rank 0 sent and received so far, in bytes."""
        return int(_lib.lib.thz_context_mpi_bytes(self._call.ctx))

    def __exit__(self, exc_type, exc, tb):
        if exc is not None and self._comm is not None:
            end_job(self._comm, exc)
        return False


def serve(comm, call, scene=None, settings=None, sequence=None):
    """A rank other than 0: serves rank 0's run on call's context until it ends (a
    scene's runs with `settings`, or a batch of `sequence`); a failure ends the job."""
    try:
        if sequence is not None:
            status = _lib.lib.thz_mpi_serve_batch(call.ctx, sequence._handle, call.err)
        else:
            status = _lib.lib.thz_mpi_serve(call.ctx, scene._handle, ctypes.byref(settings),
                                            call.err)
        call.check(status)
    except BaseException as e:  # noqa: B902 - rank 0 waits for this rank: end the job
        end_job(comm, e)
