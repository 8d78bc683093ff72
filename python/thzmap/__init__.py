"""thzmap: simulate a passive multispectral terahertz camera from Python.

    import thzmap
    scene = thzmap.load_scene("examples/teraeye/scene.json")
    result = thzmap.simulate(scene, integrator="photon-map", photons=100_000, seed=1,
                             progress=True)
    image = result.image("cam")
    image.brightness_temperature      # numpy float32 (rows, columns, channels), K
    result.summary["channels"]        # summary.json as a dict
    result.save("out/teraeye")        # the files `thzmap simulate` writes

A binding of libthzmap's C API (include/thzmap/) through ctypes; docs/python.md tells
the whole story (installation, threads, cancellation, memory ownership); installed,
docs/ is PREFIX/share/doc/thzmap/.
"""
from . import _lib, mpi
from ._call import RunWarning
from .band_selection import BandSelection, bands
from .classification import Classification, classify, classify_spectra
from .errors import (ArgumentError, CancelledError, Error, OutOfMemoryError,
                     SceneError)
from .optics import (Atmosphere, MaterialLibrary, atmosphere, brightness_temperature,
                     material_library, planck_radiance, surface_optics)
from .progress import Progress
from .run import (Image, PhotonMap, Result, fire_photons, load_photon_map,
                  merge_photon_maps, render, simulate)
from .scene import Scene, identify, load_scene, scene_from_dict, scene_from_json
from .sequence import BatchProgress, BatchResult, Frame, Sequence, batch, load_sequence

__version__ = _lib.text(_lib.lib.thz_version())
revision = _lib.text(_lib.lib.thz_revision())
"""The source revision of the library this package uses, as summary.json's
thzmap_revision: the git commit (40 hex digits, "-dirty" when the tree differed from
it), or "unknown" (built outside a git checkout)."""
library_path = _lib.path
"""The libthzmap file this package uses."""

__all__ = ["ArgumentError", "Atmosphere", "BandSelection", "BatchProgress", "BatchResult",
           "CancelledError", "Classification", "Error", "Frame", "Image", "MaterialLibrary",
           "OutOfMemoryError", "PhotonMap", "Progress", "Result", "RunWarning", "Scene",
           "SceneError", "Sequence", "atmosphere", "bands", "batch", "brightness_temperature",
           "classify", "classify_spectra", "fire_photons", "identify", "library_path", "load_photon_map",
           "load_scene", "load_sequence", "material_library", "merge_photon_maps", "mpi",
           "planck_radiance", "render", "revision", "scene_from_dict", "scene_from_json",
           "simulate", "surface_optics"]
