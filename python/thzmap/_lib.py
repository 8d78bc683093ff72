"""The C library: where it is found, and the ctypes declarations of include/thzmap/.

Every structure and prototype here mirrors the public headers field for field;
tests/python/test_abi.py compiles a small C program against those headers and checks
the sizes and offsets of these structures, so a header change that is not made here
too fails a test instead of corrupting memory.

The library is found, in this order:
  1. the file named by the environment variable THZMAP_LIBRARY;
  2. the installed layout: `cmake --install` writes _installed.py next to this file,
     naming the installed library relative to the package;
  3. the build tree of the repository this package sits in (build/libthzmap.so);
  4. the system loader (ctypes.util.find_library("thzmap")).
"""
import ctypes
import ctypes.util
import os
from ctypes import (CFUNCTYPE, POINTER, Structure, c_char, c_char_p, c_double, c_float,
                    c_int, c_long, c_size_t, c_uint32, c_uint64, c_void_p)

# ---- status codes (thzmap.h) ---------------------------------------------------------
OK = 0
ERR_INPUT = 2
ERR_IO = 3
ERR_NOMEM = 4
ERR_LIMIT = 5
ERR_CANCELLED = 6
ERR_INTERNAL = 7

# ---- planes (run.h, enum thz_plane) --------------------------------------------------
PLANE_RADIANCE = 0
PLANE_RADIANCE_STDERR = 1
PLANE_POWER = 2
PLANE_BRIGHTNESS_TEMPERATURE = 3
PLANE_NORMALIZED = 4
PLANE_TEMPERATURE = 5
PLANE_DISTANCE = 6
PLANE_OBJECT_ID = 7
PLANE_VISUAL_RGB = 8
PLANE_MEASURED_RADIANCE = 9
PLANE_MEASURED_BRIGHTNESS_TEMPERATURE = 10

# ---- file kinds (scene.h, enum thz_file_kind) ------------------------------------------
FILE_KINDS = {0: "other", 1: "scene", 2: "sequence", 3: "photon-map"}


# ---- structures ------------------------------------------------------------------------
class ThzError(Structure):
    _fields_ = [("status", c_int), ("message", c_char * 1024)]


class ThzProgress(Structure):
    _fields_ = [("stage", c_char_p), ("channel", c_size_t), ("n_channels", c_size_t),
                ("done", c_uint64), ("total", c_uint64)]


class ThzSceneInfo(Structure):
    _fields_ = [("name", c_char_p), ("path", c_char_p), ("atmosphere_model", c_char_p),
                ("n_channels", c_size_t), ("n_materials", c_size_t), ("n_objects", c_size_t),
                ("n_sensors", c_size_t), ("n_warnings", c_size_t),
                ("photons_per_channel", c_uint64), ("seed", c_uint64),
                ("min_relative_power", c_double), ("gather_min_photons", c_uint32),
                ("integrator", c_char_p), ("gather_rays", c_uint32),
                ("paths_per_sample", c_uint32)]


class ThzChannelInfo(Structure):
    _fields_ = [("name", c_char_p), ("frequency_hz", c_double), ("frequency_thz", c_double),
                ("relative_width", c_double), ("bandwidth_hz", c_double),
                ("emitted_power_w_per_hz", c_double), ("noise_bandwidth_hz", c_double),
                ("fwhm_hz", c_double), ("response_points", c_size_t)]


class ThzSpectrumInfo(Structure):
    _fields_ = [("kind", c_int), ("n_points", c_size_t), ("value", c_double),
                ("from_thz", c_double), ("to_thz", c_double), ("min_value", c_double),
                ("max_value", c_double)]


class ThzMaterialInfo(Structure):
    _fields_ = [("name", c_char_p), ("reflectivity", ThzSpectrumInfo),
                ("attenuation_per_m", ThzSpectrumInfo), ("emissivity", ThzSpectrumInfo),
                ("transmission", c_char_p), ("color", c_double * 3),
                ("index_model", c_char_p), ("reflection", c_char_p),
                ("ward_alpha_x", c_double), ("ward_alpha_y", c_double)]


class ThzObjectInfo(Structure):
    _fields_ = [("name", c_char_p), ("type", c_char_p), ("two_sided", c_int),
                ("thickness_m", c_double), ("material", c_size_t), ("material_name", c_char_p),
                ("temperature_k", c_double), ("triangles", c_size_t), ("area_m2", c_double),
                ("bbox_min_m", c_double * 3), ("bbox_max_m", c_double * 3)]


class ThzSensorInfo(Structure):
    _fields_ = [("name", c_char_p), ("columns", c_uint32), ("rows", c_uint32),
                ("channels", c_size_t), ("fov_deg", c_double), ("oversampling", c_uint32),
                ("aperture_m2", c_double), ("position_m", c_double * 3),
                ("direction", c_double * 3), ("up", c_double * 3), ("normalize_to_k", c_double)]


