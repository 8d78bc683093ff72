"""Memory: simulate in a loop does not grow the process; threads: two runs in two
Python threads give the arrays of sequential runs, and the GIL is free while a run
goes on."""
import ctypes
import gc
import os
import threading
import time
import warnings
import weakref

import numpy as np
import pytest
import thzmap
from conftest import CUBES, MAPS, assert_bitwise_equal, tiny_scene_dict

PAGE = os.sysconf("SC_PAGE_SIZE")


_LIBC = ctypes.CDLL("libc.so.6")


def rss_bytes():
    """Resident memory, after glibc has given free heap pages back to the system (so
    that memory freed by earlier tests and reused here is not counted as growth)."""
    gc.collect()
    _LIBC.malloc_trim(0)
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * PAGE


def sensitive_scene(base_dir):
    """The tiny scene with 64 x 64 pixels: one run's images hold 2 channels x 6 planes
    of 16 kB each (~200 kB), so 100 leaked runs would add ~20 MB."""
    d = tiny_scene_dict()
    d["sensors"][0]["resolution"] = [64, 64]
    d["photons"]["per_channel"] = 1000
    d["render"] = {"paths_per_sample": 1}
    return thzmap.scene_from_dict(d, base_dir=base_dir)


MARGIN = 4 << 20  # bytes: allocator noise; a leak of the images alone is 5 times that


def test_simulate_in_a_loop_does_not_grow(tiny_dir):
    scene = sensitive_scene(tiny_dir)
    for _ in range(10):  # let the allocator and OpenMP reach their steady state
        r = thzmap.simulate(scene, integrator="path", seed=1, threads=2)
        r.image("cam").radiance.sum()
    del r
    gc.collect()
    before = rss_bytes()
    for i in range(100):
        r = thzmap.simulate(scene, integrator="path", seed=i, threads=2)
        assert r.image("cam").radiance.shape == (64, 64, 2)
        r.summary
    del r
    gc.collect()
    grown = rss_bytes() - before
    assert grown < MARGIN, f"the process grew by {grown / 1e6:.1f} MB over 100 runs"


def test_the_measurement_sees_a_leak_of_one_run_per_call(tiny_dir):
    """What the loop above would measure if every run leaked: the test can fail."""
    scene = sensitive_scene(tiny_dir)
    gc.collect()
    before = rss_bytes()
    kept = []
    for i in range(20):
        kept.append(thzmap.simulate(scene, integrator="path", seed=i, threads=2))
        kept[-1].image("cam").radiance.sum()
    per_run = (rss_bytes() - before) / len(kept)
    assert 100 * per_run > 2 * MARGIN, f"a kept run holds only {per_run / 1e3:.0f} kB"


def test_arrays_keep_the_run_alive_and_free_it_with_the_last(tiny_dir):
    scene = sensitive_scene(tiny_dir)
    r = thzmap.simulate(scene, integrator="path", seed=3)
    arr = r.image("cam").brightness_temperature
    expected = np.array(arr)
    owner = weakref.ref(r._owner)
    del r
    gc.collect()
    assert owner() is not None and owner().ptr  # alive through arr
    assert np.array_equal(arr, expected)
    del arr
    gc.collect()
    assert owner() is None  # gone, and with it the run (thz_run_destroy)


def all_planes(result):
    im = result.image("cam")
    return {q: np.array(getattr(im, q)) for q in CUBES + MAPS
            if getattr(im, q) is not None}


def test_two_threads_match_sequential_runs(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    settings = [dict(seed=11), dict(seed=12, integrator="path")]
    sequential = [all_planes(thzmap.simulate(scene, threads=2, **s)) for s in settings]
    parallel = [None, None]
    errors = []

    def work(k):
        try:
            parallel[k] = all_planes(thzmap.simulate(scene, threads=1, **settings[k]))
        except BaseException as e:  # report in the main thread
            errors.append(e)
    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors, errors
    for k in range(2):
        for q in sequential[k]:
            assert_bitwise_equal(parallel[k][q], sequential[k][q], f"run {k} {q}")


def test_the_gil_is_released_during_a_run(tiny_dir):
    """While one thread runs a simulate, the main thread keeps running Python code.
    Were the GIL held during the C call, the main thread could run only while the run
    calls back into Python (its progress reports): about one tick per report. A run too
    short to tell (a fast machine) is repeated with twice the photons."""
    d = tiny_scene_dict()
    photons = 400_000
    for _ in range(4):
        d["photons"]["per_channel"] = photons
        scene = thzmap.scene_from_dict(d, base_dir=tiny_dir)
        reports = []
        done = threading.Event()
        t = threading.Thread(target=lambda: (
            thzmap.simulate(scene, threads=1, progress=reports.append), done.set()))
        start = time.monotonic()
        t.start()
        ticks = 0
        while not done.is_set():
            time.sleep(0.001)
            ticks += 1
        t.join()
        seconds = time.monotonic() - start
        if seconds > 0.3:
            break
        photons *= 2
    assert seconds > 0.3, f"the run was too short to tell ({photons} photons, {seconds:.2f} s)"
    assert ticks > 5 * len(reports) + 20, \
        f"{ticks} ticks of the main thread for {len(reports)} reports in {seconds:.2f} s"


def test_library_objects_refuse_pickle_and_deepcopy(tiny_dir):
    """A Scene, Result, PhotonMap or material library cannot be pickled (as
    multiprocessing does to a sweep's arguments) or deep-copied: a TypeError that says
    what to do instead. ctypes refused with 'ctypes objects containing pointers cannot be
    pickled' and a half-made Handle then failed in __del__ ('Exception ignored'), which
    pytest reports as an error here. A shallow copy shares the handle and works."""
    import copy
    import pickle
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    result = thzmap.simulate(scene, photons=500, keep_photons=True)
    for obj in (scene, result, result.photon_map, thzmap.material_library()):
        with pytest.raises(TypeError, match="cannot be pickled or deep-copied: give another"):
            copy.deepcopy(obj)
        with pytest.raises(TypeError, match="cannot be pickled or deep-copied"):
            pickle.dumps(obj)
    gc.collect()
    assert copy.copy(scene).sensor_names == scene.sensor_names


def test_threads_beyond_the_cpus_to_run_on_are_warned(tiny_dir):
    """threads=2 in a process that may run on one CPU (its affinity, as mpirun binds a
    rank to a core) warns, pointing at the caller, as the thzmap program does; the run
    goes on and gives the bytes of 1 thread. threads=1 does not warn."""
    scene = thzmap.scene_from_dict(tiny_scene_dict(), base_dir=tiny_dir)
    before = os.sched_getaffinity(0)
    os.sched_setaffinity(0, {min(before)})
    try:
        with pytest.warns(RuntimeWarning,
                          match=r"threads=2, but this process may run on only 1 CPU \(") as w:
            two = thzmap.simulate(scene, integrator="photon-map", seed=3, threads=2)
        assert w[0].filename == __file__
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            one = thzmap.simulate(scene, integrator="photon-map", seed=3, threads=1)
    finally:
        os.sched_setaffinity(0, before)
    assert_bitwise_equal(two.image(0).radiance, one.image(0).radiance, "radiance")
