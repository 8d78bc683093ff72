"""Runs: simulate and render into a Result, its images as numpy arrays over the
library's own buffers, photon maps (fire, save, load, merge), and writing results.

Memory. A Result owns one thz_run; its images' arrays are read-only numpy views of the
run's float planes (no copy), and every such array keeps the run alive through its
`base` chain, so the run is freed (thz_run_destroy) only when the Result and every array
taken from it are gone. A run borrows its scene, so it keeps the Scene alive too.
"""
import collections
import ctypes
import json
import math
import numbers
import os
import threading

import numpy as np

from . import _lib
from . import mpi as _mpi
from ._call import Call
from .errors import ArgumentError
from .progress import check as check_progress
from .scene import _path_arg, scene_arg

# The CLI's bound of --photons; the library itself does not bound photons_per_channel.
MAX_PHOTONS = 10**12

Totals = collections.namedtuple("Totals", [f for f, _ in _lib.ThzRunTotals._fields_])
PhotonStats = collections.namedtuple("PhotonStats",
                                     [f for f, _ in _lib.ThzPhotonStats._fields_])


class _PlaneBuffer:
    """Exposes one float plane to numpy (read-only) while holding its owner."""

    def __init__(self, owner, address, shape):
        self.owner = owner
        self.__array_interface__ = {"version": 3, "typestr": "<f4", "shape": shape,
                                    "data": (address, True)}


# ---- arguments ------------------------------------------------------------------------
def _whole(name, value, lo, hi=(1 << 64) - 1):
    if isinstance(value, bool) or not isinstance(value, numbers.Integral):
        raise ArgumentError(f"{name}: expected a whole number, got {value!r}")
    if not lo <= value <= hi:
        raise ArgumentError(f"{name}: expected a whole number in [{lo}, {hi}], got {value}")
    return int(value)


def _positive(name, value):
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ArgumentError(f"{name}: expected a number > 0, got {value!r}")
    if not (math.isfinite(value) and value > 0):
        raise ArgumentError(f"{name}: expected a finite number > 0, got {value}")
    return float(value)


def _integrator_arg(integrator):
    if integrator is None:
        return None
    if not isinstance(integrator, str) or "\0" in integrator or \
            not _lib.lib.thz_integrator_known(integrator.encode()):
        raise ArgumentError(f"integrator: expected 'photon-map', 'final-gather' or 'path', "
                            f"got {integrator!r}")
    return integrator


def _effective_integrator(scene, integrator):
    """The integrator a call runs: the one given, else the scene's."""
    return integrator if integrator is not None else scene.info.integrator


def _settings(scene, integrator=None, photons=None, seed=None, target_noise_k=None,
              max_seconds=None, keep_photons=False, first_photon=0):
    s = _lib.ThzRunSettings()
    if photons is not None:
        s.photons_per_channel = _whole("photons", photons, 1, MAX_PHOTONS)
    if seed is not None:
        s.has_seed, s.seed = 1, _whole("seed", seed, 0, (1 << 63) - 1)
    integrator = _integrator_arg(integrator)
    if integrator is not None:
        s.integrator = integrator.encode()  # the structure keeps the bytes alive
    if target_noise_k is not None:
        s.target_noise_k = _positive("target_noise_k", target_noise_k)
    if max_seconds is not None:
        # as --max-seconds: it limits the target given here, the scene's, or the default
        # one; where no target applies a run warning says it is not used
        s.max_seconds = _positive("max_seconds", max_seconds)
    if not isinstance(keep_photons, bool):
        raise ArgumentError(f"keep_photons: expected True or False, got {keep_photons!r}")
    s.keep_photons = 1 if keep_photons else 0
    s.first_photon = _whole("first_photon", first_photon, 0)
    s.seconds_load = scene.seconds_load
    return s


