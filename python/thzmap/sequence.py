"""Sequences and batches (`thzmap batch`, docs/scene-format.md "Sequences, sweeps and
movies"): thzmap.load_sequence() reads a "thzmap-sequence/1" file, thzmap.batch() runs
its frames into a directory, through the C API of include/thzmap/batch.h.

Memory. A Sequence owns one thz_sequence; a frame's Scene (frame_scene) is a scene of
its own. A batch writes its frames, batch.json and movies to disk as `thzmap batch`
does (the same bytes for the same sequence, timings aside) and returns what it did and
batch.json as a dict; the images are read from the frame directories (or rendered
again from frame_scene). The GIL is released while the library runs.
"""
import collections
import ctypes
import json
import numbers
import os
import re
import sys
import time
from ctypes import (CFUNCTYPE, POINTER, Structure, c_char_p, c_double, c_int, c_size_t,
                    c_uint64, c_void_p)

from . import _lib
from . import mpi as _mpi
from ._call import Call
from .errors import ArgumentError
from .progress import check as check_progress, make_reporter
from .scene import _load, _load_error, _path_arg, _root_arg


class ThzFrameInfo(Structure):
    """thz_frame_info (thzmap/batch.h), field for field."""
    _fields_ = [("sweep", c_size_t), ("index", c_size_t), ("time_s", c_double),
                ("dir", c_char_p), ("hash", c_uint64)]


class ThzBatchProgress(Structure):
    _fields_ = [("frame", c_size_t), ("n_frames", c_size_t), ("computed", c_size_t),
                ("reused", c_size_t), ("seconds", c_double), ("stage", c_char_p),
                ("fraction", c_double)]


BATCH_PROGRESS_FN = CFUNCTYPE(c_int, c_void_p, POINTER(ThzBatchProgress))


class ThzBatchOptions(Structure):
    _fields_ = [("progress", BATCH_PROGRESS_FN), ("progress_user", c_void_p),
                ("no_movies", c_int), ("open_output", c_void_p)]


class ThzBatchResult(Structure):
    _fields_ = [("n_frames", c_size_t), ("computed", c_size_t), ("reused", c_size_t),
                ("movies", c_size_t), ("seconds", c_double)]


# For tests/python/test_abi.py's check against the C headers.
STRUCTS = {"thz_frame_info": ThzFrameInfo, "thz_batch_progress": ThzBatchProgress,
           "thz_batch_options": ThzBatchOptions, "thz_batch_result": ThzBatchResult}

_P = c_void_p
_ERR = POINTER(_lib.ThzError)
_PROTOTYPES = {
    "thz_sequence_load": (c_int, [c_char_p, POINTER(c_void_p), _ERR]),
    "thz_sequence_load_within": (c_int, [c_char_p, c_char_p, POINTER(c_void_p), _ERR]),
    "thz_sequence_load_ctx": (c_int, [_P, c_char_p, c_char_p, POINTER(c_void_p), _ERR]),
    "thz_sequence_destroy": (None, [_P]),
    "thz_sequence_frame_count": (c_size_t, [_P]),
    "thz_sequence_sweep_count": (c_size_t, [_P]),
    "thz_sequence_frames_per_sweep": (c_size_t, [_P]),
    "thz_sequence_frame": (c_int, [_P, c_size_t, POINTER(ThzFrameInfo)]),
    "thz_sequence_frame_json": (c_size_t, [_P, c_size_t, c_char_p, c_size_t]),
    "thz_sequence_frame_scene": (c_int, [_P, c_size_t, POINTER(c_void_p), _ERR]),
    "thz_batch_run": (c_int, [_P, _P, c_char_p, POINTER(ThzBatchOptions),
                              POINTER(ThzBatchResult), _ERR]),
}
_lib.bind(_PROTOTYPES)

Frame = collections.namedtuple("Frame", "sweep index time_s dir hash")
Frame.__doc__ = """One frame of a sequence: `sweep` the index of its sweep value (0
without a sweep), `index` its number within that sweep value, `time_s` index / fps in s,
`dir` its directory under a batch's OUTDIR ("frame-00003" or "sweep-01/frame-00003"),
`hash` the 64-bit hash of its inputs (batch.json's input_hash, in hex there)."""

