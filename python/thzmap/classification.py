"""Material recognition on a run (`thzmap classify`, docs/analysis.md): thzmap.classify()
classifies every pixel of a sensor's brightness-temperature cube against the object_id
truth, through the C API of include/thzmap/analysis.h (thz_classify_run);
thzmap.classify_spectra() does the same on arrays the caller holds (thz_cube_create,
thz_classify_cube): spectra pooled over a sweep of runs, say.

Memory. A Classification owns one thz_classification; its arrays (confusion, class map)
are copies, so it may be dropped at any time. The GIL is released while the library
classifies (ctypes releases it around every call).
"""
import ctypes
import json
import math
import numbers
import os
import tempfile
from ctypes import (POINTER, Structure, c_char_p, c_double, c_float, c_int, c_int32,
                    c_long, c_size_t, c_uint8, c_uint32, c_uint64, c_void_p)

import numpy as np

from . import _lib
from .errors import ArgumentError, from_status
from .scene import _path_arg


class ThzClassifyOptions(Structure):
    """thz_classify_options (thzmap/analysis.h), field for field."""
    _fields_ = [("method", c_char_p), ("train_fraction", c_double), ("seed", c_uint64),
                ("netd_k", c_double)]


class ThzClassificationInfo(Structure):
    _fields_ = [("method", c_char_p), ("sensor", c_char_p), ("source", c_char_p),
                ("n_classes", c_size_t), ("columns", c_uint32), ("rows", c_uint32),
                ("pixels", c_uint64), ("training_pixels", c_uint64),
                ("held_out_pixels", c_uint64), ("accuracy", c_double),
                ("held_out_accuracy", c_double)]


# For tests/python/test_bands.py's check against the C headers.
STRUCTS = {"thz_classify_options": ThzClassifyOptions,
           "thz_classification_info": ThzClassificationInfo}

_P = c_void_p
_ERR = POINTER(_lib.ThzError)
_PROTOTYPES = {
    "thz_classify_options_init": (None, [POINTER(ThzClassifyOptions)]),
    "thz_classify_method": (c_char_p, [c_size_t]),
    "thz_classify_run": (c_int, [c_char_p, c_char_p, POINTER(ThzClassifyOptions),
                                 POINTER(c_void_p), _ERR]),
    "thz_classify_cube": (c_int, [_P, _P, POINTER(ThzClassifyOptions), POINTER(c_void_p),
                                  _ERR]),
    "thz_cube_create": (c_int, [c_char_p, c_uint32, c_uint32, c_size_t, POINTER(c_float),
                                POINTER(c_void_p), _ERR]),
    "thz_cube_set_object_names": (c_int, [_P, POINTER(c_char_p), c_size_t, _ERR]),
    "thz_cube_destroy": (None, [_P]),
    "thz_classification_destroy": (None, [_P]),
    "thz_classification_get_info": (None, [_P, POINTER(ThzClassificationInfo)]),
    "thz_classification_class_object": (c_long, [_P, c_size_t]),
    "thz_classification_class_name": (c_char_p, [_P, c_size_t]),
    "thz_classification_class_accuracy": (c_double, [_P, c_size_t]),
    "thz_classification_auc": (c_double, [_P, c_size_t]),
    "thz_classification_confusion": (POINTER(c_uint64), [_P]),
    "thz_classification_map": (POINTER(c_int32), [_P]),
    "thz_classification_training": (POINTER(c_uint8), [_P]),
    "thz_classification_json": (c_char_p, [_P]),
    "thz_classification_write": (c_int, [_P, c_char_p, _ERR]),
}
_lib.bind(_PROTOTYPES)


def methods():
    """The recognition methods' names ("sam", "mahalanobis", ...)."""
    out, i = [], 0
    while True:
        name = _lib.lib.thz_classify_method(i)
        if name is None:
            return out
        out.append(_lib.text(name))
        i += 1


