"""Optics at chosen frequencies, through the C API (include/thzmap/atmosphere.h,
materials.h, scene.h): the air's attenuation as `thzmap atmosphere` prints it, the
material library as `thzmap materials` lists it, a scene material's surface optics as
the simulation uses them, and Planck's law as the images use it. For choosing a
detector's frequencies without running a simulation.

Every function takes frequencies in THz as a number or an array (any shape) and returns
numpy float64 arrays of that shape (a plain float for a number). The library computes
each value; nothing here re-implements the physics.
"""
import collections
import ctypes
import math
import numbers
import os
from ctypes import POINTER, Structure, c_char_p, c_double, c_int, c_size_t, c_void_p

import numpy as np

from . import _lib
from .errors import ArgumentError, from_status
from .scene import _path_arg, scene_arg


class ThzAtmOptions(Structure):
    """thz_atm_options (thzmap/atmosphere.h), field for field."""
    _fields_ = [("model", c_char_p), ("temperature_k", c_double), ("pressure_hpa", c_double),
                ("humidity_kind", c_int), ("humidity", c_double), ("h2o_lines_file", c_char_p),
                ("o2_lines_file", c_char_p), ("no_continuum", c_int)]


class ThzAtmInfo(Structure):
    _fields_ = [("model", c_char_p), ("has_air", c_int), ("temperature_k", c_double),
                ("pressure_hpa", c_double), ("h2o_pressure_hpa", c_double),
                ("h2o_density_g_m3", c_double), ("h2o_vmr", c_double), ("emitting", c_int),
                ("emission_temperature_k", c_double), ("background_temperature_k", c_double)]


class ThzAtmAttenuation(Structure):
    _fields_ = [("total_per_m", c_double), ("h2o_lines_per_m", c_double),
                ("h2o_continuum_per_m", c_double), ("o2_per_m", c_double),
                ("dry_continuum_per_m", c_double)]


class ThzLibraryMaterialInfo(Structure):
    _fields_ = [("name", c_char_p), ("description", c_char_p), ("basis", c_char_p),
                ("source", c_char_p), ("note", c_char_p), ("model", c_char_p),
                ("has_valid_range", c_int), ("valid_from_thz", c_double),
                ("valid_to_thz", c_double), ("has_data_range", c_int),
                ("data_from_thz", c_double), ("data_to_thz", c_double),
                ("n_data_ranges", c_size_t)]


class ThzLibraryOptics(Structure):
    _fields_ = [("n", c_double), ("k", c_double), ("eps_real", c_double),
                ("eps_imag", c_double), ("attenuation_per_m", c_double),
                ("normal_reflectance", c_double)]


class ThzSurfaceOptics(Structure):
    _fields_ = [("reflectance_normal", c_double), ("reflectance_mean", c_double),
                ("emissivity_normal", c_double), ("emissivity_mean", c_double),
                ("transmission_mean", c_double), ("attenuation_per_m", c_double),
                ("has_index", c_int), ("n", c_double), ("k", c_double)]


# For tests/python/test_abi.py's check against the C headers.
STRUCTS = {"thz_atm_options": ThzAtmOptions, "thz_atm_info": ThzAtmInfo,
           "thz_atm_attenuation": ThzAtmAttenuation,
           "thz_library_material_info": ThzLibraryMaterialInfo,
           "thz_library_optics": ThzLibraryOptics, "thz_surface_optics": ThzSurfaceOptics}
# enum thz_humidity_kind
HUMIDITY_KINDS = {"dry": 0, "relative": 1, "density_g_m3": 2, "vmr": 3}

