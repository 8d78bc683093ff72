"""Scenes: loading one from a file, a dict or JSON text, and reading what it holds."""
import collections
import ctypes
import json
import math
import numbers
import os
import stat
import time

from . import _lib
from .errors import ArgumentError, SceneError, scene_error


def _record(name, struct):
    """A namedtuple type with the fields of a ctypes structure."""
    return collections.namedtuple(name, [f for f, _ in struct._fields_])


Channel = _record("Channel", _lib.ThzChannelInfo)
Spectrum = _record("Spectrum", _lib.ThzSpectrumInfo)
Material = _record("Material", _lib.ThzMaterialInfo)
Object = _record("Object", _lib.ThzObjectInfo)
Sensor = _record("Sensor", _lib.ThzSensorInfo)
SceneInfo = _record("SceneInfo", _lib.ThzSceneInfo)
_SPECTRUM_KINDS = {0: "absent", 1: "constant", 2: "table"}


def _value(v):
    if isinstance(v, bytes):
        return v.decode("utf-8", "replace")
    if isinstance(v, ctypes.Array):
        return tuple(v)
    if isinstance(v, _lib.ThzSpectrumInfo):
        fields = _convert(v)
        fields["kind"] = _SPECTRUM_KINDS.get(fields["kind"], fields["kind"])
        return Spectrum(**fields)
    return v


def _convert(struct):
    return {f: _value(getattr(struct, f)) for f, _ in struct._fields_}


class Scene:
    """A loaded and checked thzmap-scene/1 document (read-only). Made by load_scene,
    scene_from_dict or scene_from_json; results and photon maps keep it alive."""

    def __init__(self, handle, label, seconds_load, file=None):
        # file: (absolute path, mtime in ns, size) of the file load_scene read, else None
        self._file = file
        self._owned = _lib.Handle(handle, _lib.lib.thz_scene_destroy)
        self._handle = handle
        self.label = label
        self.seconds_load = seconds_load
        info = _lib.ThzSceneInfo()
        _lib.lib.thz_scene_get_info(handle, ctypes.byref(info))
        self.info = SceneInfo(**_convert(info))
        self.channels = self._list(_lib.lib.thz_scene_channel, _lib.ThzChannelInfo, Channel,
                                   self.info.n_channels)
        self.materials = self._list(_lib.lib.thz_scene_material, _lib.ThzMaterialInfo,
                                    Material, self.info.n_materials)
        self.objects = self._list(_lib.lib.thz_scene_object, _lib.ThzObjectInfo, Object,
                                  self.info.n_objects)
        self.sensors = self._list(_lib.lib.thz_scene_sensor, _lib.ThzSensorInfo, Sensor,
                                  self.info.n_sensors)
        n = _lib.lib.thz_scene_warning_count(handle)
        self.warnings = [_lib.text(_lib.lib.thz_scene_warning(handle, i)) for i in range(n)]

    def _list(self, fn, struct, record, n):
        out = []
        for i in range(n):
            s = struct()
            fn(self._handle, i, ctypes.byref(s))
            out.append(record(**_convert(s)))
        return out

    @property
    def name(self):
        """The scene's name (its "name", else the file's stem)."""
        return self.info.name

    @property
    def sensor_names(self):
        """The sensors' names, in the scene's order (the index simulate's images use)."""
        return [s.name for s in self.sensors]

    @property
    def object_names(self):
        """The objects' names, in the scene's order (object_id's indices)."""
        return [o.name for o in self.objects]

    def sensor_index(self, sensor):
        """The index of a sensor given by name or index; ArgumentError if there is none."""
        return _index("sensor", sensor, self.sensor_names)

    def object_index(self, obj):
        """The index of an object given by name or index (the value of its pixels in an
        image's object_id); ArgumentError if there is none."""
        return _index("object", obj, self.object_names)

    def __repr__(self):
        return (f"<thzmap.Scene {self.name!r}: {len(self.channels)} channels, "
                f"{len(self.objects)} objects, sensors {self.sensor_names}>")


