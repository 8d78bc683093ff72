"""Errors: a bad scene raises SceneError naming the file and the JSON path (or line and
column); wrong arguments raise ArgumentError before the library is called; nothing here
may crash the interpreter."""
import json
import math
import os
import shutil
import threading
import warnings

import numpy as np
import pytest
import thzmap
from conftest import PLATE, tiny_scene_dict


def test_bad_dict_names_the_json_path(tiny_dir):
    d = tiny_scene_dict()
    d["channels"][1]["frequency_thz"] = -0.3
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.scene_from_dict(d, base_dir=tiny_dir)
    assert e.value.file == "<dict>"
    assert e.value.path == "channels[1].frequency_thz"
    assert "expected a number in (0, 10000], got -0.3" in e.value.reason
    assert isinstance(e.value, thzmap.Error)


@pytest.mark.parametrize("edit, path", [
    (lambda d: d["objects"][2].__setitem__("temperature_k", "hot"), "objects[2].temperature_k"),
    (lambda d: d["materials"]["wall"].__setitem__("reflectivity", 1.5),
     "materials.wall.reflectivity"),
    (lambda d: d.__setitem__("photon", {}), "photon"),
    (lambda d: d["sensors"][0].__setitem__("fov_deg", math.nan), "sensors[0].fov_deg"),
    (lambda d: d["sensors"][0].__setitem__("fov_deg", np.float32(np.inf)),
     "sensors[0].fov_deg"),
    (lambda d: d["objects"][0]["shape"].__setitem__("size_m", object()),
     "objects[0].shape.size_m"),
])
def test_bad_values_name_their_path(tiny_dir, edit, path):
    d = tiny_scene_dict()
    edit(d)
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.scene_from_dict(d, base_dir=tiny_dir, label="mine")
    assert e.value.path == path
    assert e.value.file == "mine"
    assert str(e.value).startswith("mine: " + path + ": ")


@pytest.mark.parametrize("psf, key", [
    ({"psf": "gaussian", "psf_fwhm_deg": 120}, "psf_fwhm_deg"),
    ({"psf": "airy", "aperture_diameter_m": 1e-5, "aperture_m2": 7e-11}, "aperture_diameter_m"),
])
def test_a_psf_no_run_could_build_is_refused_at_load(tiny_dir, psf, key):
    """simulate refuses a PSF too much wider than the image to fold onto it; loading the
    scene says so (it loaded, and simulate raised only later)."""
    d = tiny_scene_dict()
    d["sensors"][0].update(psf, fov_deg=0.01)
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.scene_from_dict(d, base_dir=tiny_dir, label="wide")
    assert e.value.file == "wide"
    assert e.value.path == "sensors[0]." + key
    assert e.value.reason.startswith("the PSF reaches ")
    assert "expected at most 4095 pixels" in e.value.reason


@pytest.mark.parametrize("name", ["foam:v2", "a: b", "a.b"])
def test_a_material_name_with_colons_or_dots_is_one_key_of_the_path(tiny_dir, name):
    d = tiny_scene_dict()
    d["materials"][name] = d["materials"].pop("wall")
    for o in d["objects"]:
        if o["material"] == "wall":
            o["material"] = name
    d["materials"][name]["reflectivity"] = 1.5
    want = "materials." + name + ".reflectivity"
    with pytest.raises(thzmap.SceneError) as e:  # from a dict
        thzmap.scene_from_dict(d, base_dir=tiny_dir)
    assert e.value.path == want and e.value.reason.startswith("expected a number in [0, 1]")
    path = tiny_dir / "colon.json"  # and from a file
    path.write_text(json.dumps(d))
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_scene(path)
    assert e.value.path == want and e.value.reason.startswith("expected a number"), e.value


def test_relative_paths_need_the_base_dir(tmp_path):
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.scene_from_dict(tiny_scene_dict(), base_dir=tmp_path)  # no materials/ there
    assert e.value.path == "materials.table.file"


def test_numpy_values_are_accepted(tiny_dir):
    d = tiny_scene_dict()
    d["sensors"][0]["position_m"] = np.array([0, -0.45, 0.4])
    d["sensors"][0]["resolution"] = [np.int64(20), np.int64(12)]
    scene = thzmap.scene_from_dict(d, base_dir=tiny_dir)
    assert scene.sensors[0].position_m == (0, -0.45, 0.4)


