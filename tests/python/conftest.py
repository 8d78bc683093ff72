"""Shared fixtures of the Python package's tests.

CTest runs them as `/usr/bin/python3 -m pytest tests/python` with PYTHONPATH at python/,
THZMAP_LIBRARY at the freshly built libthzmap and THZMAP_BINARY at the `thzmap` program
of the same build (see the end of CMakeLists.txt). Run by hand from the repository:
    PYTHONPATH=python /usr/bin/python3 -m pytest tests/python
(the package then finds build/libthzmap.so, and the tests build/thzmap).
"""
import copy
import json
import os
import shutil
import subprocess

import numpy as np
import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLATE = os.path.join(REPO, "examples", "plate-in-box")

# The plate-in-box example made small: two channels, 20 x 12 pixels (not square, so a
# swapped axis shows), few photons, photon-map. It keeps its CSV material ("materials/sample.csv"),
# a relative path that tests base_dir.
with open(os.path.join(PLATE, "scene.json")) as f:
    _TINY = json.load(f)
_TINY["channels"] = [{"name": "0.35 THz", "frequency_thz": 0.35, "relative_width": 0.01},
                     {"name": "0.8 THz", "frequency_thz": 0.8, "relative_width": 0.01}]
_TINY["sensors"][0].update({"resolution": [20, 12], "oversampling": 1})
_TINY["photons"]["per_channel"] = 3000
# the integrator these tests fire photons for (the default, path, fires none)
_TINY["render"] = {"integrator": "photon-map"}

# The quantities of a sensor's ENVI files, and their shape in the Python API.
CUBES = ["radiance", "radiance_stderr", "power", "brightness_temperature", "normalized"]
MAPS = ["temperature", "distance", "object_id"]


def tiny_scene_dict():
    return copy.deepcopy(_TINY)


@pytest.fixture
def tiny_dict():
    return tiny_scene_dict()


@pytest.fixture
def tiny_dir(tmp_path):
    """A directory holding the tiny scene as scene.json with its materials/."""
    shutil.copytree(os.path.join(PLATE, "materials"), tmp_path / "materials")
    with open(tmp_path / "scene.json", "w") as f:
        json.dump(tiny_scene_dict(), f)
    return tmp_path


@pytest.fixture(scope="session")
def thzmap_binary():
    path = os.environ.get("THZMAP_BINARY") or os.path.join(REPO, "build", "thzmap")
    if not os.access(path, os.X_OK):
        pytest.fail(f"no thzmap program at {path} (set THZMAP_BINARY or run make build)")
    return path


def run_cli(binary, *args):
    """Runs the thzmap program; fails the test with its stderr when it fails."""
    p = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
    assert p.returncode == 0, f"thzmap {' '.join(map(str, args))}: {p.stderr}"
    return p


def read_envi(outdir, sensor, quantity, rows, columns):
    """An ENVI image the CLI wrote, as the Python API shapes it: float32 little-endian,
    band-sequential on disk; cubes become (rows, columns, bands), maps (rows, columns)."""
    data = np.fromfile(os.path.join(outdir, f"{sensor}.{quantity}.img"), dtype="<f4")
    bands = data.size // (rows * columns)
    assert bands * rows * columns == data.size
    cube = data.reshape(bands, rows, columns)
    return cube[0] if quantity in MAPS else cube.transpose(1, 2, 0)


def assert_bitwise_equal(a, b, what):
    assert a is not None and b is not None, what
    assert a.shape == b.shape, f"{what}: shape {a.shape} against {b.shape}"
    assert a.dtype == np.float32 and b.dtype == np.float32, what
    # Compare the bits, so that NaNs and signed zeros count too.
    same = np.array_equal(a.view(np.uint32), b.view(np.uint32))
    assert same, f"{what}: {np.count_nonzero(a.view(np.uint32) != b.view(np.uint32))} " \
                 f"values differ"