BatchProgress = collections.namedtuple(
    "BatchProgress", "stage frame n_frames computed reused fraction seconds")
BatchProgress.__doc__ = """One progress report of a batch. `stage` is "check" (before
checking frame `frame`, 0-based, of `n_frames`, against the memory, before anything is
written), "frame" (before running it), "run" (while it runs), "movie" (before the
movies) or "done" (once at the end; `frame` is then n_frames); `computed` and `reused` count the
frames this call ran and the ones it found finished; `fraction` (0..1, never falling) is
the share of the whole batch done; `seconds` the wall time so far, s."""

BatchResult = collections.namedtuple(
    "BatchResult", "outdir n_frames computed reused movies seconds summary")
BatchResult.__doc__ = """What thzmap.batch() did: `outdir`; the frames in all,
`computed` by this call, `reused` (found finished with the same input hash: a resumed
batch); `movies` written; `seconds` of wall time; `summary`, OUTDIR/batch.json as a dict
(every frame's status and directory, the sweeps, the movies)."""


class Sequence:
    """A loaded and checked "thzmap-sequence/1" file (read-only): its frames over all
    sweep values, sweep-major. Made by load_sequence."""

    def __init__(self, handle, path):
        self._owned = _lib.Handle(handle, _lib.lib.thz_sequence_destroy)
        self._handle = handle
        self.path = path

    def __len__(self):
        return _lib.lib.thz_sequence_frame_count(self._handle)

    @property
    def n_sweeps(self):
        """Sweep values (1 without a sweep)."""
        return _lib.lib.thz_sequence_sweep_count(self._handle)

    @property
    def frames_per_sweep(self):
        return _lib.lib.thz_sequence_frames_per_sweep(self._handle)

    def _index(self, i):
        n = len(self)
        if isinstance(i, bool) or not isinstance(i, numbers.Integral):
            raise ArgumentError(f"frame: expected a whole number, got {i!r}")
        if not -n <= i < n:
            raise ArgumentError(f"frame: the sequence has {n} frames (0 to {n - 1}), got {i}")
        return int(i) % n

    def frame(self, i):
        """Frame i (0 .. len - 1; negative counts from the end) as a Frame."""
        info = ThzFrameInfo()
        _lib.lib.thz_sequence_frame(self._handle, self._index(i), ctypes.byref(info))
        return Frame(info.sweep, info.index, info.time_s, _lib.text(info.dir), info.hash)

    @property
    def frames(self):
        return [self.frame(i) for i in range(len(self))]

    def frame_json(self, i):
        """Frame i's scene as JSON text: the scene with the keyframes' values at its time
        and its sweep value applied. Relative file paths in it are relative to the
        directory of the sequence's scene file."""
        i = self._index(i)
        n = _lib.lib.thz_sequence_frame_json(self._handle, i, None, 0)
        buf = ctypes.create_string_buffer(n + 1)
        _lib.lib.thz_sequence_frame_json(self._handle, i, buf, n + 1)
        return buf.value.decode("utf-8")

    def frame_dict(self, i):
        """Frame i's scene as a dict (json.loads of frame_json)."""
        return json.loads(self.frame_json(i))

    def frame_scene(self, i):
        """Frame i's scene, loaded (within the sequence's root if it has one): a Scene
        to simulate or render as any other, whose `warnings` are that frame's."""
        i = self._index(i)
        label = f"{self.path}: {self.frame(i).dir}"
        return _load(lambda out, err: _lib.lib.thz_sequence_frame_scene(
            self._handle, i, out, err), label)

    def __repr__(self):
        k = self.n_sweeps
        return (f"<thzmap.Sequence {self.path!r}: {len(self)} frames ({k} sweep "
                f"value{'' if k == 1 else 's'} x {self.frames_per_sweep})>")