def _index(kind, key, names):
    """The index of `key` (a name, or an index) among names; ArgumentError naming them."""
    if isinstance(key, numbers.Integral) and not isinstance(key, bool):
        if 0 <= key < len(names):
            return int(key)
    elif isinstance(key, str) and key in names:
        return names.index(key)
    raise ArgumentError(f"{kind}: the scene has no {kind} {key!r} (it has {', '.join(names)})")


def _file_stamp(path):
    """(absolute path, mtime in ns, size) of a scene file, or None if it cannot be read."""
    try:
        st = os.stat(path)
    except OSError:
        return None
    return (os.path.abspath(path), st.st_mtime_ns, st.st_size)


def _document(path=None, text=None):
    """The scene's JSON as a dict (to split a SceneError's path from its reason), or None."""
    try:
        if text is None:
            # Only a regular file of at most 64 MiB (as the loader reads): read() of a FIFO
            # would wait for its writer, and read(1 << 26) would allocate 64 MiB for any
            # file (0.37 s a SceneError under python3 -X dev, whose allocator fills it).
            st = os.stat(path)
            if not stat.S_ISREG(st.st_mode) or st.st_size > 1 << 26:
                return None
            with open(path, encoding="utf-8") as f:
                text = f.read()
        doc = json.loads(text)
    except (OSError, ValueError, TypeError, RecursionError):
        return None
    return doc if isinstance(doc, dict) else None


def _load(loader, label, path=None, text=None):
    stamp = _file_stamp(path) if path is not None else None
    handle = ctypes.c_void_p()
    err = _lib.ThzError()
    start = time.perf_counter()
    status = loader(ctypes.byref(handle), ctypes.byref(err))
    seconds = time.perf_counter() - start
    if status != _lib.OK:
        raise _load_error(status, _lib.text(err.message), label, path, text)
    return Scene(handle.value, label, seconds, stamp)


def _load_error(status, message, label, path=None, text=None):
    """The exception for a failed load of the file at `path` (or of JSON `text`):
    SceneError for bad input, with its JSON path told from the reason by the document."""
    if status == _lib.ERR_INPUT:
        return scene_error(message, label,
                           _document(path, text) if path is not None or text else None)
    from .errors import from_status
    return from_status(status, message)


def _path_arg(name, value):
    if not isinstance(value, (str, bytes, os.PathLike)):
        raise ArgumentError(f"{name}: expected a path, got {value!r}")
    value = os.fsdecode(value)
    if not value:
        raise ArgumentError(f"{name}: expected a path, got an empty one")
    if "\0" in value:
        raise ArgumentError(f"{name}: a path cannot contain a NUL character")
    return value


def _root_arg(root):
    """The library's `root` argument: None, or the directory as bytes."""
    return None if root is None else os.fsencode(_path_arg("root", root))


def load_scene(path, root=None):
    """Loads and checks the scene file at `path`. Raises SceneError (with .file, .path,
    .line, .column) for a bad scene. With `root` (a directory), the scene file and every
    file it names must lie under root once symlinks are resolved (as `thzmap serve
    --root` loads scenes on behalf of others); one that does not is a SceneError at the
    JSON path of the key naming it."""
    path = _path_arg("path", path)
    if root is None:
        return _load(lambda out, err: _lib.lib.thz_scene_load(os.fsencode(path), out, err),
                     path, path)
    r = _root_arg(root)
    return _load(lambda out, err: _lib.lib.thz_scene_load_within(
        os.fsencode(path), r, out, err), path, path)


def scene_arg(scene):
    """A Scene, or the Scene load_scene makes of a path: what every function taking a
    scene accepts."""
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, (str, bytes, os.PathLike)):
        return load_scene(scene)
    raise ArgumentError(f"scene: expected a thzmap.Scene or a path, got {type(scene).__name__}")