class Classification:
    """The result of classify(). accuracy (over every pixel that sees an object, 0..1),
    held_out_accuracy (over the pixels that did not train; NaN: none), classes (names,
    in the order of the confusion matrix), class_objects (their object indices),
    class_accuracy (per class, over all its pixels: the confusion matrix's row), auc (per
    class, one against the rest on the held-out pixels), confusion (numpy uint64
    (classes, classes): rows the truth, columns the assigned class; it sums to
    `pixels`), class_map (numpy int32 (rows, columns), or truth's shape for
    classify_spectra: the object index of each pixel's class, -1 where nothing is hit),
    training_mask (numpy bool, class_map's shape: the pixels that trained; the held-out
    figures are measured on the classified pixels outside it, so another classifier can
    be trained and scored on the same split), report (the dict of classification.json).
    save(outdir) writes what `thzmap classify -o outdir` writes."""

    def __init__(self, handle):
        self._handle = handle
        ptr = handle.ptr
        info = ThzClassificationInfo()
        _lib.lib.thz_classification_get_info(ptr, ctypes.byref(info))
        self.method = _lib.text(info.method)
        self.sensor = _lib.text(info.sensor)
        self.source = _lib.text(info.source)
        self.pixels = info.pixels
        self.training_pixels = info.training_pixels
        self.held_out_pixels = info.held_out_pixels
        self.accuracy = info.accuracy
        self.held_out_accuracy = info.held_out_accuracy
        n = info.n_classes
        self.classes = [_lib.text(_lib.lib.thz_classification_class_name(ptr, k))
                        for k in range(n)]
        self.class_objects = [_lib.lib.thz_classification_class_object(ptr, k)
                              for k in range(n)]
        self.class_accuracy = [_lib.lib.thz_classification_class_accuracy(ptr, k)
                               for k in range(n)]
        self.auc = [_lib.lib.thz_classification_auc(ptr, k) for k in range(n)]
        conf = _lib.lib.thz_classification_confusion(ptr)
        self.confusion = np.ctypeslib.as_array(conf, shape=(n * n,)).reshape(n, n).copy() \
            if n else np.zeros((0, 0), np.uint64)
        cmap = _lib.lib.thz_classification_map(ptr)
        self.class_map = np.ctypeslib.as_array(
            cmap, shape=(info.rows * info.columns,)).reshape(info.rows, info.columns).copy()
        train = _lib.lib.thz_classification_training(ptr)
        self.training_mask = np.ctypeslib.as_array(
            train, shape=(info.rows * info.columns,)).reshape(info.rows, info.columns) != 0
        self.report = json.loads(_lib.text(_lib.lib.thz_classification_json(ptr)))

    def save(self, outdir):
        """Writes classification.json and S.class.hdr/.img/.png into `outdir` (created if
        missing), all or nothing."""
        outdir = _path_arg("outdir", outdir)
        err = _lib.ThzError()
        status = _lib.lib.thz_classification_write(self._handle.ptr, os.fsencode(outdir),
                                                   ctypes.byref(err))
        if status != _lib.OK:
            raise from_status(status, _lib.text(err.message))

    def __repr__(self):
        return (f"<thzmap.Classification {self.method!r} of {self.sensor or self.source!r}: "
                f"{len(self.classes)} classes, accuracy {self.accuracy:.4f}>")


def _finish(status, out, err):
    """The Classification of a thz_classify_* call's result, or its error raised."""
    if status != _lib.OK:
        if out.value:
            _lib.lib.thz_classification_destroy(out.value)
        raise from_status(status, _lib.text(err.message))
    return Classification(_lib.Handle(out.value, _lib.lib.thz_classification_destroy))


def _classify_dir(run_dir, sensor, o):
    out = c_void_p()
    err = _lib.ThzError()
    status = _lib.lib.thz_classify_run(os.fsencode(run_dir), sensor, ctypes.byref(o),
                                       ctypes.byref(out), ctypes.byref(err))
    return _finish(status, out, err)


def _options(method, train_fraction, seed, netd_k):
    """thz_classify_options of the keywords classify and classify_spectra share (None:
    the default); ArgumentError naming a bad one."""
    o = ThzClassifyOptions()
    _lib.lib.thz_classify_options_init(ctypes.byref(o))
    if method is not None:
        if method not in methods():
            raise ArgumentError(f"method: expected one of {', '.join(methods())}, "
                                f"got {method!r}")
        o.method = method.encode()
    if train_fraction is not None:
        if isinstance(train_fraction, bool) or not isinstance(train_fraction, numbers.Real) \
                or not 0.0 < train_fraction < 1.0:
            raise ArgumentError(f"train_fraction: expected a number in (0, 1), got "
                                f"{train_fraction!r}")
        o.train_fraction = float(train_fraction)
    if seed is not None:
        if isinstance(seed, bool) or not isinstance(seed, numbers.Integral) or \
                not 0 <= seed <= (1 << 63) - 1:
            raise ArgumentError(f"seed: expected a whole number in [0, 2**63 - 1], got {seed!r}")
        o.seed = int(seed)
    if netd_k is not None:
        if isinstance(netd_k, bool) or not isinstance(netd_k, numbers.Real) or \
                not (math.isfinite(netd_k) and netd_k >= 0):
            raise ArgumentError(f"netd_k: expected a number >= 0, got {netd_k!r}")
        o.netd_k = float(netd_k)
    return o