class ThzRunSettings(Structure):
    _fields_ = [("photons_per_channel", c_uint64), ("has_seed", c_int), ("seed", c_uint64),
                ("integrator", c_char_p), ("target_noise_k", c_double),
                ("max_seconds", c_double), ("keep_photons", c_int),
                ("first_photon", c_uint64), ("seconds_load", c_double),
                ("plan", c_void_p), ("plan_user", c_void_p)]


class ThzPhotonStats(Structure):
    _fields_ = [(n, c_uint64) for n in
                ("fired", "stored", "hits", "reflected", "transmitted", "absorbed", "escaped",
                 "back_face_hits", "terminated", "bounce_capped", "rays")] + \
               [(n, c_double) for n in
                ("emitted_power_w_per_hz", "fired_power_w_per_hz", "absorbed_power_w_per_hz",
                 "escaped_power_w_per_hz", "atmosphere_power_w_per_hz",
                 "terminated_power_w_per_hz", "mean_bounces", "reference_temperature_k",
                 "seconds")]


class ThzRunTotals(Structure):
    _fields_ = [("n_channels", c_size_t), ("n_sensors", c_size_t),
                ("photons_fired", c_uint64), ("photons_stored", c_uint64),
                ("back_face_samples", c_uint64), ("n_warnings", c_size_t),
                ("worst_median_stderr_k", c_double), ("max_passes", c_uint32),
                ("seconds", c_double), ("worst_p95_stderr_k", c_double),
                ("worst_object", c_long), ("worst_object_channel", c_size_t),
                ("worst_object_p95_stderr_k", c_double)]


class ThzWriteOptions(Structure):
    _fields_ = [("photon_map", c_int), ("ply_max_points", c_uint64)]


# The structures tests/python/test_abi.py checks against the C headers.
STRUCTS = {"thz_error": ThzError, "thz_progress": ThzProgress,
           "thz_scene_info": ThzSceneInfo, "thz_channel_info": ThzChannelInfo,
           "thz_spectrum_info": ThzSpectrumInfo, "thz_material_info": ThzMaterialInfo,
           "thz_object_info": ThzObjectInfo, "thz_sensor_info": ThzSensorInfo,
           "thz_run_settings": ThzRunSettings, "thz_photon_stats": ThzPhotonStats,
           "thz_run_totals": ThzRunTotals, "thz_write_options": ThzWriteOptions}

PROGRESS_FN = CFUNCTYPE(c_int, c_void_p, POINTER(ThzProgress))
WARNING_FN = CFUNCTYPE(None, c_void_p, c_char_p)

_P = c_void_p  # every opaque handle
_ERR = POINTER(ThzError)
_PP = POINTER(c_void_p)

# name: (return type, argument types)
_PROTOTYPES = {
    "thz_version": (c_char_p, []),
    "thz_revision": (c_char_p, []),
    "thz_status_name": (c_char_p, [c_int]),
    "thz_context_create": (_P, []),
    "thz_context_destroy": (None, [_P]),
    "thz_context_set_threads": (None, [_P, c_int]),
    "thz_context_set_progress": (None, [_P, PROGRESS_FN, c_void_p]),
    "thz_context_set_warning": (None, [_P, WARNING_FN, c_void_p]),
    "thz_scene_load": (c_int, [c_char_p, _PP, _ERR]),
    "thz_scene_load_string": (c_int, [c_char_p, c_char_p, c_char_p, _PP, _ERR]),
    "thz_scene_load_within": (c_int, [c_char_p, c_char_p, _PP, _ERR]),
    "thz_scene_load_string_within": (c_int, [c_char_p, c_char_p, c_char_p, c_char_p, _PP, _ERR]),
    "thz_scene_destroy": (None, [_P]),
    "thz_file_identify": (c_int, [c_char_p, POINTER(c_int), _ERR]),
    "thz_scene_get_info": (c_int, [_P, POINTER(ThzSceneInfo)]),
    "thz_scene_channel": (c_int, [_P, c_size_t, POINTER(ThzChannelInfo)]),
    "thz_scene_material": (c_int, [_P, c_size_t, POINTER(ThzMaterialInfo)]),
    "thz_scene_object": (c_int, [_P, c_size_t, POINTER(ThzObjectInfo)]),
    "thz_scene_sensor": (c_int, [_P, c_size_t, POINTER(ThzSensorInfo)]),
    "thz_scene_sensor_index": (c_long, [_P, c_char_p]),
    "thz_scene_warning_count": (c_size_t, [_P]),
    "thz_scene_warning": (c_char_p, [_P, c_size_t]),
    "thz_integrator_known": (c_int, [c_char_p]),
    "thz_integrator_needs_photons": (c_int, [c_char_p]),
    "thz_photons_fire": (c_int, [_P, _P, POINTER(ThzRunSettings), _PP, _ERR]),
    "thz_photons_load": (c_int, [_P, _P, c_char_p, _PP, _ERR]),
    "thz_photons_load_channel": (c_int, [_P, _P, c_char_p, c_size_t, _PP, _ERR]),
    "thz_photons_save": (c_int, [_P, c_char_p, _ERR]),
    "thz_photons_merge": (c_int, [_P, POINTER(c_void_p), c_size_t, _PP, _ERR]),
    "thz_photons_destroy": (None, [_P]),
    "thz_photons_channel_count": (c_size_t, [_P]),
    "thz_photons_has_channel": (c_int, [_P, c_size_t]),
    "thz_photons_seed": (c_uint64, [_P]),
    "thz_photons_per_channel": (c_uint64, [_P]),
    "thz_photons_stats": (c_int, [_P, c_size_t, POINTER(ThzPhotonStats)]),
    "thz_image_columns": (c_uint32, [_P]),
    "thz_image_rows": (c_uint32, [_P]),
    "thz_image_channel_count": (c_size_t, [_P]),
    "thz_image_sensor_name": (c_char_p, [_P]),
    "thz_image_plane": (POINTER(c_float), [_P, c_int, POINTER(c_size_t)]),
    "thz_simulate": (c_int, [_P, _P, POINTER(ThzRunSettings), _PP, _ERR]),
    "thz_render_run": (c_int, [_P, _P, _P, c_long, POINTER(ThzRunSettings), _PP, _ERR]),
    "thz_render_file": (c_int, [_P, _P, c_char_p, c_long, POINTER(ThzRunSettings), _PP, _ERR]),
    "thz_run_destroy": (None, [_P]),
    "thz_run_image_count": (c_size_t, [_P]),
    "thz_run_image": (_P, [_P, c_size_t]),
    "thz_run_photons": (_P, [_P]),
    "thz_run_summary_json": (c_char_p, [_P]),
    "thz_run_get_totals": (None, [_P, POINTER(ThzRunTotals)]),
    "thz_run_write": (c_int, [_P, _P, c_char_p, POINTER(ThzWriteOptions), _ERR]),
}