_P = c_void_p
_ERR = POINTER(_lib.ThzError)
_PROTOTYPES = {
    "thz_atm_options_init": (None, [POINTER(ThzAtmOptions)]),
    "thz_atm_check_air": (c_int, [POINTER(ThzAtmOptions), _ERR]),
    "thz_atm_create": (c_int, [POINTER(ThzAtmOptions), _P, POINTER(c_void_p), _ERR]),
    "thz_atm_from_scene": (c_int, [_P, POINTER(c_void_p), _ERR]),
    "thz_atm_destroy": (None, [_P]),
    "thz_atm_get_info": (None, [_P, POINTER(ThzAtmInfo)]),
    "thz_atm_check_range": (c_int, [_P, c_double, c_double, c_char_p, _ERR]),
    "thz_atm_attenuation_parts": (None, [_P, c_double, POINTER(ThzAtmAttenuation)]),
    "thz_library_load": (c_int, [POINTER(c_void_p), _ERR]),
    "thz_library_destroy": (None, [_P]),
    "thz_library_count": (c_size_t, [_P]),
    "thz_library_find": (c_int, [_P, c_char_p, POINTER(c_size_t), _ERR]),
    "thz_library_get_info": (None, [_P, c_size_t, POINTER(ThzLibraryMaterialInfo)]),
    "thz_library_in_range": (c_int, [_P, c_size_t, c_double]),
    "thz_library_optics_at": (None, [_P, c_size_t, c_double, POINTER(ThzLibraryOptics)]),
    "thz_scene_material_optics": (c_int, [_P, c_size_t, c_double, c_double,
                                          POINTER(ThzSurfaceOptics)]),
    "thz_planck_radiance": (c_double, [c_double, c_double]),
    "thz_brightness_temperature": (c_double, [c_double, c_double]),
}
_lib.bind(_PROTOTYPES)


# The highest centre frequency a channel may have (docs/scene-format.md, channels).
MAX_FREQUENCY_THZ = 10000.0


def _frequencies(frequency_thz, name="frequency_thz"):
    """(flat float64 array in Hz, the shape to return, whether a scalar was given)."""
    bad = ArgumentError(f"{name}: expected a number or an array of numbers in THz, "
                        f"got {frequency_thz!r}")
    try:
        f = np.asarray(frequency_thz)
    except (TypeError, ValueError):
        raise bad from None
    if f.dtype.kind not in "iuf":  # not True, "0.5" (numpy would read the text), None
        raise bad
    f = f.astype(np.float64)
    if not np.all(np.isfinite(f)) or np.any(f <= 0):
        raise ArgumentError(f"{name}: expected frequencies above 0 THz, finite")
    if np.any(f > MAX_FREQUENCY_THZ):  # a channel's limit; beyond, most likely Hz or GHz
        raise ArgumentError(f"{name}: {np.max(f):g} THz is above {MAX_FREQUENCY_THZ:g} THz, "
                            "the highest a channel may have: frequencies are in THz "
                            "(0.82 for 820 GHz)")
    return (f * 1e12).ravel(), f.shape, f.ndim == 0


def _shaped(values, shape, scalar):
    a = np.asarray(values, dtype=np.float64).reshape(shape)
    return float(a) if scalar else a


def _number(name, value, lo=None, hi=None):
    if isinstance(value, bool) or not isinstance(value, numbers.Real) or \
            not math.isfinite(value):
        raise ArgumentError(f"{name}: expected a finite number, got {value!r}")
    if (lo is not None and value < lo) or (hi is not None and value > hi):
        want = (f"in [{lo:g}, {hi:g}]" if lo is not None and hi is not None else
                f"at least {lo:g}" if lo is not None else f"at most {hi:g}")
        raise ArgumentError(f"{name}: expected a number {want}, got {value!r}")
    return float(value)


# ---- the atmosphere --------------------------------------------------------------------

AirInfo = collections.namedtuple("AirInfo", [f for f, _ in ThzAtmInfo._fields_])
AirInfo.__doc__ = """An atmosphere's model and air: temperature_k, pressure_hpa (total),
h2o_pressure_hpa, h2o_density_g_m3, h2o_vmr (0 without air: has_air false); emitting,
emission_temperature_k and background_temperature_k (a scene's)."""

_PARTS = ("total_per_m", "h2o_lines_per_m", "h2o_continuum_per_m", "o2_per_m",
          "dry_continuum_per_m")