# ---- photon maps ------------------------------------------------------------------------
class PhotonMap:
    """The photon maps of every channel of a scene (the photon phase's result). Made by
    fire_photons, load_photon_map, merge_photon_maps, or kept by simulate
    (keep_photons=True, as Result.photon_map)."""

    def __init__(self, owner, ptr, scene):
        self._owner = owner  # keeps ptr valid: its own Handle, or the run it belongs to
        self._ptr = ptr
        self.scene = scene

    @property
    def seed(self):
        """The seed the photons were fired with."""
        return _lib.lib.thz_photons_seed(self._ptr)

    @property
    def photons_per_channel(self):
        """Photons fired per channel (K)."""
        return _lib.lib.thz_photons_per_channel(self._ptr)

    @property
    def n_channels(self):
        """The scene's channels (a map loaded for one channel holds only that one's)."""
        return _lib.lib.thz_photons_channel_count(self._ptr)

    def has_channel(self, c):
        """Whether channel c's records are in the map (False for the others of a map
        loaded with load_photon_map(..., channel=...))."""
        c = _whole("channel", c, 0, self.n_channels - 1)
        return bool(_lib.lib.thz_photons_has_channel(self._ptr, c))

    @property
    def stats(self):
        """Per channel, the photon phase's statistics (summary.json "channels")."""
        out = []
        for c in range(self.n_channels):
            s = _lib.ThzPhotonStats()
            _lib.lib.thz_photons_stats(self._ptr, c, ctypes.byref(s))
            out.append(PhotonStats(*(getattr(s, f) for f, _ in s._fields_)))
        return out

    def save(self, path):
        """Writes the maps to `path` (.thzpm, what render and load_photon_map read),
        replacing a file there only once the new one is whole."""
        path = _path_arg("path", path)
        err = _lib.ThzError()
        status = _lib.lib.thz_photons_save(self._ptr, os.fsencode(path), ctypes.byref(err))
        if status != _lib.OK:
            from .errors import from_status
            raise from_status(status, _lib.text(err.message))

    def __repr__(self):
        return (f"<thzmap.PhotonMap: {self.n_channels} channels, "
                f"{self.photons_per_channel} photons per channel, seed {self.seed}>")


def _owned_call(call, fn, scene, destroy, *keep):
    """Calls fn(&out) and returns out as a Handle that destroys it, keeping `keep`
    alive; on failure destroys whatever fn left in out and raises."""
    out = ctypes.c_void_p()
    status = fn(ctypes.byref(out))
    try:
        call.check(status, scene.label)
    except BaseException:
        if out.value:
            destroy(out.value)
        raise
    return _lib.Handle(out.value, destroy, scene, *keep)


def _photons_call(call, fn, scene):
    handle = _owned_call(call, fn, scene, _lib.lib.thz_photons_destroy)
    return PhotonMap(handle, handle.ptr, scene)


def fire_photons(scene, integrator=None, photons=None, seed=None, first_photon=0,
                 threads=None, progress=None):
    """The photon phase alone: fires every channel's photons (photons 'first_photon' ..
    + photons - 1, so that maps of disjoint ranges merge)."""
    scene = scene_arg(scene)
    s = _settings(scene, integrator, photons, seed, first_photon=first_photon)
    effective = _effective_integrator(scene, integrator)
    if not _lib.lib.thz_integrator_needs_photons(effective.encode()):
        raise ArgumentError(f"integrator: the {effective} integrator uses no photons; give "
                            "integrator='photon-map' or 'final-gather'")
    with Call(threads, progress) as call:
        return _photons_call(call, lambda out: _lib.lib.thz_photons_fire(
            call.ctx, scene._handle, ctypes.byref(s), out, call.err), scene)


def load_photon_map(scene, path, channel=None, threads=None, progress=None):
    """Reads a photon-map file made from this scene; the library refuses one made from
    another geometry, material or channel set. With `channel` (an index), that channel's
    map alone is kept (the others' records are checked and dropped: has_channel is False
    for them, their statistics are read), for a look at one channel's photons of a large
    file."""
    scene = scene_arg(scene)
    path = _path_arg("path", path)
    if channel is None:
        with Call(threads, progress) as call:
            return _photons_call(call, lambda out: _lib.lib.thz_photons_load(
                call.ctx, scene._handle, os.fsencode(path), out, call.err), scene)
    c = _whole("channel", channel, 0, len(scene.channels) - 1)
    with Call(threads, progress) as call:
        return _photons_call(call, lambda out: _lib.lib.thz_photons_load_channel(
            call.ctx, scene._handle, os.fsencode(path), c, out, call.err), scene)