def load_sequence(path, root=None, progress=None):
    """Loads and checks the sequence file at `path`, its scene and every frame's scene
    (as `thzmap batch` does before its first frame). Raises SceneError for a bad one:
    its `file` and JSON `path` name the sequence's key (e.g.
    "keyframes[1].objects.person"), or its `reason` names the frame and the scene's
    own error. With `root`, the sequence file and every file it names must lie under
    root (as for load_scene). `progress` as for simulate: the stage "frames", done/total
    frames checked (minutes for the largest sequences); a true return value, or Ctrl-C,
    cancels it."""
    path = _path_arg("path", path)
    r = _root_arg(root)
    check_progress(progress)
    out = ctypes.c_void_p()
    with Call(None, progress) as call:
        status = _lib.lib.thz_sequence_load_ctx(call.ctx, os.fsencode(path), r,
                                                ctypes.byref(out), call.err)
        if status == _lib.OK:
            try:
                call.check(status)  # a callback's exception, or Ctrl-C, that came too late
            except BaseException:
                _lib.lib.thz_sequence_destroy(out.value)
                raise
        elif status == _lib.ERR_CANCELLED:
            call.check(status)  # the callback's exception, Ctrl-C or CancelledError
        else:
            call.check(_lib.OK)
            raise _load_error(status, _lib.text(call.error.message), path, path)
    return Sequence(out.value, path)


# A number in a warning, as the CLI's frame warnings find them (src/cli/frame_warnings.c):
# digits with points between them, and an exponent, free-standing: the digits of a name
# (cam1, ch2, x86_64, h2o) follow a letter, digit or '_' and are not a number, nor is an
# index, digits alone between '[' and ']' (sensors[1] names another sensor than sensors[0]).
_NUMBER = re.compile(r"(?<![A-Za-z0-9_])(?!(?<=\[)[0-9]+\])"
                     r"[0-9](?:[0-9]|\.(?=[0-9]))*(?:[eE][-+]?[0-9]+)?")


class _SeenWarning:
    """A warning as a batch first met it: its frame, the frames that repeated it."""

    def __init__(self, frame, shape):
        self.first = self.last = frame
        self.shape = shape
        self.repeats = self.alike = 0

    def count(self, frame, same):
        """Counts frame once, as repeating it to the letter or but for its numbers; a
        warning of no frame (None) each time, leaving the last frame as it was."""
        if frame is not None:
            if self.last == frame:
                return
            self.last = frame
        if same:
            self.repeats += 1
        else:
            self.alike += 1


class _BatchCall(Call):
    """A Call whose warnings name their frame, each message once (the first frame with
    it), and at the end how many later frames repeated it, to the letter or but for its
    numbers, as `thzmap batch` prints them."""

    _stacklevel = 4  # past __exit__ below

    def __init__(self, threads, sequence):
        super().__init__(threads, None)
        self.frame = 0
        self._sequence = sequence
        self._seen = {}

    def _first(self, text):
        """Whether text is new; else counts it with the warning it repeats."""
        seen = self._seen.get(text)
        if seen is not None:
            seen.count(self.frame, True)
            return False
        shape = _NUMBER.sub("#", text)
        if self.frame is not None:
            for seen in self._seen.values():
                if seen.first is not None and seen.first < self.frame and seen.shape == shape:
                    seen.count(self.frame, False)
                    return False
        self._seen[text] = _SeenWarning(self.frame, shape)
        return True

    def _on_warning(self, user, message):
        try:
            text = _lib.text(message)
            if self._first(text):
                if self.frame is None:
                    self._warnings.append(text)
                else:
                    where = self._sequence.frame(self.frame).dir
                    self._warnings.append(f"{where}: {text}")
        except BaseException as e:  # noqa: B902 - every exception must stop at this frame
            if self._exc is None:
                self._exc = e

    def __exit__(self, exc_type, exc, tb):
        for text, seen in self._seen.items():
            for k, how in ((seen.repeats, "the same"),
                           (seen.alike, "the same but for its numbers")):
                if k:
                    kept = " (each frame's summary.json has its own)" if how != "the same" else ""
                    self._warnings.append(f"{how} in {k} later frame{'' if k == 1 else 's'}"
                                          f"{kept}: {text}")
        return super().__exit__(exc_type, exc, tb)


