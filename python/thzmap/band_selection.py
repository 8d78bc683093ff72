"""Band selection (`thzmap bands`, docs/analysis.md): thzmap.bands() chooses the channel
centres (and, if asked, widths) that best separate a scene's targets, through the C API
of include/thzmap/analysis.h (thz_bands_select).

Memory. A BandSelection owns one thz_bands; everything it returns (lists, the dict of
bands.json) is a copy, so it may be dropped at any time. The GIL is released while the
library renders the candidates (ctypes releases it around every call).
"""
import ctypes
import json
import math
import numbers
import os
from ctypes import (POINTER, Structure, c_char_p, c_double, c_int, c_size_t, c_uint32,
                    c_uint64, c_void_p)

from . import _lib
from ._call import Call
from .errors import ArgumentError, from_status
from .scene import Scene, _path_arg


class ThzBandsOptions(Structure):
    """thz_bands_options (thzmap/analysis.h), field for field."""
    _fields_ = [("count", c_size_t), ("from_thz", c_double), ("to_thz", c_double),
                ("step_ghz", c_double), ("relative_width", c_double), ("sensor", c_char_p),
                ("targets", POINTER(c_char_p)), ("n_targets", c_size_t), ("has_netd", c_int),
                ("netd_k", c_double), ("target_temperature_range_k", c_double),
                ("ambient_temperature_range_k", c_double), ("humidity_range", c_double),
                ("paths_per_sample", c_uint32), ("has_seed", c_int), ("seed", c_uint64),
                ("exhaustive_limit", c_uint64), ("relative_widths", POINTER(c_double)),
                ("n_widths", c_size_t), ("thickness_range", c_double),
                ("angle_range_deg", c_double), ("root", c_char_p)]


class ThzBandsInfo(Structure):
    _fields_ = [("n_candidates", c_size_t), ("count", c_size_t), ("n_classes", c_size_t),
                ("search", c_char_p), ("score", c_double)]


# For tests/python/test_bands.py's check against the C headers.
STRUCTS = {"thz_bands_options": ThzBandsOptions, "thz_bands_info": ThzBandsInfo}

_P = c_void_p
_ERR = POINTER(_lib.ThzError)
_PROTOTYPES = {
    "thz_bands_options_init": (None, [POINTER(ThzBandsOptions)]),
    "thz_bands_candidate_centres": (c_double, [POINTER(ThzBandsOptions)]),
    "thz_bands_select": (c_int, [_P, c_char_p, POINTER(ThzBandsOptions), POINTER(c_void_p),
                                 _ERR]),
    "thz_bands_destroy": (None, [_P]),
    "thz_bands_get_info": (None, [_P, POINTER(ThzBandsInfo)]),
    "thz_bands_selected_thz": (c_double, [_P, c_size_t]),
    "thz_bands_selected_relative_width": (c_double, [_P, c_size_t]),
    "thz_bands_score": (c_double, [_P, c_size_t]),
    "thz_bands_json": (c_char_p, [_P]),
    "thz_bands_write": (c_int, [_P, c_char_p, _ERR]),
}
_lib.bind(_PROTOTYPES)

# THZ_BANDS_MAX_COUNT of thzmap/analysis.h; the library checks the count too, and caps the
# candidates (centres x widths) at 4096.
MAX_COUNT = 32
MAX_WIDTHS = 16


def _number(name, value, lo, hi, lo_open=False):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentError(f"{name}: expected a number, got {value!r}")
    value = float(value)
    if not (math.isfinite(value) and (value > lo if lo_open else value >= lo) and value <= hi):
        raise ArgumentError(f"{name}: expected a number in {'(' if lo_open else '['}{lo}, "
                            f"{hi}], got {value}")
    return value


def _whole(name, value, lo, hi):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral) or \
            not lo <= value <= hi:
        raise ArgumentError(f"{name}: expected a whole number in [{lo}, {hi}], got {value!r}")
    return int(value)


def _text(name, value):
    if not isinstance(value, str) or not value or "\0" in value:
        raise ArgumentError(f"{name}: expected a non-empty name, got {value!r}")
    return value.encode()