def merge_photon_maps(parts, threads=None):
    """One photon map of all the photons of `parts` (one scene, seed and integrator,
    fired with disjoint photon ranges). Parts of different Scene objects merge when their
    scenes fit one another as a render's photon map must (the same geometry, channels,
    materials, temperatures and atmosphere; thzmap.Error says what differs); the merged
    map belongs to the first part's Scene."""
    if isinstance(parts, (str, bytes)) or not hasattr(parts, "__iter__"):
        raise ArgumentError(f"parts: expected a non-empty sequence of PhotonMap, got "
                            f"{type(parts).__name__}")
    parts = list(parts)
    if not parts or not all(isinstance(p, PhotonMap) for p in parts):
        raise ArgumentError("parts: expected a non-empty sequence of PhotonMap")
    scene = parts[0].scene
    arr = (ctypes.c_void_p * len(parts))(*(p._ptr for p in parts))
    with Call(threads) as call:
        pm = _photons_call(call, lambda out: _lib.lib.thz_photons_merge(
            call.ctx, arr, len(parts), out, call.err), scene)
    return pm


# ---- images -----------------------------------------------------------------------------
_PLANES = {"radiance": _lib.PLANE_RADIANCE, "radiance_stderr": _lib.PLANE_RADIANCE_STDERR,
           "power": _lib.PLANE_POWER,
           "brightness_temperature": _lib.PLANE_BRIGHTNESS_TEMPERATURE,
           "normalized": _lib.PLANE_NORMALIZED, "temperature": _lib.PLANE_TEMPERATURE,
           "distance": _lib.PLANE_DISTANCE, "object_id": _lib.PLANE_OBJECT_ID,
           "visual": _lib.PLANE_VISUAL_RGB, "measured_radiance": _lib.PLANE_MEASURED_RADIANCE,
           "measured_brightness_temperature": _lib.PLANE_MEASURED_BRIGHTNESS_TEMPERATURE}
_MAPS = (_lib.PLANE_TEMPERATURE, _lib.PLANE_DISTANCE, _lib.PLANE_OBJECT_ID)

class Image:
    """One sensor's rendered image. Cubes are numpy float32 arrays shaped (rows, columns,
    channels): radiance (W m^-2 sr^-1 Hz^-1), radiance_stderr (the same unit; all 0 where
    not estimated: one estimate per sample in one pass), power (W), brightness_temperature (K), normalized (1). Maps shaped (rows, columns):
    temperature (K, -1 where nothing is hit), distance (m, -1: none), object_id (index
    of the object seen as float, -1: none), as in the ENVI files; visual (rows, columns,
    3) rgb 0..1; measured_radiance and measured_brightness_temperature (the sensor's PSF
    and noise applied; None when the sensor has neither) shaped like the cubes. Row 0 is
    the top of the picture. The arrays are read-only views of the library's buffers."""

    def __init__(self, run_owner, ptr, scene):
        self._run = run_owner
        self._ptr = ptr
        self.scene = scene
        self.sensor = _lib.text(_lib.lib.thz_image_sensor_name(ptr))
        self.rows = _lib.lib.thz_image_rows(ptr)
        self.columns = _lib.lib.thz_image_columns(ptr)
        self.n_channels = _lib.lib.thz_image_channel_count(ptr)

    def plane(self, plane):
        """A plane by its file quantity ("radiance", "object_id", "visual", ...) as the
        library lays it out: channel cubes band-sequential (bands, rows, columns) like the
        ENVI files, visual (rows, columns, 3), maps (rows, columns); None when absent."""
        if isinstance(plane, str):
            if plane not in _PLANES:
                raise ArgumentError(f"plane: expected one of {', '.join(_PLANES)}, "
                                    f"got {plane!r}")
            plane = _PLANES[plane]
        elif isinstance(plane, bool) or plane not in _PLANES.values():
            raise ArgumentError(f"plane: expected a plane name, got {plane!r}")
        n = ctypes.c_size_t()
        p = _lib.lib.thz_image_plane(self._ptr, plane, ctypes.byref(n))
        if not p:
            return None
        if plane == _lib.PLANE_VISUAL_RGB:
            shape = (self.rows, self.columns, n.value)
        elif plane in _MAPS:
            shape = (self.rows, self.columns)
        else:
            shape = (n.value, self.rows, self.columns)
        address = ctypes.cast(p, ctypes.c_void_p).value
        return np.asarray(_PlaneBuffer(self._run, address, shape))

    def _cube(self, plane):
        a = self.plane(plane)
        return None if a is None else a.transpose(1, 2, 0)

    radiance = property(lambda self: self._cube(_lib.PLANE_RADIANCE),
                        doc="Band-mean spectral radiance L_c, W m^-2 sr^-1 Hz^-1, float32 "
                            "(rows, columns, channels).")
    radiance_stderr = property(lambda self: self._cube(_lib.PLANE_RADIANCE_STDERR),
                               doc="Standard error of radiance, W m^-2 sr^-1 Hz^-1, (rows, "
                                   "columns, channels); None when the integrator gives none.")
    power = property(lambda self: self._cube(_lib.PLANE_POWER),
                     doc="Power received P_c = L_c Omega_S A_S B_c, W, (rows, columns, "
                         "channels).")
    brightness_temperature = property(
        lambda self: self._cube(_lib.PLANE_BRIGHTNESS_TEMPERATURE),
        doc="Brightness temperature Tb_c, K, (rows, columns, channels).")
    normalized = property(lambda self: self._cube(_lib.PLANE_NORMALIZED),
                          doc="Normalised radiance N_c = L_c / B(T_ref), 1, (rows, columns, "
                              "channels).")
    temperature = property(lambda self: self.plane(_lib.PLANE_TEMPERATURE),
                           doc="Truth: temperature of the surface seen, K, (rows, columns); "
                               "-1 where nothing is hit.")
    distance = property(lambda self: self.plane(_lib.PLANE_DISTANCE),
                        doc="Truth: distance from the pinhole to the surface seen, m, (rows, "
                            "columns); -1 where nothing is hit.")
    object_id = property(lambda self: self.plane(_lib.PLANE_OBJECT_ID),
                         doc="Truth: index into the scene's objects of the object seen, as "
                             "float32 (rows, columns); -1 where nothing is hit.")
    visual = property(lambda self: self.plane(_lib.PLANE_VISUAL_RGB),
                      doc="A shaded picture in the materials' colors (S.visual.png), sRGB "
                          "0..1, (rows, columns, 3).")
    measured_radiance = property(
        lambda self: self._cube(_lib.PLANE_MEASURED_RADIANCE),
        doc="radiance through the sensor's PSF and noise, W m^-2 sr^-1 Hz^-1; None when "
            "the sensor has neither.")
    measured_brightness_temperature = property(
        lambda self: self._cube(_lib.PLANE_MEASURED_BRIGHTNESS_TEMPERATURE),
        doc="brightness_temperature through the sensor's PSF and noise, K; None when the "
            "sensor has neither.")

    @property
    def frequencies_thz(self):
        """The channels' centre frequencies, THz, in the cubes' channel order."""
        return np.array([c.frequency_thz for c in self.scene.channels])

    def __repr__(self):
        return (f"<thzmap.Image {self.sensor!r}: {self.rows} x {self.columns} pixels, "
                f"{self.n_channels} channels>")