class Atmosphere:
    """An attenuation model alpha(nu) in given air (thz_atm). Made by atmosphere()."""

    def __init__(self, handle, keep=None):
        self._owned = _lib.Handle(handle, _lib.lib.thz_atm_destroy, keep)
        self._handle = handle
        info = ThzAtmInfo()
        _lib.lib.thz_atm_get_info(handle, ctypes.byref(info))
        self.info = AirInfo(*[_lib.text(v) if isinstance(v, bytes) else v
                              for v in (getattr(info, f) for f, _ in ThzAtmInfo._fields_)])

    @property
    def model(self):
        return self.info.model

    def _check_range(self, f_hz):
        if f_hz.size == 0:
            return
        err = _lib.ThzError()
        st = _lib.lib.thz_atm_check_range(self._handle, float(f_hz.min()), float(f_hz.max()),
                                          b"frequency_thz", ctypes.byref(err))
        if st != _lib.OK:
            raise from_status(st, _lib.text(err.message))

    def attenuation(self, frequency_thz):
        """A dict of the attenuation per part in 1/m ("total_per_m", "h2o_lines_per_m",
        "h2o_continuum_per_m", "o2_per_m", "dry_continuum_per_m"; parts the model lacks
        are 0; itu-p676 puts all its water vapour into h2o_lines_per_m), each shaped as
        frequency_thz. Frequencies outside the model's range raise Error."""
        f_hz, shape, scalar = _frequencies(frequency_thz)
        self._check_range(f_hz)
        out = np.empty((len(_PARTS), f_hz.size))
        p = ThzAtmAttenuation()
        for i, f in enumerate(f_hz):
            _lib.lib.thz_atm_attenuation_parts(self._handle, float(f), ctypes.byref(p))
            out[:, i] = [getattr(p, name) for name in _PARTS]
        return {name: _shaped(out[j], shape, scalar) for j, name in enumerate(_PARTS)}

    def attenuation_per_m(self, frequency_thz):
        """The total attenuation alpha in 1/m (power), shaped as frequency_thz."""
        return self.attenuation(frequency_thz)["total_per_m"]

    def attenuation_db_per_km(self, frequency_thz):
        """alpha in dB/km, as `thzmap atmosphere` prints it."""
        return self.attenuation_per_m(frequency_thz) * (1000.0 * 10.0 / math.log(10.0))

    def transmittance(self, frequency_thz, distance_m):
        """exp(-alpha * distance_m) of a path through this air; distance_m (m, at least 0)
        a number or an array that broadcasts against frequency_thz."""
        alpha = self.attenuation_per_m(frequency_thz)
        if np.ndim(distance_m) == 0:
            d = _number("distance_m", distance_m, 0.0)
        else:
            try:
                d = np.asarray(distance_m)
                if d.dtype.kind not in "iuf":  # text, booleans, None
                    raise TypeError
                d = d.astype(np.float64)
                np.broadcast_shapes(np.shape(alpha), d.shape)
            except (TypeError, ValueError):
                raise ArgumentError("distance_m: expected a number or an array of numbers in m "
                                    "that broadcasts against frequency_thz, got "
                                    f"{distance_m!r}") from None
            if not np.all(np.isfinite(d)) or np.any(d < 0):
                raise ArgumentError("distance_m: expected finite numbers of at least 0 m")
        return np.exp(-alpha * d)

    def __repr__(self):
        i = self.info
        air = (f"{i.temperature_k:g} K, {i.pressure_hpa:g} hPa, {i.h2o_density_g_m3:.3g} g/m3 "
               "water vapour" if i.has_air else "no air")
        return f"<thzmap.Atmosphere {i.model}: {air}>"