def _scene_path(scene):
    """The scene file: bands renders variants of the file itself (its JSON), so a Scene
    must come from load_scene."""
    if isinstance(scene, Scene):
        if scene._file is None:
            raise ArgumentError("scene: bands works on a scene file; this Scene was not "
                                "loaded from one (save its JSON and give the path)")
        path = scene._file[0]
        try:
            st = os.stat(path)
        except OSError as e:
            raise ArgumentError(f"scene: {path}, the file this Scene was loaded from, "
                                f"cannot be read now: {e.strerror}") from None
        if (st.st_mtime_ns, st.st_size) != scene._file[1:]:
            raise ArgumentError(f"scene: {path} has changed since this Scene was loaded "
                                f"from it (bands renders the file; load it again)")
        return path
    if isinstance(scene, (str, bytes, os.PathLike)):
        return _path_arg("scene", scene)
    raise ArgumentError(f"scene: expected a path or a thzmap.Scene, got "
                        f"{type(scene).__name__}")


class BandSelection:
    """The result of bands(): the chosen channels and their separability.

    selected_thz: the chosen centres, THz, ascending; selected_relative_width: their
    relative widths (FWHM / centre), aligned; score: their worst-pair Jeffries-Matusita
    distance (0..2); scores[k - 1]: the best set's score with k channels; search:
    "exhaustive" or "sffs"; report: the dict of bands.json (every key of
    docs/analysis.md). save(outdir) writes what `thzmap bands -o outdir` writes."""

    def __init__(self, handle):
        self._handle = handle
        info = ThzBandsInfo()
        _lib.lib.thz_bands_get_info(handle.ptr, ctypes.byref(info))
        self.n_candidates = info.n_candidates
        self.n_classes = info.n_classes
        self.search = _lib.text(info.search)
        self.score = info.score
        k = info.count
        self.selected_thz = [_lib.lib.thz_bands_selected_thz(handle.ptr, i) for i in range(k)]
        self.selected_relative_width = [
            _lib.lib.thz_bands_selected_relative_width(handle.ptr, i) for i in range(k)]
        self.scores = [_lib.lib.thz_bands_score(handle.ptr, i) for i in range(1, k + 1)]
        self.report = json.loads(_lib.text(_lib.lib.thz_bands_json(handle.ptr)))

    @property
    def count(self):
        return len(self.selected_thz)

    def save(self, outdir):
        """Writes bands.json, bands-score.png, bands-spectra.png and, when the air
        attenuates, bands-air.png into `outdir` (created if missing), all or nothing."""
        outdir = _path_arg("outdir", outdir)
        err = _lib.ThzError()
        status = _lib.lib.thz_bands_write(self._handle.ptr, os.fsencode(outdir),
                                          ctypes.byref(err))
        if status != _lib.OK:
            raise from_status(status, _lib.text(err.message))

    def __repr__(self):
        chosen = ", ".join(f"{f:.4g} THz (relative width {w:.3g})"
                           for f, w in zip(self.selected_thz, self.selected_relative_width))
        return f"<thzmap.BandSelection: {chosen}; worst-pair JM {self.score:.4f}>"