# ---- results ----------------------------------------------------------------------------
class Result:
    """A finished run held in memory: its sensors' images, its summary, and its photon
    map when it was kept. save(outdir) writes what `thzmap simulate -o outdir` writes."""

    def __init__(self, owner, scene, photons=None):
        self._owner = owner
        self.scene = scene
        self._photons = photons  # the PhotonMap a render was made from
        ptr = owner.ptr
        self._images = [Image(owner, _lib.lib.thz_run_image(ptr, i), scene)
                        for i in range(_lib.lib.thz_run_image_count(ptr))]
        self._summary = None
        # thz_run_write records its time in the run (thzmap/run.h): a handle used by one
        # thread at a time, so saves of this result take turns; other results' saves go
        # on at once (their figures are drawn in the library's child processes)
        self._lock = threading.RLock()
        kept = _lib.lib.thz_run_photons(ptr)
        self.photon_map = PhotonMap(owner, kept, scene) if kept else None
        self.mpi_bytes = 0  # a run with mpi=True: bytes rank 0 sent and received

    @property
    def sensors(self):
        """Names of the rendered sensors, in scene order."""
        return [im.sensor for im in self._images]

    def image(self, sensor=None):
        """The Image of a sensor given by name or by index among `sensors` (None: the
        only one)."""
        if sensor is None:
            if len(self._images) != 1:
                raise ArgumentError(f"sensor: the run has {len(self._images)} sensors "
                                    f"({', '.join(self.sensors)}); name one")
            return self._images[0]
        if isinstance(sensor, str):
            for im in self._images:
                if im.sensor == sensor:
                    return im
        elif isinstance(sensor, numbers.Integral) and not isinstance(sensor, bool) and \
                0 <= sensor < len(self._images):
            return self._images[sensor]
        raise ArgumentError(f"sensor: the run has no sensor {sensor!r} "
                            f"(it has {', '.join(self.sensors)})")

    @property
    def summary(self):
        """The dict of summary.json (as written by save, but for timings_s.output)."""
        if self._summary is None:
            with self._lock:  # not while a save rewrites it
                self._summary = json.loads(
                    _lib.text(_lib.lib.thz_run_summary_json(self._owner.ptr)))
        return self._summary

    @property
    def totals(self):
        """The run's totals (photons fired and stored, sensors, channels, ...) as a
        named tuple, the fields of thz_run_totals (thzmap/run.h)."""
        t = _lib.ThzRunTotals()
        _lib.lib.thz_run_get_totals(self._owner.ptr, ctypes.byref(t))
        return Totals(*(getattr(t, f) for f, _ in t._fields_))

    def save(self, outdir, photon_map=None, ply_max_points=None, progress=None):
        """Writes every file of the run into `outdir` (created if missing) as the CLI
        does: per sensor the ENVI images and PNGs, summary.json, and photon-map.thzpm with
        photon-map.ply when `photon_map` (default: when the run kept its photons). Files
        appear only when all were written; a failure or cancellation leaves outdir as it
        was."""
        outdir = _path_arg("outdir", outdir)
        if photon_map is not None and not isinstance(photon_map, bool):
            raise ArgumentError("photon_map: expected True or False (whether to write the "
                                f"run's own photon map) or None, got {photon_map!r}")
        opt = _lib.ThzWriteOptions()
        opt.photon_map = int(self.photon_map is not None if photon_map is None
                             else bool(photon_map))
        if opt.photon_map and self.photon_map is None:
            raise ArgumentError("photon_map: the run did not keep its photons "
                                "(simulate(..., keep_photons=True))")
        if ply_max_points is not None:
            opt.ply_max_points = _whole("ply_max_points", ply_max_points, 1, MAX_PHOTONS)
        with self._lock, Call(None, progress) as call:
            status = _lib.lib.thz_run_write(call.ctx, self._owner.ptr, os.fsencode(outdir),
                                            ctypes.byref(opt), call.err)
            self._summary = None
            call.check(status, self.scene.label)

    def __repr__(self):
        return f"<thzmap.Result: sensors {self.sensors}>"