def _package_dir():
    return os.path.dirname(os.path.abspath(__file__))


def _candidates():
    """Paths to try, in order, with where each comes from."""
    env = os.environ.get("THZMAP_LIBRARY")
    if env:
        yield env, "THZMAP_LIBRARY"
        return  # an explicit choice is never silently replaced by another library
    here = _package_dir()
    try:
        from . import _installed  # written by cmake --install
        yield os.path.normpath(os.path.join(here, _installed.LIBRARY)), "installed layout"
    except ImportError:
        pass
    for name in sorted(os.listdir(here)):
        if name.startswith("libthzmap.so"):
            yield os.path.join(here, name), "next to the package"
    yield os.path.join(here, "..", "..", "build", "libthzmap.so"), "build tree"
    found = ctypes.util.find_library("thzmap")
    if found:
        yield found, "system loader"


def _load():
    tried = []
    for path, origin in _candidates():
        if origin != "system loader" and not os.path.exists(path):
            tried.append(f"{path} ({origin}: no such file)")
            continue
        try:
            return ctypes.CDLL(path), os.path.abspath(path) if os.path.exists(path) else path
        except OSError as e:
            tried.append(f"{path} ({origin}: {e})")
    raise ImportError("thzmap: cannot find libthzmap; tried " + "; ".join(tried) +
                      ". Build it (make build), install it (cmake --install), or set "
                      "THZMAP_LIBRARY to its path")


lib, path = _load()


def bind(prototypes):
    """Gives the library's functions named in `prototypes` ({name: (restype, argtypes)})
    their types; ImportError naming the first one the library lacks."""
    for name, (restype, argtypes) in prototypes.items():
        try:
            fn = getattr(lib, name)
        except AttributeError:
            raise ImportError(f"thzmap: {path} has no function {name}: it is older or newer "
                              "than this package") from None
        fn.restype = restype
        fn.argtypes = argtypes


bind(_PROTOTYPES)


class Handle:
    """A library handle and its destructor, called when the Handle is collected (also
    at interpreter exit: the destructor is held here, not looked up then). `keep` holds
    the Python objects whose handles this one borrows, so they outlive it."""

    def __init__(self, ptr, destroy, *keep):
        self.ptr = ptr
        self._destroy = destroy
        self._keep = keep

    def __del__(self):
        ptr, self.ptr = self.ptr, None
        if ptr and self._destroy is not None:
            self._destroy(ptr)

    def __reduce__(self):
        # pickle and copy.deepcopy reach every object through this: a copy of the pointer
        # would be freed twice, and ctypes' own refusal ('ctypes objects containing
        # pointers cannot be pickled') came with a half-made Handle failing in __del__
        raise TypeError("a thzmap Scene, Result, PhotonMap or other library object holds a "
                        "library handle and cannot be pickled or deep-copied: give another "
                        "process what made it (a scene's path or dict) and load it there, "
                        "or copy the arrays (np.array(image.radiance))")


def text(value):
    """A C string (bytes or None) as str."""
    return None if value is None else value.decode("utf-8", "replace")