def test_syntax_error_in_a_file_names_line_and_column(tmp_path):
    p = tmp_path / "broken.json"
    p.write_text('{\n  "format": "thzmap-scene/1"\n      "name": "x"\n}\n')
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_scene(p)
    assert e.value.file == str(p)
    assert (e.value.line, e.value.column, e.value.path) == (3, 7, None)  # at "name"


def test_missing_file(tmp_path):
    with pytest.raises(thzmap.Error) as e:
        thzmap.load_scene(tmp_path / "nothing.json")
    assert "nothing.json" in str(e.value)


@pytest.mark.parametrize("kwargs", [
    {"photons": 0}, {"photons": -5}, {"photons": 2.5}, {"photons": 1 << 64}, {"photons": 10**12 + 1},
    {"seed": -1}, {"seed": "1"}, {"seed": 1 << 63}, {"threads": 0}, {"threads": True},
    {"integrator": "magic"}, {"integrator": "path\0"}, {"target_noise_k": math.nan},
    {"target_noise_k": -1}, {"max_seconds": -3}, {"progress": 42}, {"keep_photons": "yes"},
    {"keep_photons": 1},
    {"integrator": "path", "keep_photons": True},  # no map to keep (it gave a run without one)
    {"target_noise_k": 0}, {"target_noise_k": 0.5, "max_seconds": 0}, {"mpi": 1},
    {"mpi": "yes"},
])
def test_bad_arguments_raise_before_the_library(tiny_dir, kwargs):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    with pytest.raises(thzmap.ArgumentError):
        thzmap.simulate(scene, **kwargs)


def test_max_seconds_alone_is_taken_as_the_cli_takes_it(tiny_dict):
    """max_seconds without target_noise_k limits the scene's target, as --max-seconds
    does; where no target applies, a run warning says it is not used. Python refused it
    ('max_seconds limits target_noise_k; give both') even when the scene gave the target,
    where thzmap simulate --max-seconds and the server's max_seconds run."""
    tiny_dict["render"] = {"integrator": "path", "target_noise_k": 5.0}
    scene = thzmap.scene_from_dict(tiny_dict, base_dir=PLATE)
    result = thzmap.simulate(scene, max_seconds=60, seed=1)
    assert result.summary["target_noise_source"] == "scene"
    assert result.summary["target_noise_k"] == 5.0
    # the same scene with a count and no target: one pass, max_seconds unused, said so
    tiny_dict["render"] = {"integrator": "path", "paths_per_sample": 2}
    scene = thzmap.scene_from_dict(tiny_dict, base_dir=PLATE)
    with pytest.warns(thzmap.RunWarning, match="max_seconds 60 s is not used"):
        result = thzmap.simulate(scene, max_seconds=60, seed=1)
    assert result.summary["target_noise_k"] is None


@pytest.mark.parametrize("threads", [4097, 40000, 1 << 20, 1 << 40])
def test_threads_beyond_the_library_limit_are_refused(tiny_dir, threads):
    # The library refuses more than THZ_MAX_THREADS (4096, as the CLI's --threads);
    # OpenMP exits the process or crashes on such counts. The package names the limit.
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    with pytest.raises(thzmap.ArgumentError, match="1 to 4096"):
        thzmap.simulate(scene, integrator="path", threads=threads)
    with pytest.raises(thzmap.ArgumentError, match="1 to 4096"):
        thzmap.fire_photons(scene, photons=500, threads=threads)


def test_numpy_whole_numbers_are_whole_numbers(tiny_dir):
    np = pytest.importorskip("numpy")
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    a = thzmap.simulate(scene, integrator="photon-map", photons=np.int64(500),
                        seed=np.uint32(7), threads=np.int64(1))
    b = thzmap.simulate(scene, integrator="photon-map", photons=500, seed=7, threads=1)
    assert a.summary["seed"] == 7
    assert (a.image(0).radiance == b.image(0).radiance).all()


def test_scene_integers_beyond_64_bits_are_named(tiny_dir):
    import json
    d = json.loads((tiny_dir / "scene.json").read_text())
    d.setdefault("photons", {})["seed"] = 1 << 63
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.scene_from_dict(d, base_dir=tiny_dir)
    assert e.value.path == "photons.seed"