def _run_call(call, fn, scene, photons=None):
    handle = _owned_call(call, fn, scene, _lib.lib.thz_run_destroy, photons)
    return Result(handle, scene, photons)


def simulate(scene, integrator=None, photons=None, seed=None, threads=None,
             target_noise_k=None, max_seconds=None, progress=None, keep_photons=False,
             mpi=False):
    """`thzmap simulate` in memory: the photon phase (none for the path integrator) and
    every sensor rendered. Arguments left None keep the scene's settings. `progress`:
    True for a bar, or a callable given a Progress whose true return value cancels.
    The GIL is released while the engine runs. Raises CancelledError when cancelled,
    KeyboardInterrupt after Ctrl-C; nothing is kept either way. mpi=True in a script
    that mpirun started on several ranks (thzmap.mpi): the ranks share the run, rank 0
    gets the Result, the others None."""
    scene = scene_arg(scene)
    s = _settings(scene, integrator, photons, seed, target_noise_k, max_seconds, keep_photons)
    effective = _effective_integrator(scene, integrator)
    if keep_photons and not _lib.lib.thz_integrator_needs_photons(effective.encode()):
        raise ArgumentError(f"keep_photons: the {effective} integrator fires no photons, so "
                            "there is no photon map to keep; give integrator='photon-map' or "
                            "'final-gather'")
    unused = []  # said, not silently dropped, as `thzmap simulate --photons` says it
    if photons is not None and not _lib.lib.thz_integrator_needs_photons(effective.encode()):
        unused.append(f"photons={photons} is not used: the {effective} integrator fires no "
                      "photons (give integrator='photon-map' or 'final-gather' to fire them)")
    return _shared_run(threads, progress, _world(mpi), scene, s, lambda call: _run_call(
        call, lambda out: _lib.lib.thz_simulate(call.ctx, scene._handle, ctypes.byref(s), out,
                                                call.err), scene), unused)


