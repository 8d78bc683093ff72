"""thzmap.load_sequence and thzmap.batch: a sequence's frames as the library interpolates
them, a batch in memory equal byte for byte to `thzmap batch` (timings aside), resuming,
cancelling, progress, frame warnings named and folded as the program prints them, and
errors with the file and JSON path. thzmap.identify tells a sequence from a scene."""
import json
import os
import shutil
import sys
import types
import warnings

import pytest
from conftest import PLATE, REPO, run_cli

WALKER = os.path.join(REPO, "examples", "walker", "sequence.json")

import thzmap

BATCH = os.path.join(REPO, "tests", "inputs", "batch")
SEQUENCE = os.path.join(BATCH, "sequence.json")  # 5 frames at 4 fps, the person 300 -> 308 K


def test_frames_are_the_keyframes_interpolated():
    seq = thzmap.load_sequence(SEQUENCE)
    assert (len(seq), seq.n_sweeps, seq.frames_per_sweep) == (5, 1, 5)
    assert [f.dir for f in seq.frames] == [f"frame-{i:05d}" for i in range(5)]
    assert [f.time_s for f in seq.frames] == [0.0, 0.25, 0.5, 0.75, 1.0]
    assert seq.frame(-1) == seq.frame(4) and seq.frame(-5) == seq.frame(0)
    # linear between t = 0 s (300 K, x = -0.5 m) and t = 1 s (308 K, x = 0.5 m)
    for i, (t_k, x_m) in enumerate([(300, -0.5), (302, -0.25), (304, 0), (306, 0.25),
                                    (308, 0.5)]):
        person = seq.frame_dict(i)["objects"][1]
        assert person["temperature_k"] == pytest.approx(t_k, abs=1e-12)
        assert person["transform"]["translate_m"][0] == pytest.approx(x_m, abs=1e-12)
    scene = seq.frame_scene(2)
    assert [o.temperature_k for o in scene.objects] == [293, 304]
    assert scene.warnings == []
    # each frame's inputs hashed apart
    assert len({f.hash for f in seq.frames}) == 5
    with pytest.raises(thzmap.ArgumentError, match="has 5 frames"):
        seq.frame(5)


def test_hash_covers_the_scene_directory(tmp_path):
    """The same sequence and scene text in two directories: other inputs (the hash covers
    the scene's directory, scene-format.md "Resuming"), the same directory however its
    path is spelled: the same."""
    for d in ("a", "b"):
        (tmp_path / d).mkdir()
        shutil.copy(SEQUENCE, tmp_path / d / "sequence.json")
        shutil.copy(os.path.join(BATCH, "scene.json"), tmp_path / d / "scene.json")
    a, b, a2 = (thzmap.load_sequence(str(p)) for p in (
        tmp_path / "a" / "sequence.json", tmp_path / "b" / "sequence.json",
        tmp_path / "b" / ".." / "a" / "sequence.json"))
    assert a.frame_json(0) == b.frame_json(0)
    assert all(x.hash != y.hash for x, y in zip(a.frames, b.frames))
    assert [x.hash for x in a.frames] == [x.hash for x in a2.frames]


def test_hash_covers_every_named_file(tmp_path):
    """A finished frame is done only while every file its scene names is as it was: a
    mesh ("file" of an object in the list "objects") and a channel's response_file (a
    "*_file" key); each file changed, every frame's hash changes (scene-format.md
    "Resuming": else the batch keeps frames made from the old file)."""
    with open(os.path.join(BATCH, "scene.json")) as f:
        scene = json.load(f)
    scene["channels"][0] = {"name": "r", "response_file": "r.csv"}
    scene["objects"].append({"name": "tetra", "type": "solid", "material": "wall",
                             "temperature_k": 290, "shape": {"type": "mesh",
                                                             "file": "tetra.obj"}})
    (tmp_path / "scene.json").write_text(json.dumps(scene))
    shutil.copy(SEQUENCE, tmp_path / "sequence.json")
    shutil.copy(os.path.join(REPO, "tests", "inputs", "meshes", "tetra.obj"), tmp_path)
    (tmp_path / "r.csv").write_text("frequency_thz,weight\n0.29,1\n0.31,1\n")

    def hashes():
        return [f.hash for f in thzmap.load_sequence(str(tmp_path / "sequence.json")).frames]

    before = hashes()
    assert hashes() == before
    (tmp_path / "r.csv").write_text("frequency_thz,weight\n0.29,1\n0.31,0.5\n")
    after_response = hashes()
    assert all(a != b for a, b in zip(before, after_response))
    obj = (tmp_path / "tetra.obj").read_text()
    (tmp_path / "tetra.obj").write_text(obj.replace("v 0 0 1\n", "v 0 0 1.5\n"))  # taller
    assert all(a != b for a, b in zip(after_response, hashes()))