def test_fire_photons_for_path_is_an_argument_error(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    with pytest.raises(thzmap.ArgumentError, match="the path integrator uses no photons"):
        thzmap.fire_photons(scene, integrator="path", photons=500)
    import json
    d = json.loads((tiny_dir / "scene.json").read_text())
    d["render"] = {"integrator": "path"}  # the scene's own
    with pytest.raises(thzmap.ArgumentError, match="the path integrator uses no photons"):
        thzmap.fire_photons(thzmap.scene_from_dict(d, base_dir=tiny_dir), photons=500)


def test_bad_render_arguments(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    pm = thzmap.fire_photons(scene, photons=500)
    # (a map of another Scene object: test_photon_map_reuse.py)
    with pytest.raises(thzmap.ArgumentError, match="no sensor"):
        thzmap.render(scene, pm, sensor="nope")
    with pytest.raises(thzmap.ArgumentError, match="photon map"):
        thzmap.render(scene, None)
    with pytest.raises(thzmap.ArgumentError):
        thzmap.render(scene, 3.0)
    # a path is read a channel at a time by the library, which names the missing file
    with pytest.raises(thzmap.Error, match="none.thzpm"):
        thzmap.render(scene, tiny_dir / "none.thzpm")
    with pytest.raises(thzmap.ArgumentError, match="map's seed"):
        thzmap.render(scene, tiny_dir / "none.thzpm", seed=3)
    with pytest.raises(thzmap.ArgumentError):
        thzmap.scene_from_dict("not a dict")
    result = thzmap.render(scene, pm)
    with pytest.raises(thzmap.ArgumentError):
        result.image("nope")
    with pytest.raises(thzmap.ArgumentError, match="keep"):
        result.save(tiny_dir / "o", photon_map=True)
    # photon_map says whether to write the run's own map: a map or a path given there
    # (to save "with this map") was read as True and answered 'the run did not keep its
    # photons', or, for a run that kept them, wrote the run's own map in silence
    kept = thzmap.simulate(scene, keep_photons=True)
    for res in (result, kept):
        for bad in (pm, str(tiny_dir / "map.thzpm"), 1):
            with pytest.raises(thzmap.ArgumentError, match="photon_map: expected True or False"):
                res.save(tiny_dir / "o", photon_map=bad)
    assert not (tiny_dir / "o").exists()


def test_a_photon_map_of_another_scene_is_refused(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    path = tiny_dir / "map.thzpm"
    thzmap.fire_photons(scene, photons=500).save(path)
    d = tiny_scene_dict()
    d["objects"][1]["temperature_k"] = 311
    changed = thzmap.scene_from_dict(d, base_dir=tiny_dir)
    with pytest.raises(thzmap.Error):
        thzmap.load_photon_map(changed, path)
    with pytest.raises(thzmap.Error):
        thzmap.load_photon_map(scene, tiny_dir / "scene.json")  # not a photon map


def test_run_warnings_arrive_as_warnings(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    with pytest.warns(thzmap.RunWarning) as caught:
        result = thzmap.simulate(scene, photons=200)
    assert result.summary["warnings"]
    # each warning points at the line that called simulate or render, not at the package
    with pytest.warns(thzmap.RunWarning) as caught_render:
        thzmap.render(scene, thzmap.fire_photons(scene, photons=200))
    assert {w.filename for w in list(caught) + list(caught_render)} == {__file__}


def test_scene_warnings_arrive_from_simulate_and_render(tiny_dict):
    """The scene's warnings arrive as RunWarnings from simulate and render, first, as
    `thzmap simulate|render` prints them, and the RunWarnings are summary["warnings"].
    They used to stay in Scene.warnings alone: a sensor outside its room, or a library
    material used beyond its source's range, went unsaid in Python though bands and batch
    said them."""
    tiny_dict["sensors"][0]["position_m"] = [0, -50, 0.4]
    scene = thzmap.scene_from_dict(tiny_dict, base_dir=PLATE)
    assert len(scene.warnings) == 1 and "outside the enclosure" in scene.warnings[0]
    with pytest.warns(thzmap.RunWarning) as caught:
        result = thzmap.simulate(scene, integrator="path", seed=1)
    said = [str(w.message) for w in caught]
    assert said[0] == scene.warnings[0]
    assert said == result.summary["warnings"]
    with pytest.warns(thzmap.RunWarning) as caught:
        result = thzmap.render(scene, integrator="path")
    assert [str(w.message) for w in caught] == result.summary["warnings"]
    assert str(caught[0].message) == scene.warnings[0]
    assert {w.filename for w in caught} == {__file__}


def test_arguments_the_integrator_does_not_use_are_said(tiny_dir):
    """photons= with the path integrator, and a photon map given to a path render, are
    said (RunWarning), first, as thzmap simulate --photons and render --photon-map say
    them; simulate(scene, photons=1000) with a scene whose integrator is path fired
    nothing and said nothing, which reads as a run of 1000 photons."""
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    with pytest.warns(thzmap.RunWarning) as caught:
        result = thzmap.simulate(scene, integrator="path", photons=1000, seed=1)
    said = [str(w.message) for w in caught]
    assert said[0].startswith("photons=1000 is not used: the path integrator fires no photons")
    assert said[1:] == result.summary["warnings"] and result.totals.photons_fired == 0
    pm = thzmap.fire_photons(scene, photons=300)
    with pytest.warns(thzmap.RunWarning) as caught:
        unused = thzmap.render(scene, pm, integrator="path", seed=3)
    assert str(caught[0].message).startswith("photon_map is not used: the path integrator")
    assert {w.filename for w in caught} == {__file__}
    # the unused map is dropped, as thzmap render drops it: its seed neither refuses the
    # seed given (it did: 'a render from a photon map uses the map's seed') nor stands in
    # for it
    plain = thzmap.render(scene, None, integrator="path", seed=3)
    assert np.array_equal(unused.image("cam").radiance, plain.image("cam").radiance)
    # used: nothing said about them
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        thzmap.simulate(scene, integrator="photon-map", photons=300, seed=1)
        thzmap.render(scene, pm, integrator="photon-map")
    assert not [w for w in caught if "is not used" in str(w.message)]


def _bad_scenes():
    import os
    from conftest import REPO
    with open(os.path.join(REPO, "tests", "inputs", "bad_scenes.tsv")) as f:
        rows = [line.rstrip("\n").split("\t") for line in f if not line.startswith("#")]
    return [(os.path.join(REPO, "tests", "inputs", "bad", name), want)
            for name, _, want in rows]


@pytest.mark.parametrize("path, want", _bad_scenes(),
                         ids=[p.rsplit("/", 1)[1] for p, _ in _bad_scenes()])
def test_every_bad_scene_of_the_cli_tests(path, want):
    """The CLI's corpus of bad scenes: each raises SceneError with the CLI's message,
    naming its file and a JSON path or a line (but for a document that is no object)."""
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_scene(path)
    assert want in str(e.value)
    assert e.value.file == path
    assert (e.value.path is not None or e.value.line is not None
            or path.endswith("not_an_object.json"))
    if e.value.path is not None:
        assert str(e.value) == f"{path}: {e.value.path}: {e.value.reason}"


def test_a_fifo_scene_is_refused_without_waiting_for_a_writer(tmp_path):
    """The loader refuses a FIFO; the package then re-read the file for the error's JSON
    path and waited for a writer that never came."""
    fifo = str(tmp_path / "scene.json")
    os.mkfifo(fifo)
    caught = {}

    def load():
        try:
            thzmap.load_scene(fifo)
        except thzmap.SceneError as e:
            caught["error"] = e

    t = threading.Thread(target=load)
    t.start()
    t.join(30)
    if t.is_alive():
        with open(fifo, "w"):  # the writer it waits for, so that the thread ends
            pass
        t.join()
        pytest.fail("load_scene of a FIFO waited for a writer")
    assert "FIFO" in str(caught["error"])
    assert caught["error"].file == fifo


def test_empty_paths_and_boolean_planes_are_argument_errors(tiny_dir, tmp_path):
    # An empty outdir reached the library ("no output directory given", thzmap.Error);
    # a bool passed as plane 1. Both are the caller's wrong arguments.
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    result = thzmap.simulate(scene, integrator="path", threads=1)
    with pytest.raises(thzmap.ArgumentError, match="empty"):
        result.save("")
    with pytest.raises(thzmap.ArgumentError, match="empty"):
        thzmap.load_scene("")
    with pytest.raises(thzmap.ArgumentError, match="plane"):
        result.image(0).plane(True)


def test_a_data_file_missing_is_no_scene_error(tmp_path, monkeypatch):
    """A valid scene whose library material thzmap's own data directory lacks: an I/O
    error naming the file and THZMAP_DATA_DIR (the installation's fault), not a
    SceneError (bad input)."""
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    data = tmp_path / "data"
    shutil.copytree(os.path.join(repo, "data"), data)
    (data / "materials" / "library.json").unlink()
    monkeypatch.setenv("THZMAP_DATA_DIR", str(data))
    with pytest.raises(thzmap.Error) as e:
        thzmap.load_scene(os.path.join(repo, "examples", "outdoor-concealed", "scene.json"))
    assert not isinstance(e.value, thzmap.SceneError)
    assert e.value.status == "input/output error"
    assert str(data / "materials" / "library.json") in e.value.message
    assert "THZMAP_DATA_DIR" in e.value.message


def test_a_damaged_data_file_is_no_scene_error(tmp_path, monkeypatch):
    """thzmap's own material library damaged: an I/O error that says so (exit 1 in the
    CLI), not bad input in the user's scene."""
    repo = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    data = tmp_path / "data"
    shutil.copytree(os.path.join(repo, "data"), data)
    (data / "materials" / "library.json").write_text('{"format": "thzmap-materials/1", ')
    monkeypatch.setenv("THZMAP_DATA_DIR", str(data))
    with pytest.raises(thzmap.Error) as e:
        thzmap.load_scene(os.path.join(repo, "examples", "outdoor-concealed", "scene.json"))
    assert not isinstance(e.value, thzmap.SceneError)
    assert e.value.status == "input/output error"
    assert "thzmap's own data is damaged" in e.value.message


def test_photons_up_to_the_cli_bound_are_taken(tiny_dir):
    """photons may be 10^12, the CLI's --photons bound itself (the run starts: the path
    integrator's, cancelled at its first report); ply_max_points is 1 to 10^12 as
    --ply-max-points."""
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    with pytest.raises(thzmap.CancelledError):
        thzmap.simulate(scene, integrator="path", photons=10**12, progress=lambda p: True)
    run = thzmap.simulate(scene, integrator="path", seed=1)
    for bad in (0, 10**12 + 1):
        with pytest.raises(thzmap.ArgumentError, match="ply_max_points"):
            run.save(tiny_dir / "out", ply_max_points=bad)


def test_exception_classes():
    """As docs/python.md says: ArgumentError is also a ValueError, OutOfMemoryError a
    MemoryError (a status of out of memory becomes one), every one a thzmap.Error."""
    from thzmap import _lib
    from thzmap.errors import from_status
    assert issubclass(thzmap.ArgumentError, ValueError)
    assert issubclass(thzmap.OutOfMemoryError, MemoryError)
    e = from_status(_lib.ERR_NOMEM, "out of memory")
    assert isinstance(e, thzmap.OutOfMemoryError) and isinstance(e, MemoryError)
    assert e.status == "out of memory"
    e = from_status(_lib.ERR_LIMIT, "the run would need 9 GiB")
    assert type(e) is thzmap.Error and not isinstance(e, MemoryError)
    assert isinstance(from_status(_lib.ERR_CANCELLED, ""), thzmap.CancelledError)


def test_nul_in_a_path_or_label_is_refused(tiny_dir):
    """A NUL would cut the path or label the C library sees (another file, or a shorter
    name in its messages): refused instead."""
    for bad in (str(tiny_dir / "scene.json") + "\0x", b"scene.json\0"):
        with pytest.raises(thzmap.ArgumentError, match="NUL"):
            thzmap.load_scene(bad)
    with pytest.raises(thzmap.ArgumentError, match="NUL"):
        thzmap.scene_from_json(json.dumps(tiny_scene_dict()), base_dir=tiny_dir,
                               label="a\0b")