def render(scene, photon_map=None, integrator=None, sensor=None, seed=None, threads=None,
           target_noise_k=None, max_seconds=None, progress=None, mpi=False):
    """`thzmap render` in memory: every sensor (or only `sensor`, a name or index)
    rendered from `photon_map` (a PhotonMap, or the path of a .thzpm file, which is read
    one channel at a time as the render comes to it: one channel's map in memory). The
    map may have been made for another Scene that differs in its sensors alone (another
    viewpoint: rendered without firing again); one of another geometry, materials or
    channels is refused (thzmap.Error saying which). The path integrator needs no photon
    map (it then uses `seed`).
    mpi=True: shared by the ranks as simulate's; rank 0 alone needs the photon map (it
    sends it to the others), whose `photon_map` may then be None."""
    scene = scene_arg(scene)
    comm = _world(mpi)
    s = _settings(scene, integrator, None, seed, target_noise_k, max_seconds)  # the integrator too
    index = -1 if sensor is None else scene.sensor_index(sensor)
    effective = _effective_integrator(scene, integrator)
    unused = []  # as `thzmap render --photon-map` with the path integrator says it
    if photon_map is not None and not _lib.lib.thz_integrator_needs_photons(effective.encode()):
        unused.append(f"photon_map is not used: the {effective} integrator renders without "
                      "photons (give integrator='photon-map' or 'final-gather' to render "
                      "from it)")

    def run(call):  # rank 0's (or the one process's): the map is its alone
        path, pm = _render_map_arg(scene, photon_map, integrator, seed)
        if path is not None:
            return _run_call(call, lambda out: _lib.lib.thz_render_file(
                call.ctx, scene._handle, os.fsencode(path), index, ctypes.byref(s), out,
                call.err), scene)
        ptr = pm._ptr if pm is not None else None
        return _run_call(call, lambda out: _lib.lib.thz_render_run(
            call.ctx, scene._handle, ptr, index, ctypes.byref(s), out, call.err), scene, pm)

    return _shared_run(threads, progress, comm, scene, s, run, unused)


def _render_map_arg(scene, photon_map, integrator, seed):
    """render's photon_map, checked: (the path of a .thzpm file or None, a PhotonMap or
    None). A PhotonMap made for another Scene object is the library's to check, as a
    file's header is: the same geometry, materials and channels render, others are
    refused saying which differs."""
    path = None
    if isinstance(photon_map, (str, bytes, os.PathLike)):
        path = _path_arg("photon_map", photon_map)
        photon_map = None
    elif photon_map is not None and not isinstance(photon_map, PhotonMap):
        raise ArgumentError(f"photon_map: expected a PhotonMap or a path, got "
                            f"{type(photon_map).__name__}")
    effective = _effective_integrator(scene, integrator)
    if not _lib.lib.thz_integrator_needs_photons(effective.encode()):
        return None, None  # unused (render warns), as `thzmap render` drops it: seed counts
    if photon_map is None and path is None:
        raise ArgumentError(f"photon_map: the {effective} integrator renders from a photon "
                            "map; give one (or integrator='path')")
    if seed is not None and (photon_map is not None or path is not None):
        raise ArgumentError("seed: a render from a photon map uses the map's seed" +
                            (f" ({photon_map.seed})" if photon_map is not None else ""))
    return path, photon_map


def _world(mpi):
    """The MPI job's communicator for mpi=True under an MPI launcher, else None."""
    if not isinstance(mpi, bool):
        raise ArgumentError(f"mpi: expected True or False, got {mpi!r}")
    return _mpi.world() if mpi else None


def _shared_run(threads, progress, comm, scene, settings, run, unused=()):
    """run(call), a Result, on a Call of its own; with comm (thzmap.mpi), shared with the
    other ranks: rank 0 runs it, the others serve it and return None. The arguments
    every rank checks alike are checked before, raising on every rank. `unused`: the
    warnings about arguments the integrator does not use, said first (rank 0)."""
    check_progress(progress)
    if comm is not None and comm.Get_rank() > 0:
        with Call(threads, report_warnings=False) as call:
            _mpi.serve(comm, call, scene=scene, settings=settings)
        return None
    with Call(threads, progress) as call, _mpi.Shared(comm, call) as shared:
        call._stacklevel = 4  # the warnings point past this function and simulate's or render's
        # the scene's own warnings first, as `thzmap simulate|render` prints them: they are
        # in summary["warnings"] too, and a run warning may refer to them ("see the scene
        # warning"); the library says them through thz_scene_warning, not the callback
        call._warnings.extend([*unused, *scene.warnings])
        result = run(call)
        result.mpi_bytes = shared.bytes()
    return result