def test_whole_number_keyframes_stay_whole(tmp_path):
    """A seed keyed from 1 to 7 over seven frames is 1, 2, ..., 7: 1 + (7 - 1) 4/6 came out
    4.999999999999999 and the frame was refused as no whole number (scene-format.md
    gives this as the way to draw a sensor's noise afresh in each frame)."""
    shutil.copy(os.path.join(BATCH, "scene.json"), tmp_path / "scene.json")
    seq = {"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 7,
           "keyframes": [{"time_s": 0, "sensors": {"cam": {"noise_seed": 1}}},
                         {"time_s": 6, "sensors": {"cam": {"noise_seed": 7}}}]}
    (tmp_path / "seq.json").write_text(json.dumps(seq))
    s = thzmap.load_sequence(str(tmp_path / "seq.json"))
    seeds = [s.frame_dict(i)["sensors"][0]["noise_seed"] for i in range(7)]
    assert seeds == [1, 2, 3, 4, 5, 6, 7] and all(type(x) is int for x in seeds), seeds
    # whole numbers at the keyframes, a fraction between them: the fraction, not the whole
    # number below it (300 -> 301 K over four frames' time is 300.25 K a frame later)
    seq["frames"], seq["keyframes"] = 5, [
        {"time_s": 0, "objects": {"person": {"temperature_k": 300}}},
        {"time_s": 4, "objects": {"person": {"temperature_k": 301}}}]
    (tmp_path / "seq.json").write_text(json.dumps(seq))
    s = thzmap.load_sequence(str(tmp_path / "seq.json"))
    temps = [s.frame_dict(i)["objects"][1]["temperature_k"] for i in range(5)]
    assert temps == [300, 300.25, 300.5, 300.75, 301], temps
    # and a seed that falls on a fraction is refused, named where the later keyframe sets
    # it (scene-format.md: keyed from 1 to N over N frames, not 1 to 2 over 3)
    seq["frames"], seq["keyframes"] = 3, [
        {"time_s": 0, "sensors": {"cam": {"noise_seed": 1}}},
        {"time_s": 2, "sensors": {"cam": {"noise_seed": 2}}}]
    (tmp_path / "seq.json").write_text(json.dumps(seq))
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_sequence(str(tmp_path / "seq.json"))
    assert e.value.path == "keyframes[1].sensors.cam.noise_seed", e.value
    assert "frame-00001" in e.value.reason, e.value


def _tree(outdir):
    """Every file under outdir (the lock aside) with its bytes; batch.json and the
    frames' summary.json without their timings."""
    out = {}
    for d, _, files in os.walk(outdir):
        for name in files:
            if name == ".thzmap-batch-lock":
                continue
            path = os.path.join(d, name)
            with open(path, "rb") as f:
                data = f.read()
            if name in ("batch.json", "summary.json"):
                data = _without_timings(json.loads(data))
            out[os.path.relpath(path, outdir)] = data
    return out


def _without_timings(value):
    if isinstance(value, dict):
        return {k: _without_timings(v) for k, v in value.items()
                if "seconds" not in k and not k.endswith("_s") or k == "time_s"}
    if isinstance(value, list):
        return [_without_timings(v) for v in value]
    return value