def atmosphere(model="lines", temperature_k=None, pressure_hpa=None, relative_humidity=None,
               water_vapour_g_m3=None, h2o_vmr=None, h2o_lines=None, o2_lines=None,
               continuum=True, scene=None):
    """An atmosphere as `thzmap atmosphere` makes it: `model` "lines" (line by line, the
    default), "itu-p676" (1-1000 GHz) or "none", in air of temperature_k (100-400 K,
    default 288.15), pressure_hpa (total, default 1013.25) and at most one humidity:
    relative_humidity (0..1), water_vapour_g_m3 (default 7.5) or h2o_vmr; for "lines" the
    catalogues h2o_lines and o2_lines (files; None: built in) and continuum=False for
    no MT_CKD continuum; "none" has no air and takes none of them. With `scene` (a Scene or a path) and nothing else, the scene's own
    atmosphere, whatever its model."""
    if scene is not None:
        scene = scene_arg(scene)
        others = (temperature_k, pressure_hpa, relative_humidity, water_vapour_g_m3, h2o_vmr,
                  h2o_lines, o2_lines)
        if model != "lines" or any(v is not None for v in others) or continuum is not True:
            raise ArgumentError("scene: the scene's atmosphere takes no other arguments")
        out = ctypes.c_void_p()
        err = _lib.ThzError()
        st = _lib.lib.thz_atm_from_scene(scene._handle, ctypes.byref(out), ctypes.byref(err))
        if st != _lib.OK:
            raise from_status(st, _lib.text(err.message))
        return Atmosphere(out.value, scene)  # borrows the scene
    if model not in ("lines", "itu-p676", "none"):
        raise ArgumentError(f"model: expected \"lines\", \"itu-p676\" or \"none\", got "
                            f"{model!r}")
    air = {"temperature_k": temperature_k, "pressure_hpa": pressure_hpa,
           "relative_humidity": relative_humidity, "water_vapour_g_m3": water_vapour_g_m3,
           "h2o_vmr": h2o_vmr}
    given = [k for k, v in air.items() if v is not None]
    if model == "none" and given:
        raise ArgumentError(f"{', '.join(given)}: describe the air of a lines or itu-p676 "
                            f"model; model \"none\" has no air")
    o = ThzAtmOptions()
    _lib.lib.thz_atm_options_init(ctypes.byref(o))
    o.model = model.encode()
    if temperature_k is not None:
        o.temperature_k = _number("temperature_k", temperature_k)
    if pressure_hpa is not None:
        o.pressure_hpa = _number("pressure_hpa", pressure_hpa)
    # (the argument's name, the library's kind of humidity, the value)
    humidities = [(n, k, v) for n, k, v in (
        ("relative_humidity", "relative", relative_humidity),
        ("water_vapour_g_m3", "density_g_m3", water_vapour_g_m3),
        ("h2o_vmr", "vmr", h2o_vmr)) if v is not None]
    if len(humidities) > 1:
        raise ArgumentError("relative_humidity, water_vapour_g_m3, h2o_vmr: give at most one")
    if humidities:
        name, kind, value = humidities[0]
        o.humidity_kind = HUMIDITY_KINDS[kind]
        o.humidity = _number(name, value)
    files = []
    for name, value in (("h2o_lines", h2o_lines), ("o2_lines", o2_lines)):
        if value is not None:
            if model != "lines":
                raise ArgumentError(f"{name}: only for the lines model")
            files.append(os.fsencode(_path_arg(name, value)))
            setattr(o, f"{name}_file", files[-1])
    if continuum is not True:
        if continuum is not False or model != "lines":
            raise ArgumentError("continuum: True or False, for the lines model")
        o.no_continuum = 1
    err = _lib.ThzError()
    if model != "none" and _lib.lib.thz_atm_check_air(ctypes.byref(o), ctypes.byref(err)) \
            != _lib.OK:
        raise ArgumentError(_lib.text(err.message))
    out = ctypes.c_void_p()
    st = _lib.lib.thz_atm_create(ctypes.byref(o), None, ctypes.byref(out), ctypes.byref(err))
    if st != _lib.OK:
        raise from_status(st, _lib.text(err.message))
    return Atmosphere(out.value)