def bands(scene, count, from_thz=None, to_thz=None, step_ghz=None, relative_width=None,
          widths=None, targets=None, sensor=None, netd_k=None, temperature_range_k=None,
          ambient_range_k=None, humidity_range=None, thickness_range=None,
          angle_range_deg=None, paths=None, seed=None, threads=None, progress=None):
    """`thzmap bands` in memory: chooses `count` channels among the candidate centres
    from_thz .. to_thz every step_ghz (default 0.1 to 1.5 THz every 10 GHz) that best
    separate the scene's targets (names; default every object the sensor sees), with the
    sensor's noise (netd_k in K, default the sensor's own) and the nuisances (ranges;
    defaults 2 K, 2 K, 0.2, 0, 0 degrees) as the classes' spread. `widths`: relative
    widths to search too (each centre with each width; a set holds a centre once);
    else every candidate has `relative_width` (default: the scene's first channel's).
    `scene` is a scene file's path or a Scene loaded from one. Arguments left None keep
    the library's defaults (docs/analysis.md). Raises SceneError for a bad scene,
    ArgumentError for bad arguments, CancelledError when `progress` cancels."""
    path = _scene_path(scene)
    o = ThzBandsOptions()
    _lib.lib.thz_bands_options_init(ctypes.byref(o))
    o.count = _whole("count", count, 1, MAX_COUNT)
    if from_thz is not None:
        o.from_thz = _number("from_thz", from_thz, 0.0, 1000.0, lo_open=True)
    if to_thz is not None:
        o.to_thz = _number("to_thz", to_thz, 0.0, 1000.0, lo_open=True)
    if step_ghz is not None:
        o.step_ghz = _number("step_ghz", step_ghz, 0.0, 1e6, lo_open=True)
    if relative_width is not None:
        o.relative_width = _number("relative_width", relative_width, 0.0, 0.5, lo_open=True)
    # the candidates' range (o holds the library's defaults where not given)
    lo, hi, step = o.from_thz, o.to_thz, o.step_ghz
    if lo > hi:
        raise ArgumentError(f"from_thz {lo} > to_thz {hi}: expected from_thz <= to_thz")
    centres = int(_lib.lib.thz_bands_candidate_centres(ctypes.byref(o)))
    if o.count > centres:
        raise ArgumentError(f"count {o.count}: only {centres} candidate centres from {lo} to "
                            f"{hi} THz every {step} GHz")
    if widths is not None and relative_width is not None:
        raise ArgumentError("relative_width and widths: give one (the candidates' one width, "
                            "or the widths searched)")
    keep = []  # buffers the options point into, alive until the call returns
    if widths is not None:
        if isinstance(widths, (str, bytes)) or not hasattr(widths, "__iter__"):
            raise ArgumentError(f"widths: expected a sequence of relative widths, got "
                                f"{widths!r}")
        widths = [_number("widths", w, 0.0, 0.5, lo_open=True) for w in widths]
        if not 1 <= len(widths) <= MAX_WIDTHS:
            raise ArgumentError(f"widths: expected 1 to {MAX_WIDTHS} relative widths")
        if len(set(widths)) != len(widths):
            raise ArgumentError(f"widths: a width given twice in {widths}")
        arr = (c_double * len(widths))(*widths)
        keep.append(arr)
        o.relative_widths, o.n_widths = arr, len(widths)
    if targets is not None:
        if isinstance(targets, str):
            targets = [targets]
        if isinstance(targets, (bytes, bytearray)) or not hasattr(targets, "__iter__"):
            raise ArgumentError(f"targets: expected object names, got {targets!r}")
        names = [_text("targets", t) for t in targets]
        if not names:
            raise ArgumentError("targets: expected at least one object name")
        if len(set(names)) != len(names):
            raise ArgumentError(f"targets: an object named twice in {list(targets)}")
        arr = (c_char_p * len(names))(*names)
        keep += [arr, names]
        o.targets, o.n_targets = arr, len(names)
    if sensor is not None:
        name = _text("sensor", sensor)
        keep.append(name)
        o.sensor = name
    if netd_k is not None:
        o.has_netd, o.netd_k = 1, _number("netd_k", netd_k, 0.0, 1e6, lo_open=True)
    for field, value, hi in (("target_temperature_range_k", temperature_range_k, 1000.0),
                             ("ambient_temperature_range_k", ambient_range_k, 1000.0),
                             ("humidity_range", humidity_range, 0.99),
                             ("thickness_range", thickness_range, 0.99),
                             ("angle_range_deg", angle_range_deg, 90.0)):
        if value is not None:
            setattr(o, field, _number(field, value, 0.0, hi))
    if paths is not None:
        o.paths_per_sample = _whole("paths", paths, 1, 1000000)
    if seed is not None:
        o.has_seed, o.seed = 1, _whole("seed", seed, 0, (1 << 63) - 1)
    with Call(threads, progress) as call:
        out = c_void_p()
        status = _lib.lib.thz_bands_select(call.ctx, os.fsencode(path), ctypes.byref(o),
                                           ctypes.byref(out), call.err)
        try:
            call.check(status, path)
        except BaseException:
            if out.value:
                _lib.lib.thz_bands_destroy(out.value)
            raise
    return BandSelection(_lib.Handle(out.value, _lib.lib.thz_bands_destroy))