def test_batch_equals_the_command(tmp_path, thzmap_binary):
    run_cli(thzmap_binary, "batch", SEQUENCE, "-o", tmp_path / "cli", "--quiet",
            "--threads", "2")
    result = thzmap.batch(SEQUENCE, tmp_path / "py", threads=2)
    assert (result.n_frames, result.computed, result.reused, result.movies) == (5, 5, 0, 2)
    assert result.summary["frames_computed"] == 5 and result.summary["complete"] is True
    cli, py = _tree(tmp_path / "cli"), _tree(tmp_path / "py")
    assert sorted(cli) == sorted(py)
    assert "cam.band-01.mp4" in py and "frame-00004/cam.brightness_temperature.img" in py
    differ = [name for name in cli if cli[name] != py[name]]
    assert differ == [], f"files that differ from thzmap batch's: {differ}"


def test_batch_resumes_reports_and_cancels(tmp_path):
    seq = thzmap.load_sequence(SEQUENCE)
    out = tmp_path / "out"

    def stop_in_frame_2(p):
        return p.stage == "run" and p.frame == 2

    with pytest.raises(thzmap.CancelledError):
        thzmap.batch(seq, out, progress=stop_in_frame_2, movies=False)
    finished = sorted(d for d in os.listdir(out) if d.startswith("frame-"))
    assert finished == ["frame-00000", "frame-00001"]  # finished frames stay, no staging

    reports = []
    result = thzmap.batch(seq, out, progress=reports.append, movies=False)
    assert (result.computed, result.reused, result.movies) == (3, 2, 0)
    # every frame done, but no movie made: not complete (scene-format.md; it said
    # complete once a helper's mutant ignored the movies, and every test passed)
    assert result.summary["frames_done"] == 5 and result.summary["complete"] is False
    # the frames to run checked against the memory first (2, 3, 4: one photon group each
    # or one for all, as they share), then run
    stages = [p.stage for p in reports]
    assert stages[0] == "check" and "frame" in stages and reports[-1].stage == "done"
    assert "check" not in stages[stages.index("frame"):]
    assert reports[-1].frame == 5 and reports[-1].fraction == 1.0
    assert (reports[-1].computed, reports[-1].reused) == (3, 2)  # as the result's
    fractions = [p.fraction for p in reports]
    assert fractions == sorted(fractions) and fractions[0] < 1.0
    assert {p.frame for p in reports if p.stage == "run"} == {2, 3, 4}

    # an exception in the callback cancels, and is raised again after the call
    shutil.rmtree(out)

    def boom(p):
        raise RuntimeError("from the callback")

    with pytest.raises(RuntimeError, match="from the callback"):
        thzmap.batch(seq, out, progress=boom)


def test_batch_failed_frame(tmp_path):
    """A frame that fails stops the batch: batch.json marks it failed, the frames before it
    done and those after it pending, and counts only the done ones (scene-format.md)."""
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "frame-00001").write_text("")  # no directory can go there
    with pytest.raises(thzmap.Error, match="frame-00001: .*not a directory"):
        thzmap.batch(SEQUENCE, tmp_path / "out", movies=False)
    with open(tmp_path / "out" / "batch.json") as f:
        b = json.load(f)
    assert [f["status"] for f in b["frames"]] == ["done", "failed"] + ["pending"] * 3, b
    assert b["frames_done"] == 1 and b["frames_computed"] == 1 and not b["complete"], b


def test_batch_sweep_values_are_json_values(tmp_path):
    # batch.json's sweeps[].values (and frame.json's sweep_values) were one display string
    # with 17-digit numbers, "materials.skin.reflectivity = 0.10000000000000001"
    shutil.copy(os.path.join(BATCH, "scene.json"), tmp_path / "scene.json")
    (tmp_path / "sweep.json").write_text(json.dumps(
        {"format": "thzmap-sequence/1", "scene": "scene.json",
         "sweep": {"materials.skin.reflectivity": [0.1, 0.3], "render.integrator": ["path"]}}))
    seq = thzmap.load_sequence(tmp_path / "sweep.json")
    assert [(f.sweep, f.index, f.dir) for f in seq.frames] == [
        (0, 0, "sweep-00/frame-00000"), (1, 0, "sweep-01/frame-00000")]
    res = thzmap.batch(seq, tmp_path / "out", movies=False)
    assert res.summary["sweeps"] == [
        {"dir": f"sweep-0{i}", "values": {"materials.skin.reflectivity": r,
                                          "render.integrator": "path"},
         "label": f'materials.skin.reflectivity = {r}, render.integrator = "path"'}
        for i, r in enumerate((0.1, 0.3))]
    with open(tmp_path / "out" / "sweep-01" / "frame-00000" / "frame.json") as f:
        assert json.load(f)["sweep_values"] == res.summary["sweeps"][1]["values"]