class _BatchBar:
    """progress=True: one tqdm bar over the batch's frames (fractional while a frame
    runs), or without tqdm a line on stderr at most every second and at each frame."""

    def __init__(self):
        try:
            import tqdm
            self._tqdm = tqdm.tqdm
        except ImportError:
            self._tqdm = None
        self._bar = None
        self._last = (None, 0.0)

    def __call__(self, p):
        if self._tqdm is not None:
            if self._bar is None:
                self._bar = self._tqdm(total=p.n_frames, desc="batch", unit="frames",
                                       leave=False)
            self._bar.n = round(p.fraction * p.n_frames, 3)
            self._bar.set_postfix_str(f"{p.computed} computed, {p.reused} already done", refresh=False)
            self._bar.refresh()
        else:
            now = time.monotonic()
            frame, last = self._last
            if p.stage == "done" or frame != p.frame or now - last >= 1.0:
                self._last = (p.frame, now)
                where = "done" if p.stage == "done" else \
                    ("movies" if p.stage == "movie" else
                     f"checking frame {p.frame + 1}/{p.n_frames}" if p.stage == "check" else
                     f"frame {p.frame + 1}/{p.n_frames}")
                print(f"thzmap: batch: {where}, {100 * p.fraction:.0f} % of the batch, "
                      f"{p.seconds:.1f} s", file=sys.stderr, flush=True)
        return False

    def close(self):
        if self._bar is not None:
            self._bar.close()
        self._bar = None


def batch(sequence, outdir, threads=None, progress=None, movies=True, mpi=False):
    """`thzmap batch SEQUENCE -o OUTDIR` in this process: runs every frame of `sequence`
    (a Sequence, or the path of a sequence file) into outdir/[sweep-NN/]frame-NNNNN/ as
    `thzmap simulate` would, writes outdir/batch.json and (with movies=True, when every
    frame has the same sensors and channels) one movie per sensor and channel. A frame
    already finished in outdir with the same input hash is not run again, so a batch
    that was cancelled or killed resumes. `progress`: True for a bar, or a callable given
    a BatchProgress whose true return value cancels (finished frames stay; raises
    CancelledError). Each frame's warnings become RunWarnings naming the frame, each
    message once. Returns a BatchResult. mpi=True in a script that mpirun started on
    several ranks (thzmap.mpi): the ranks share the batch as `mpirun thzmap batch` does
    (whole frames dealt to them when there are enough); rank 0 alone writes outdir and
    gets the BatchResult, the others None."""
    if isinstance(sequence, (str, bytes, os.PathLike)):
        sequence = load_sequence(sequence)
    elif not isinstance(sequence, Sequence):
        raise ArgumentError(f"sequence: expected a Sequence or a path, got "
                            f"{type(sequence).__name__}")
    outdir = _path_arg("outdir", outdir)
    if not isinstance(movies, bool):
        raise ArgumentError(f"movies: expected True or False, got {movies!r}")
    if not isinstance(mpi, bool):
        raise ArgumentError(f"mpi: expected True or False, got {mpi!r}")
    check_progress(progress)
    comm = _mpi.world() if mpi else None
    if comm is not None and comm.Get_rank() > 0:
        with Call(threads, report_warnings=False) as call:
            _mpi.serve(comm, call, sequence=sequence)
        return None
    report = make_reporter(progress, _BatchBar)
    try:
        with _BatchCall(threads, sequence) as call, _mpi.Shared(comm, call):

            def on_progress(user, p):
                c = p.contents
                stage = _lib.text(c.stage)
                # a frame's warnings name it; the movies' and the end's name none, as
                # `thzmap batch` prints them
                in_frame = stage in ("frame", "run") and c.frame < c.n_frames
                call.frame = c.frame if in_frame else None
                if report is None:
                    return call.guarded(lambda: False)
                return call.guarded(report, BatchProgress(
                    _lib.text(c.stage), c.frame, c.n_frames, c.computed, c.reused, c.fraction,
                    c.seconds))

            callback = BATCH_PROGRESS_FN(on_progress)  # alive until the call returns
            opt = ThzBatchOptions(progress=callback, no_movies=0 if movies else 1)
            res = ThzBatchResult()
            status = _lib.lib.thz_batch_run(call.ctx, sequence._handle, os.fsencode(outdir),
                                            ctypes.byref(opt), ctypes.byref(res), call.err)
            call.check(status)
    finally:
        if report is not None and hasattr(report, "close"):
            report.close()
    with open(os.path.join(outdir, "batch.json"), encoding="utf-8") as f:
        summary = json.load(f)
    return BatchResult(outdir, res.n_frames, res.computed, res.reused, res.movies, res.seconds,
                       summary)