def classify(run, sensor, method=None, train_fraction=None, seed=None, netd_k=None):
    """`thzmap classify` in memory: classifies sensor `sensor`'s cube of `run` (a
    directory `thzmap simulate` wrote, or a Result, which is saved to a temporary
    directory first) with `method` (default "sam"; "sam" and "ace" need 2 channels or more;
    methods() lists them), training on
    `train_fraction` of each class's pixels (default 0.5) chosen by `seed` (default 1);
    `netd_k` > 0 first adds Gaussian noise of that many K. Raises ArgumentError for bad
    arguments and thzmap.Error for a run the library cannot read."""
    from .run import Result
    if not isinstance(sensor, str) or not sensor or "\0" in sensor:
        raise ArgumentError(f"sensor: expected a sensor's name, got {sensor!r}")
    o = _options(method, train_fraction, seed, netd_k)
    name = sensor.encode()
    if isinstance(run, Result):
        if sensor not in run.sensors:
            raise ArgumentError(f"sensor: the run has no sensor {sensor!r} "
                                f"(it has {', '.join(run.sensors)})")
        with tempfile.TemporaryDirectory(prefix="thzmap-classify-") as tmp:
            out = os.path.join(tmp, "run")
            run.save(out)
            return _classify_dir(out, name, o)
    return _classify_dir(_path_arg("run", run), name, o)


# The largest object index a truth may hold: object_id images hold indices as float32,
# exact up to 2^24 (thz_classify_cube refuses larger ones).
_MAX_LABEL = (1 << 24) - 1


def _first_bad(mask):
    """The index (a tuple) of the first True of `mask`, as the error messages give it."""
    return tuple(int(i) for i in np.unravel_index(int(np.argmax(mask)), mask.shape))


def _spectra_arg(spectra):
    """spectra as float32 (rows, columns, channels); ArgumentError naming what is wrong."""
    if isinstance(spectra, (str, bytes)) or spectra is None:
        raise ArgumentError(f"spectra: expected a numpy array of brightness temperatures (K), "
                            f"got {spectra!r}")
    try:
        a = np.asarray(spectra)
    except ValueError as e:  # ragged lists
        raise ArgumentError(f"spectra: expected an array of one shape: {e}") from None
    if a.dtype.kind not in "fiu":
        raise ArgumentError(f"spectra: expected real numbers (brightness temperatures, K), "
                            f"got an array of {a.dtype}")
    if a.ndim not in (2, 3) or 0 in a.shape:
        raise ArgumentError(f"spectra: expected a shape (rows, columns, channels) or (pixels, "
                            f"channels), none of them 0, got {a.shape}")
    with np.errstate(over="ignore", invalid="ignore"):  # said below, by the value
        f = a.astype(np.float32)
    bad = ~np.isfinite(f)
    if bad.any():
        at = _first_bad(bad)
        value = a[at].item()
        why = "not finite" if not np.isfinite(value) else "beyond float32's range"
        raise ArgumentError(f"spectra: the value at {list(at)} is {value!r}: {why} (expected "
                            f"brightness temperatures in K)")
    return f if a.ndim == 3 else f.reshape(1, *f.shape)