def _moving_camera_batch(tmp_path, positions, background_k=None, sweep=None,
                         cameras=("cam",)):
    """The plate in its box (8 x 6 pixels, 1 path), its camera at y = positions' (t, y)
    (cameras: copies of it by those names, the k-th at y - 4 k m), 3 frames at 1 fps, run
    by thzmap.batch without movies: (the warnings caught, the RunWarnings' texts)."""
    shutil.copytree(PLATE, tmp_path / "plate")
    with open(tmp_path / "plate" / "scene.json") as f:
        scene = json.load(f)
    if background_k is not None:
        scene["atmosphere"]["background_temperature_k"] = background_k
    scene["sensors"][0]["resolution"] = [8, 6]
    scene["sensors"] = [dict(scene["sensors"][0], name=name) for name in cameras]
    scene["render"] = {"integrator": "path", "paths_per_sample": 1}
    with open(tmp_path / "plate" / "scene.json", "w") as f:
        json.dump(scene, f)
    seq = {"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 3,
           "keyframes": [{"time_s": t,
                          "sensors": {name: {"position_m": [0, y - 4 * k, 0.4]}
                                      for k, name in enumerate(cameras)}}
                         for t, y in positions]}
    if sweep:
        seq["sweep"] = sweep
    with open(tmp_path / "plate" / "sequence.json", "w") as f:
        json.dump(seq, f)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        thzmap.batch(tmp_path / "plate" / "sequence.json", tmp_path / "out", movies=False)
    return caught, [str(w.message) for w in caught if issubclass(w.category, thzmap.RunWarning)]


def test_batch_warnings_name_their_frame_once(tmp_path):
    # As test_validate.sh's sequence: the plate in its box with a background given (a
    # warning while the camera is in the room: the first frame of each sweep value), the
    # camera leaving the room at t = 1 s (frames 2 and 3 of each: a scene warning and a
    # run warning), swept over two temperatures of the target: 6 frames
    caught, texts = _moving_camera_batch(tmp_path, ((0, -0.45), (1, -3)), background_k=3,
                                         sweep={"objects.target.temperature_k": [300, 320]})
    background = [t for t in texts if "background_temperature_k is given" in t]
    outside = [t for t in texts if "is outside the enclosure" in t]
    back_side = [t for t in texts if "saw the back side" in t]
    # one path a sample in one pass (for speed): its standard errors are not estimated
    unestimated = [t for t in texts if "standard errors are not estimated" in t]
    assert len(texts) == 8 and len(background) == len(outside) == len(back_side) == 2, texts
    assert unestimated[0].startswith("sweep-00/frame-00000: the standard errors")
    assert unestimated[1].startswith("the same in 5 later frames: the standard errors")
    assert background[0].startswith(
        "sweep-00/frame-00000: atmosphere.background_temperature_k")
    assert background[1].startswith("the same in 1 later frame: atmosphere.background")
    assert outside[0].startswith(
        'sweep-00/frame-00001: sensor "cam" at [0, -3, 0.4] m is outside')
    assert outside[1].startswith('the same in 3 later frames: sensor "cam" at')
    assert back_side[0].startswith("sweep-00/frame-00001: sensor 'cam': ")
    assert back_side[1].startswith("the same in 3 later frames: sensor 'cam': ")
    # each points at the caller of batch, as simulate's do, not into the package
    assert {w.filename for w in caught if issubclass(w.category, thzmap.RunWarning)} == \
        {__file__}


def test_batch_warnings_alike_but_for_numbers(tmp_path):
    """A camera moving outside the room warns in every frame with its own position: the
    first frame's warning in full, the later ones counted, as thzmap batch does."""
    _, texts = _moving_camera_batch(tmp_path, ((0, -3), (2, -5)))
    outside = [t for t in texts if "is outside the enclosure" in t]
    assert len(outside) == 2, texts
    assert outside[0].startswith('frame-00000: sensor "cam" at [0, -3, 0.4] m is outside')
    assert outside[1].startswith(
        "the same but for its numbers in 2 later frames (each frame's summary.json has its "
        'own): sensor "cam" at [0, -3, 0.4] m is outside')


