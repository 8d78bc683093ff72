"""Material recognition on a run (`thzmap classify`, docs/analysis.md): thzmap.classify()
classifies every pixel of a sensor's brightness-temperature cube against the object_id
truth, through the C API of include/thzmap/analysis.h (thz_classify_run).

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
from ctypes import (POINTER, Structure, c_char_p, c_double, c_int, c_int32, c_long,
                    c_size_t, c_uint32, c_uint64, c_void_p)

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
    "thz_classification_destroy": (None, [_P]),
    "thz_classification_get_info": (None, [_P, POINTER(ThzClassificationInfo)]),
    "thz_classification_class_object": (c_long, [_P, c_size_t]),
    "thz_classification_class_name": (c_char_p, [_P, c_size_t]),
    "thz_classification_class_accuracy": (c_double, [_P, c_size_t]),
    "thz_classification_auc": (c_double, [_P, c_size_t]),
    "thz_classification_confusion": (POINTER(c_uint64), [_P]),
    "thz_classification_map": (POINTER(c_int32), [_P]),
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
    `pixels`), class_map (numpy int32 (rows, columns): the object index of each pixel's
    class, -1 where nothing is hit), report (the dict of classification.json).
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
        return (f"<thzmap.Classification {self.method!r} of {self.sensor!r}: "
                f"{len(self.classes)} classes, accuracy {self.accuracy:.4f}>")


def _classify_dir(run_dir, sensor, o):
    out = c_void_p()
    err = _lib.ThzError()
    status = _lib.lib.thz_classify_run(os.fsencode(run_dir), sensor, ctypes.byref(o),
                                       ctypes.byref(out), ctypes.byref(err))
    if status != _lib.OK:
        if out.value:
            _lib.lib.thz_classification_destroy(out.value)
        raise from_status(status, _lib.text(err.message))
    return Classification(_lib.Handle(out.value, _lib.lib.thz_classification_destroy))


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