# ---- the material library -------------------------------------------------------------

LibraryMaterial = collections.namedtuple(
    "LibraryMaterial", [f for f, _ in ThzLibraryMaterialInfo._fields_])
LibraryMaterial.__doc__ = """A library entry as `thzmap materials NAME` describes it:
name, description, basis ("measured", "model", "fit", "assumed"), source (the citation),
note, model ("constant", "table", "debye", "double-debye", "lorentz", "drude",
"itu-p2040"), the source's stated validity (has_valid_range, valid_from_thz,
valid_to_thz) and the data's range (has_data_range, data_from_thz, data_to_thz,
n_data_ranges)."""

MaterialOptics = collections.namedtuple("MaterialOptics", [f for f, _ in
                                                           ThzLibraryOptics._fields_])
MaterialOptics.__doc__ = """A library material's complex index n + ik, its relative
permittivity eps_real + i eps_imag, the power attenuation inside it (1/m) and its
reflectance at normal incidence from air, each shaped as the frequencies."""


class MaterialLibrary:
    """The material library shipped with thzmap (a scene's "library": "NAME"). Made by
    material_library()."""

    def __init__(self, handle):
        self._owned = _lib.Handle(handle, _lib.lib.thz_library_destroy)
        self._handle = handle
        self.materials = []
        for i in range(_lib.lib.thz_library_count(handle)):
            info = ThzLibraryMaterialInfo()
            _lib.lib.thz_library_get_info(handle, i, ctypes.byref(info))
            self.materials.append(LibraryMaterial(*[
                _lib.text(v) if isinstance(v, bytes) else v
                for v in (getattr(info, f) for f, _ in ThzLibraryMaterialInfo._fields_)]))

    @property
    def names(self):
        return [m.name for m in self.materials]

    def _index(self, name):
        if not isinstance(name, str):
            raise ArgumentError(f"name: expected a material's name, got {name!r}")
        index = c_size_t()
        err = _lib.ThzError()
        if _lib.lib.thz_library_find(self._handle, name.encode(), ctypes.byref(index),
                                     ctypes.byref(err)) != _lib.OK:
            raise ArgumentError(_lib.text(err.message))
        return index.value

    def info(self, name):
        return self.materials[self._index(name)]

    def optics(self, name, frequency_thz):
        """The material's MaterialOptics at frequency_thz. Frequencies outside the range
        its source states (or, for itu-p2040 entries, its rows') raise ArgumentError, as
        a scene using it would be refused."""
        i = self._index(name)
        f_hz, shape, scalar = _frequencies(frequency_thz)
        for f in f_hz:
            if not _lib.lib.thz_library_in_range(self._handle, i, float(f)):
                raise ArgumentError(f"frequency_thz: {f / 1e12:g} THz is outside the range "
                                    f"of \"{name}\"'s data or source")
        fields = [f for f, _ in ThzLibraryOptics._fields_]
        out = np.empty((len(fields), f_hz.size))
        o = ThzLibraryOptics()
        for j, f in enumerate(f_hz):
            _lib.lib.thz_library_optics_at(self._handle, i, float(f), ctypes.byref(o))
            out[:, j] = [getattr(o, k) for k in fields]
        return MaterialOptics(*[_shaped(out[k], shape, scalar) for k in range(len(fields))])

    def __len__(self):
        return len(self.materials)

    def __repr__(self):
        return f"<thzmap.MaterialLibrary: {len(self)} materials>"


def material_library():
    """The material library, as `thzmap materials` lists it."""
    out = ctypes.c_void_p()
    err = _lib.ThzError()
    st = _lib.lib.thz_library_load(ctypes.byref(out), ctypes.byref(err))
    if st != _lib.OK:
        raise from_status(st, _lib.text(err.message))
    return MaterialLibrary(out.value)


# ---- a scene's surfaces, and Planck's law ----------------------------------------------

SurfaceOptics = collections.namedtuple("SurfaceOptics", [f for f, _ in
                                                         ThzSurfaceOptics._fields_])