def test_batch_warnings_alike_but_for_names_apart(tmp_path):
    """Two cameras, cam1 and cam2, moving outside the room: their warnings differ in the
    digit of their names, which is no number (as thzmap validate's sequence in
    test_validate.sh), so each is printed and counted on its own."""
    _, texts = _moving_camera_batch(tmp_path, ((0, -3), (2, -5)), cameras=("cam1", "cam2"))
    outside = [t for t in texts if "is outside the enclosure" in t]
    assert len(outside) == 4, texts
    assert outside[0].startswith('frame-00000: sensor "cam1" at [0, -3, 0.4] m is outside')
    assert outside[1].startswith('frame-00000: sensor "cam2" at [0, -7, 0.4] m is outside')
    kept = "the same but for its numbers in 2 later frames (each frame's summary.json has its own)"
    assert outside[2].startswith(f'{kept}: sensor "cam1" at [0, -3, 0.4] m')
    assert outside[3].startswith(f'{kept}: sensor "cam2" at [0, -7, 0.4] m')


def test_warning_numbers_are_free_standing():
    # the rule src/cli/frame_warnings.c's frame_warning_shape follows: a name's digits stay,
    # and so does an index (objects[3] and objects[4] name two objects: the warning of one
    # was counted with the other's and never printed); a list's numbers are numbers
    shape = thzmap.sequence._NUMBER.sub(
        "#", 'sensor "ch2" (x86_64, h2o): 0.4 m, 1e-3 K, -2.5E+2 s, 3 passes, [0, -7]')
    assert shape == 'sensor "ch2" (x86_64, h2o): # m, # K, -# s, # passes, [#, -#]'
    shape = thzmap.sequence._NUMBER.sub(
        "#", "s.json: objects[3].shape, sensors[12].aperture_m2: 0.05 m^2, [2], [0.5], [7, 1]")
    assert shape == "s.json: objects[3].shape, sensors[12].aperture_m2: # m^#, [2], [#], [#, #]"


def test_warning_counted_once_a_frame():
    # as src/cli/frame_warnings.c counts (tests/unit/test_frame_warnings.c): frame 1, the
    # batch's own (no frame), frame 1 again is one later frame and one repeat of no frame
    seen = thzmap.sequence._SeenWarning(0, "disk nearly full")
    for frame in (1, 1, None, 1, 2):
        seen.count(frame, True)
    assert (seen.repeats, seen.alike) == (3, 0)
    seen.count(3, False)
    seen.count(3, True)
    assert (seen.repeats, seen.alike) == (3, 1)
    # within one frame, messages alike but for their numbers are each new; a later
    # frame's is folded; with no frame, only the same to the letter is
    call = thzmap.sequence._BatchCall(None, None)
    call.frame = 0
    assert call._first("noise 0.12 K") and call._first("noise 0.25 K")
    call.frame = 1
    assert not call._first("noise 0.3 K") and call._first("sensor cam2 at 3 m")
    call.frame = None
    assert call._first("movie 3 s") and call._first("movie 4 s")
    assert not call._first("movie 4 s")


def test_batch_movie_warning_names_no_frame(tmp_path):
    # scenes with other sensors: no movies, and the warning saying why belongs to the
    # batch, not to its last frame (as `thzmap batch` prints it)
    shutil.copytree(PLATE, tmp_path / "plate")
    with open(tmp_path / "plate" / "scene.json") as f:
        scene = json.load(f)
    scene["sensors"][0]["resolution"] = [8, 6]
    scene["render"] = {"integrator": "path", "paths_per_sample": 1}
    with open(tmp_path / "plate" / "a.json", "w") as f:
        json.dump(scene, f)
    scene["sensors"][0]["resolution"] = [4, 3]
    with open(tmp_path / "plate" / "b.json", "w") as f:
        json.dump(scene, f)
    with open(tmp_path / "plate" / "mixed.json", "w") as f:
        json.dump({"format": "thzmap-sequence/1", "scenes": ["a.json", "b.json"]}, f)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        thzmap.batch(tmp_path / "plate" / "mixed.json", tmp_path / "out")
    texts = [str(w.message) for w in caught if issubclass(w.category, thzmap.RunWarning)]
    movie = [t for t in texts if "no movies" in t]
    assert movie and movie[0].startswith("no movies: frame frame-00001 has other sensors"), \
        texts
    # the same sensors, another channel centre: no movies either (a band's movie would
    # show two bands' frames on one colour scale), and batch.json says which channel
    scene["sensors"][0]["resolution"] = [8, 6]
    scene["channels"][0]["frequency_thz"] = 0.4
    with open(tmp_path / "plate" / "b.json", "w") as f:
        json.dump(scene, f)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        thzmap.batch(tmp_path / "plate" / "mixed.json", tmp_path / "out2")
    with open(tmp_path / "out2" / "batch.json") as f:
        b = json.load(f)
    assert b["movies"] == [] and b["complete"], b
    assert "its channel 1 is at 0.4 THz, frame 0's at 0.35 THz" in b["movies_skipped"], b