def identify(path):
    """What kind of thzmap file `path` is: "scene", "sequence" (for load_sequence),
    "photon-map" (a .thzpm file, for load_photon_map) or "other", from its first bytes or
    its JSON "format"; it does not check the file (the loaders do). Raises Error for a
    path that is not a regular file."""
    path = _path_arg("path", path)
    kind = ctypes.c_int(0)
    err = _lib.ThzError()
    status = _lib.lib.thz_file_identify(os.fsencode(path), ctypes.byref(kind), ctypes.byref(err))
    if status != _lib.OK:
        from .errors import from_status
        raise from_status(status, _lib.text(err.message))
    return _lib.FILE_KINDS[kind.value]


def _check_json_values(value, path, label):
    """Raises SceneError at the first value JSON cannot hold (NaN, infinity, other
    types), naming its JSON path as the library would."""
    def fail(reason):
        where = f"{label}: {path}: " if path else f"{label}: "
        return SceneError(where + reason, file=label, path=path or None, reason=reason)

    if isinstance(value, dict):
        for k, v in value.items():
            if not isinstance(k, str):
                raise fail(f"keys must be strings, got {k!r}")
            _check_json_values(v, f"{path}.{k}" if path else k, label)
    elif isinstance(value, (list, tuple)):
        for i, v in enumerate(value):
            _check_json_values(v, f"{path}[{i}]", label)
    elif hasattr(value, "tolist") and not isinstance(value, (str, bytes)):  # numpy
        _check_json_values(value.tolist(), path, label)
    elif isinstance(value, bool) or value is None or isinstance(value, str):
        pass
    elif isinstance(value, numbers.Integral) and not -(1 << 63) <= value < (1 << 63):
        raise fail(f"expected a whole number from -2^63 to 2^63 - 1 (what a scene file's "
                   f"integers can be), got {value}")
    elif isinstance(value, numbers.Real):
        if not math.isfinite(value):
            raise fail(f"expected a finite number, got {value}")
    else:
        raise fail(f"cannot be written as JSON ({type(value).__name__})")


def _json_default(value):
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return value.tolist()
    if isinstance(value, numbers.Integral):
        return int(value)
    if isinstance(value, numbers.Real):
        return float(value)
    raise TypeError(type(value).__name__)


def scene_from_json(text, base_dir=None, label="<string>", root=None):
    """A scene from JSON text; relative file paths in it are taken against `base_dir`
    (default: the current directory); `label` names it in messages (SceneError.file);
    `root` confines the files it names as load_scene does."""
    if not isinstance(text, str):
        raise ArgumentError(f"text: expected a str, got {type(text).__name__}")
    if not isinstance(label, str) or "\0" in label:
        raise ArgumentError(f"label: expected a str without NUL, got {label!r}")
    if "\0" in text:
        raise ArgumentError("text: JSON text cannot contain a NUL character")
    base = None if base_dir is None else os.fsencode(_path_arg("base_dir", base_dir))
    data = text.encode("utf-8")
    if root is None:
        return _load(lambda out, err: _lib.lib.thz_scene_load_string(
            data, base, label.encode("utf-8"), out, err), label, text=text)
    r = _root_arg(root)
    return _load(lambda out, err: _lib.lib.thz_scene_load_string_within(
        data, base, label.encode("utf-8"), r, out, err), label, text=text)


def scene_from_dict(d, base_dir=None, label="<dict>", root=None):
    """A scene from a dict with the keys of a scene file; relative file paths in it are
    taken against `base_dir` (default: the current directory). Numbers may be numpy
    scalars or arrays. Raises SceneError naming the JSON path of a bad value."""
    if not isinstance(d, dict):
        raise ArgumentError(f"d: expected a dict, got {type(d).__name__}")
    if not isinstance(label, str):
        raise ArgumentError(f"label: expected a str, got {label!r}")
    _check_json_values(d, "", label)
    text = json.dumps(d, default=_json_default, allow_nan=False)
    return scene_from_json(text, base_dir=base_dir, label=label, root=root)