SurfaceOptics.__doc__ = """A scene material's optics as the simulation uses them
(docs/physics.md "Surfaces"): reflectance_normal and reflectance_mean (R at normal
incidence, hemispherical mean), emissivity_normal and emissivity_mean, transmission_mean
(0 for a half-space), attenuation_per_m inside it, and n, k where has_index (1) says it
has a complex index; each shaped as the frequencies (has_index a plain int)."""


def surface_optics(scene, material, frequency_thz, thickness_m=0.0):
    """The optics of `scene`'s material (its name or index) at frequency_thz, for a
    half-space (thickness_m 0: a solid) or a slab of thickness_m (a shell)."""
    scene = scene_arg(scene)
    names = [m.name for m in scene.materials]
    if isinstance(material, str) and material in names:
        i = names.index(material)
    elif isinstance(material, numbers.Integral) and not isinstance(material, bool) and \
            0 <= material < len(names):
        i = int(material)
    else:
        raise ArgumentError(f"material: the scene has no material {material!r} (it has "
                            f"{', '.join(names)})")
    t = _number("thickness_m", thickness_m, 0.0)
    f_hz, shape, scalar = _frequencies(frequency_thz)
    fields = [f for f, _ in ThzSurfaceOptics._fields_]
    out = np.empty((len(fields), f_hz.size))
    o = ThzSurfaceOptics()
    for j, f in enumerate(f_hz):
        if _lib.lib.thz_scene_material_optics(scene._handle, i, float(f), t,
                                              ctypes.byref(o)) != _lib.OK:
            raise ArgumentError(f"material {names[i]!r} at {f / 1e12:g} THz, thickness "
                                f"{t:g} m: refused by the library")
        out[:, j] = [getattr(o, k) for k in fields]
    values = [_shaped(out[k], shape, scalar) for k in range(len(fields))]
    values[fields.index("has_index")] = int(out[fields.index("has_index"), 0]) if f_hz.size \
        else 0
    return SurfaceOptics(*values)


def _per_frequency(fn, frequency_thz, other, name, lowest=None):
    """fn(freq_hz, x) over frequency_thz and `other` (called `name`: finite numbers, at
    least `lowest` unless None) broadcast against each other."""
    hz, shape, _ = _frequencies(frequency_thz)  # checked, in Hz
    f = hz.reshape(shape)
    try:
        x = np.asarray(other)
        if x.dtype.kind not in "iuf":  # "300" (numpy would read the text), True, None
            raise TypeError(f"got {other!r}")
        x = x.astype(np.float64)
        fb, xb = np.broadcast_arrays(f, x)
    except (TypeError, ValueError) as e:
        raise ArgumentError(f"{name}: expected a number or an array of numbers that "
                            f"broadcasts against frequency_thz ({e})") from None
    if isinstance(other, bool) or not np.all(np.isfinite(x)) or \
            (lowest is not None and np.any(x < lowest)):
        raise ArgumentError(f"{name}: expected finite numbers"
                            + (f" of at least {lowest}" if lowest is not None else ""))
    out = np.array([fn(float(a), float(b)) for a, b in zip(fb.ravel(), xb.ravel())])
    out = out.reshape(fb.shape)
    return float(out) if out.ndim == 0 else out


def planck_radiance(frequency_thz, temperature_k):
    """Planck's B_nu(T) in W m^-2 sr^-1 Hz^-1, as the images use it; frequency_thz and
    temperature_k broadcast against each other."""
    return _per_frequency(_lib.lib.thz_planck_radiance, frequency_thz, temperature_k,
                          "temperature_k", 0.0)


def brightness_temperature(frequency_thz, radiance):
    """The brightness temperature in K of a radiance (W m^-2 sr^-1 Hz^-1) at
    frequency_thz, Planck's law inverted (0 for radiance <= 0); broadcasts."""
    return _per_frequency(_lib.lib.thz_brightness_temperature, frequency_thz, radiance,
                          "radiance")