def test_errors(tmp_path):
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_sequence(os.path.join(BATCH, "scene.json"))
    assert e.value.path == "format" and "a scene file" in e.value.reason
    shutil.copy(os.path.join(BATCH, "scene.json"), tmp_path / "scene.json")
    bad = {"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 4, "frames": 2,
           "keyframes": [{"time_s": 0, "objects": {"nobody": {"temperature_k": 300}}}]}
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_sequence(tmp_path / "bad.json")
    assert e.value.file == str(tmp_path / "bad.json")
    assert e.value.path == "keyframes[0].objects.nobody", e.value
    # a bad value a keyframe set: its path in the sequence file (it was the scene's,
    # "sensors[0].fov", which the scene file does not have)
    bad["keyframes"] = [{"time_s": 0, "sensors": {"cam": {"fov": 30}}}]
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_sequence(tmp_path / "bad.json")
    assert e.value.file == str(tmp_path / "bad.json")
    assert e.value.path == "keyframes[0].sensors.cam.fov", e.value
    assert e.value.reason.startswith("unknown key") and \
        "(the scene scene.json's sensors[0].fov, frame-00000, t = 0 s)" in e.value.reason
    with pytest.raises(thzmap.Error, match="cannot"):
        thzmap.load_sequence(tmp_path / "missing.json")
    # a sweep key checked against every listed scene, not the first alone: the second
    # lacks the object (it was "out of memory", from setting a value where none could go)
    empty = json.loads((tmp_path / "scene.json").read_text())
    empty["objects"] = empty["objects"][:1]
    (tmp_path / "empty.json").write_text(json.dumps(empty))
    bad = {"format": "thzmap-sequence/1", "scenes": ["scene.json", "empty.json"],
           "sweep": {"objects.person.temperature_k": [300, 310]}}
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_sequence(tmp_path / "bad.json")
    assert e.value.path == "sweep.objects.person.temperature_k", e.value
    assert 'scenes[1] (empty.json) has no object named "person"' in e.value.reason, e.value
    # a bad sweep value named by its own index, with a key varying faster after it
    # (sweep-02 is its second value with the seed's first)
    bad = {"format": "thzmap-sequence/1", "scene": "scene.json",
           "sweep": {"objects.person.temperature_k": [300, -1], "photons.seed": [1, 2]}}
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.load_sequence(tmp_path / "bad.json")
    assert e.value.path == "sweep.objects.person.temperature_k[1]", e.value
    assert "sweep-02/frame-00000" in e.value.reason, e.value
    # at most 10 000 combinations of sweep values: 10 000 itself is accepted, and 11 frames
    # of each are then refused as more than the 100 000 frames a sequence may have
    bad = {"format": "thzmap-sequence/1", "scene": "scene.json", "frames": 11,
           "sweep": {"objects.person.temperature_k": list(range(300, 400)),
                     "photons.seed": list(range(100))}}
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(thzmap.SceneError, match="11 frames per sweep value x 10000 sweep "
                                                "values = 110000 frames, more than the 100000"):
        thzmap.load_sequence(tmp_path / "bad.json")
    bad["sweep"]["photons.seed"].append(100)
    (tmp_path / "bad.json").write_text(json.dumps(bad))
    with pytest.raises(thzmap.SceneError, match="more than 10000 combinations"):
        thzmap.load_sequence(tmp_path / "bad.json")
    # the least rate, 1e-9 frames per second, is accepted (a frame in 31.7 years)
    slow = {"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1e-9, "frames": 2}
    (tmp_path / "slow.json").write_text(json.dumps(slow))
    times = [f.time_s for f in thzmap.load_sequence(tmp_path / "slow.json").frames]
    assert times == pytest.approx([0, 1e9], rel=1e-12), times
    with pytest.raises(thzmap.ArgumentError, match="sequence: expected"):
        thzmap.batch(42, tmp_path / "out")
    with pytest.raises(thzmap.ArgumentError, match="movies"):
        thzmap.batch(SEQUENCE, tmp_path / "out", movies="no")
    (tmp_path / "file").write_text("")
    with pytest.raises(thzmap.Error) as e:
        thzmap.batch(SEQUENCE, tmp_path / "file", movies=False)
    assert e.value.status == "bad input" and "not a directory" in e.value.message


def test_identify_tells_the_files_apart(tmp_path):
    assert thzmap.identify(SEQUENCE) == "sequence"
    assert thzmap.identify(os.path.join(BATCH, "scene.json")) == "scene"
    scene = thzmap.load_scene(os.path.join(BATCH, "scene.json"))
    thzmap.fire_photons(scene, integrator="photon-map", photons=100, seed=1).save(
        tmp_path / "map.thzpm")
    assert thzmap.identify(tmp_path / "map.thzpm") == "photon-map"
    (tmp_path / "other.json").write_text('{"format": "thzmap-batch/1"}')
    assert thzmap.identify(tmp_path / "other.json") == "other"
    with pytest.raises(thzmap.Error, match="is a directory"):
        thzmap.identify(tmp_path)


def test_load_sequence_progress_and_cancel():
    """load_sequence reports its frames' check and a true return cancels it (it took no
    context: no progress, and Ctrl-C waited for the whole load)."""
    seen = []
    seq = thzmap.load_sequence(WALKER, progress=seen.append)
    assert len(seq) == 25
    assert seen and {p.stage for p in seen} == {"frames"}, seen
    assert seen[-1].done == seen[-1].total == 25, seen[-1]
    with pytest.raises(thzmap.CancelledError):
        thzmap.load_sequence(WALKER, progress=lambda p: True)
    with pytest.raises(thzmap.ArgumentError):
        thzmap.load_sequence(WALKER, progress=3)


def test_batch_bar_says_what_it_counts(monkeypatch):
    """progress=True with tqdm: the bar's counts say computed and already done, as thzmap
    batch's lines do (it said "1 done, 3 reused": done meant computed only there)."""
    from thzmap.sequence import BatchProgress, _BatchBar
    postfix = []

    class FakeBar:
        def __init__(self, total, **kw):
            self.n = 0

        def set_postfix_str(self, text, refresh=True):
            postfix.append(text)

        def refresh(self):
            pass

        def close(self):
            pass
    monkeypatch.setitem(sys.modules, "tqdm", types.SimpleNamespace(tqdm=FakeBar))
    bar = _BatchBar()
    bar(BatchProgress("frame", 4, 5, 1, 3, 0.8, 0.1))
    bar.close()
    assert postfix == ["1 computed, 3 already done"]


def test_batch_lines_without_tqdm(monkeypatch, capsys):
    """progress=True without tqdm: a line per frame (counted from 1) and at the end, with
    the share of the batch done in per cent."""
    from thzmap.sequence import BatchProgress, _BatchBar
    monkeypatch.setitem(sys.modules, "tqdm", None)
    bar = _BatchBar()
    bar(BatchProgress("frame", 0, 4, 0, 0, 0.0, 0.0))
    bar(BatchProgress("frame", 1, 4, 1, 0, 0.25, 1.5))
    bar(BatchProgress("done", 4, 4, 4, 0, 1.0, 6.0))
    assert capsys.readouterr().err.splitlines() == [
        "thzmap: batch: frame 1/4, 0 % of the batch, 0.0 s",
        "thzmap: batch: frame 2/4, 25 % of the batch, 1.5 s",
        "thzmap: batch: done, 100 % of the batch, 6.0 s"]