def _truth_arg(truth, shape):
    """truth as float32 object indices of `shape` (rows, columns), -1 for none."""
    if isinstance(truth, (str, bytes)) or truth is None:
        raise ArgumentError(f"truth: expected a numpy array of class labels, got {truth!r}")
    try:
        t = np.asarray(truth)
    except ValueError as e:
        raise ArgumentError(f"truth: expected an array of one shape: {e}") from None
    if t.dtype.kind not in "fiu":
        raise ArgumentError(f"truth: expected whole class labels (integers, -1 for none), "
                            f"got an array of {t.dtype}")
    if t.shape != shape:
        raise ArgumentError(f"truth: expected the shape {shape} of spectra without its "
                            f"channels, got {t.shape}")
    if t.dtype.kind == "f":
        bad = ~np.isfinite(t) | (t != np.floor(t))
        if bad.any():
            at = _first_bad(bad)
            raise ArgumentError(f"truth: the label at {list(at)} is {t[at].item()!r}: expected a "
                                f"whole number")
    bad = (t < -1) | (t > _MAX_LABEL)
    if bad.any():
        at = _first_bad(bad)
        raise ArgumentError(f"truth: the label at {list(at)} is {t[at].item()!r}: expected -1 "
                            f"(unclassified) or 0 to {_MAX_LABEL}")
    return t


def _names_arg(names, labels):
    """names as a list of bytes, one per label up to the largest in `labels`."""
    if isinstance(names, (str, bytes)) or not isinstance(names, (list, tuple)):
        raise ArgumentError(f"names: expected a list of class names (names[k]: label k), "
                            f"got {names!r}")
    for k, n in enumerate(names):
        if not isinstance(n, str) or not n or "\0" in n:
            raise ArgumentError(f"names: expected non-empty names, got {n!r} at {k}")
    top = int(labels.max())
    if top >= len(names):
        raise ArgumentError(f"names: {len(names)} names, but truth holds the label {top}")
    return [n.encode() for n in names]


class _Cube:
    """A thz_cube made of a float32 array (copied by the library), destroyed with it."""

    def __init__(self, name, values, columns, rows, bands):
        out = c_void_p()
        err = _lib.ThzError()
        status = _lib.lib.thz_cube_create(name, columns, rows, bands,
                                          values.ctypes.data_as(POINTER(c_float)),
                                          ctypes.byref(out), ctypes.byref(err))
        if status != _lib.OK:
            raise from_status(status, _lib.text(err.message))
        self.handle = _lib.Handle(out.value, _lib.lib.thz_cube_destroy)


def classify_spectra(spectra, truth, method=None, train_fraction=None, seed=None,
                     netd_k=None, names=None):
    """classify() on arrays the caller holds: `spectra` (numpy, brightness temperatures
    in K) shaped (rows, columns, channels) or (pixels, channels), such as spectra pooled
    over several runs, and `truth` the class label of each (integers, or floats holding
    whole numbers such as Image.object_id; -1: not classified) shaped (rows, columns) or
    (pixels,); `names` (optional) the class names, names[k] of label k (else "object k").
    The other keywords as for classify(). Returns a Classification whose class_map has
    truth's shape, sensor None and source "spectra". Raises ArgumentError for a wrong
    shape, dtype, a value that is not finite or a label outside -1 to 2**24 - 1, and
    thzmap.Error for what the library refuses (a truth of fewer than two classes, "sam"
    or "ace" on one channel)."""
    o = _options(method, train_fraction, seed, netd_k)
    values = _spectra_arg(spectra)
    rows, columns, bands = values.shape
    if columns > 0xFFFFFFFF or rows > 0xFFFFFFFF:
        raise ArgumentError(f"spectra: {values.shape[:2]} pixels: expected at most 2**32 - 1 "
                            f"along each axis")
    labels = _truth_arg(truth, np.asarray(spectra).shape[:-1])
    cube = _Cube(b"spectra", np.ascontiguousarray(values.transpose(2, 0, 1)), columns, rows,
                 bands)
    ids = _Cube(b"truth", np.ascontiguousarray(labels, dtype=np.float32).reshape(rows, columns),
                columns, rows, 1)
    if names is not None:
        encoded = _names_arg(names, labels)
        err = _lib.ThzError()
        status = _lib.lib.thz_cube_set_object_names(
            ids.handle.ptr, (c_char_p * len(encoded))(*encoded), len(encoded),
            ctypes.byref(err))
        if status != _lib.OK:
            raise from_status(status, _lib.text(err.message))
    out = c_void_p()
    err = _lib.ThzError()
    status = _lib.lib.thz_classify_cube(cube.handle.ptr, ids.handle.ptr, ctypes.byref(o),
                                        ctypes.byref(out), ctypes.byref(err))
    c = _finish(status, out, err)
    c.class_map = c.class_map.reshape(labels.shape)
    c.training_mask = c.training_mask.reshape(labels.shape)
    return c
