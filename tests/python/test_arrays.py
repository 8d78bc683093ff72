"""The arrays of the Python API equal, bit for bit, the ENVI files `thzmap simulate`
and `thzmap render` write for the same scene and seed; result.save writes the same
files; photon maps save, load and re-render."""
import filecmp
import json
import os
import stat

import numpy as np
import pytest
import thzmap
from conftest import (CUBES, MAPS, REPO, assert_bitwise_equal, read_envi, run_cli,
                      tiny_scene_dict)

SEED = 7


def compare_with_files(result, outdir):
    for sensor in result.sensors:
        im = result.image(sensor)
        for q in CUBES + MAPS:
            if q == "radiance_stderr" and not os.path.exists(
                    os.path.join(outdir, f"{sensor}.{q}.img")):
                assert im.radiance_stderr is None
                continue
            assert_bitwise_equal(getattr(im, q), read_envi(outdir, sensor, q, im.rows,
                                                            im.columns), f"{sensor}.{q}")


@pytest.mark.parametrize("integrator", [None, "path"])
def test_simulate_equals_cli_files(tiny_dir, thzmap_binary, integrator):
    out = tiny_dir / "cli"
    args = ["simulate", tiny_dir / "scene.json", "-o", out, "--seed", SEED, "--threads", 2,
            "--quiet"]
    if integrator:
        args += ["--integrator", integrator]
    run_cli(thzmap_binary, *args)
    # From a dict with a base directory, and with a different thread count.
    scene = thzmap.scene_from_dict(tiny_scene_dict(), base_dir=tiny_dir)
    result = thzmap.simulate(scene, integrator=integrator, seed=SEED, threads=1)
    im = result.image("cam")
    assert im.radiance.shape == (12, 20, 2)
    assert im.object_id.shape == (12, 20)
    compare_with_files(result, out)


def test_arrays_are_views_of_the_library_buffers(tiny_dir):
    result = thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"), seed=SEED)
    im = result.image("cam")
    cube = im.radiance
    assert not cube.flags.writeable
    assert not cube.flags.owndata and cube.base is not None
    # (rows, columns, channels) is a transposed view of the band-sequential plane.
    bsq = im.plane("radiance")
    assert cube.__array_interface__["data"][0] == bsq.__array_interface__["data"][0]
    assert cube.strides == (20 * 4, 4, 12 * 20 * 4)
    # An array outlives the Result and the Scene it came from.
    copy = np.array(cube)
    del result, im, bsq, cube
    import gc
    gc.collect()
    again = thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"), seed=SEED)
    assert np.array_equal(again.image("cam").radiance, copy)


def test_save_writes_the_cli_files(tiny_dir, thzmap_binary):
    cli = tiny_dir / "cli"
    run_cli(thzmap_binary, "simulate", tiny_dir / "scene.json", "-o", cli, "--seed", SEED,
            "--quiet", "--save-photon-map")
    result = thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"), seed=SEED,
                             keep_photons=True)
    py = tiny_dir / "py"
    result.save(py)
    assert sorted(os.listdir(py)) == sorted(os.listdir(cli))
    for name in os.listdir(cli):
        if name != "summary.json":  # it holds timings
            assert filecmp.cmp(cli / name, py / name, shallow=False), name
    with open(cli / "summary.json") as f:
        cli_summary = json.load(f)
    for key in ("seed", "photons_per_channel", "integrator", "channels"):
        if key == "channels":
            strip = [{k: v for k, v in c.items() if not k.endswith("_s")}
                     for c in cli_summary[key]]
            mine = [{k: v for k, v in c.items() if not k.endswith("_s")}
                    for c in result.summary[key]]
            assert strip == mine
        else:
            assert result.summary[key] == cli_summary[key]


def test_photon_map_save_load_render(tiny_dir, thzmap_binary):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    result = thzmap.simulate(scene, seed=SEED, keep_photons=True)
    pm = result.photon_map
    assert pm.n_channels == 2 and pm.seed == SEED and pm.photons_per_channel == 3000
    assert pm.stats[0].fired == 3000
    path = tiny_dir / "map.thzpm"
    pm.save(path)
    # Re-rendering the kept map gives the simulate's images again.
    again = thzmap.render(scene, pm)
    for q in CUBES[:1] + CUBES[2:] + MAPS:
        assert_bitwise_equal(getattr(again.image("cam"), q), getattr(result.image("cam"), q), q)
    # From the file, with the final-gather integrator... compared with `thzmap render`.
    loaded = thzmap.load_photon_map(scene, path)
    # Timings and ray counts are not stored in the file.
    assert [s._replace(seconds=0, rays=0) for s in loaded.stats] == \
        [s._replace(seconds=0, rays=0) for s in pm.stats]
    rendered = thzmap.render(scene, loaded, sensor="cam")
    out = tiny_dir / "render"
    run_cli(thzmap_binary, "render", tiny_dir / "scene.json", "--photon-map", path, "-o", out,
            "--quiet")
    compare_with_files(rendered, out)
    by_path = thzmap.render(scene, str(path))
    assert_bitwise_equal(by_path.image(0).power, rendered.image(0).power, "power")


def test_photon_map_save_replaces_whole(tiny_dir):
    """PhotonMap.save writes beside the file and renames it into place: a save that fails
    (a file-size limit; Python ignores SIGXFSZ, so the write fails with EFBIG) leaves the
    map that was there, whole (it was truncated in place, and then failed to load as
    corrupted); nothing else is left in the directory; a symbolic link is written
    through and the file keeps its mode."""
    import resource
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    pm = thzmap.fire_photons(scene, photons=3000, seed=SEED)
    maps = tiny_dir / "maps"
    maps.mkdir()
    path = maps / "map.thzpm"
    pm.save(path)
    os.chmod(path, 0o640)
    before = path.read_bytes()
    other = thzmap.fire_photons(scene, photons=3000, seed=SEED + 1)
    soft, hard = resource.getrlimit(resource.RLIMIT_FSIZE)
    resource.setrlimit(resource.RLIMIT_FSIZE, (len(before) // 2, hard))
    try:
        with pytest.raises(thzmap.Error, match="cannot write photon map .*maps/map.thzpm: File too large"):
            other.save(path)
    finally:
        resource.setrlimit(resource.RLIMIT_FSIZE, (soft, hard))
    assert path.read_bytes() == before
    assert os.listdir(maps) == ["map.thzpm"]
    os.symlink("map.thzpm", maps / "link.thzpm")
    other.save(maps / "link.thzpm")
    assert os.path.islink(maps / "link.thzpm")
    assert path.read_bytes() != before
    assert os.stat(path).st_mode & 0o777 == 0o640
    assert sorted(os.listdir(maps)) == ["link.thzpm", "map.thzpm"]
    assert thzmap.load_photon_map(scene, path).seed == SEED + 1


def test_photon_map_save_through_links_and_devices(tiny_dir):
    """PhotonMap.save onto what is not a regular file, or a symbolic link to a file not
    there yet, writes through it in place, as before the save renamed a temporary file
    into place: renamed over them, a link to /dev/null and a dangling link became regular
    files, and a device node (as root, /dev/null itself) was replaced by the map."""
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    pm = thzmap.fire_photons(scene, photons=3000, seed=SEED)
    null = tiny_dir / "null.thzpm"
    os.symlink("/dev/null", null)
    pm.save(null)
    assert os.path.islink(null) and os.readlink(null) == "/dev/null"
    dangling = tiny_dir / "dangling.thzpm"
    os.symlink("made.thzpm", dangling)
    pm.save(dangling)
    assert os.path.islink(dangling)
    assert thzmap.load_photon_map(scene, tiny_dir / "made.thzpm").seed == SEED
    device = tiny_dir / "device"
    try:
        os.mknod(device, 0o666 | stat.S_IFCHR, os.makedev(1, 3))  # /dev/null's numbers
    except PermissionError:
        return  # not root: no device node to write to
    pm.save(device)
    assert stat.S_ISCHR(os.lstat(device).st_mode)
    assert not [n for n in os.listdir(tiny_dir) if n.endswith(".part")]


def test_fire_and_merge(tiny_dir, tmp_path):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    a = thzmap.fire_photons(scene, photons=1500, seed=SEED)
    b = thzmap.fire_photons(scene, photons=1500, seed=SEED, first_photon=1500)
    merged = thzmap.merge_photon_maps([a, b])
    assert [s.fired for s in merged.stats] == [3000, 3000]
    # the same photons twice would count double: refused, as overlapping ranges are
    with pytest.raises(thzmap.Error, match="parts 0 and 1 are the same photon maps"):
        thzmap.merge_photon_maps([a, a])
    with pytest.raises(thzmap.Error, match="parts 0 and 1 are the same photon maps"):
        thzmap.merge_photon_maps([merged, merged])
    c = thzmap.fire_photons(scene, photons=1500, seed=SEED, first_photon=1000)
    with pytest.raises(thzmap.Error, match=r"channel 0 \(photons 1000 to 2499, and 1500 photons "
                       r"from 1500\)"):
        thzmap.merge_photon_maps([c, b])
    # a merged map knows its photons: 0..2999 again is refused
    full = thzmap.fire_photons(scene, photons=3000, seed=SEED)
    with pytest.raises(thzmap.Error, match=r"channel 0 \(photons 0 to 2999, and 3000 photons "
                       r"from 0\)"):
        thzmap.merge_photon_maps([full, merged])
    # a part that does not know its range (a loaded map) hides no overlap of the others
    b.save(tmp_path / "b.thzpm")
    loaded = thzmap.load_photon_map(scene, tmp_path / "b.thzpm")
    again = thzmap.fire_photons(scene, photons=1500, seed=SEED)  # a's photons
    with pytest.raises(thzmap.Error, match=r"channel 0 \(photons 0 to 1499, and 1500 photons "
                       r"from 0\)"):
        thzmap.merge_photon_maps([a, again, loaded])
    assert [s.fired for s in thzmap.merge_photon_maps([a, loaded]).stats] == [3000, 3000]
    with pytest.raises(thzmap.ArgumentError, match="sequence of PhotonMap"):
        thzmap.merge_photon_maps(a)
    assert thzmap.render(scene, merged).image("cam").radiance.shape == (12, 20, 2)


def test_scene_accessors(tiny_dir):
    scene = thzmap.scene_from_dict(tiny_scene_dict(), base_dir=tiny_dir, label="tiny")
    assert scene.name == "plate-in-box"
    assert [c.frequency_thz for c in scene.channels] == pytest.approx([0.35, 0.8])
    assert scene.object_names == ["room", "target", "cover"]
    assert scene.sensors[0].columns == 20 and scene.sensors[0].rows == 12
    table = [m for m in scene.materials if m.name == "table"][0]
    assert table.reflectivity.kind == "table"
    assert scene.info.path == "tiny"
    # an object by name, as its pixels hold it in object_id (there was sensor_index alone,
    # and object_names.index("targt") said "'targt' is not in list")
    assert scene.object_index("target") == 1 and scene.object_index(2) == 2
    ids = thzmap.simulate(scene, photons=500).image(0).object_id
    assert (ids == scene.object_index("target")).any()
    for bad in ("targt", 3, -1, True, None):
        with pytest.raises(thzmap.ArgumentError, match="object: the scene has no object .* "
                           r"\(it has room, target, cover\)"):
            scene.object_index(bad)
    with pytest.raises(thzmap.ArgumentError, match=r"sensor: the scene has no sensor 'x' "
                       r"\(it has cam\)"):
        scene.sensor_index("x")


def test_scene_values_as_written():
    """A channel's frequency_thz is the scene file's number (0.8, not the 0.7999999999999999
    of 8e11 Hz x 1e-12), and an object's bounds are its float vertices' shortest decimals
    (0.6, not 0.6000000238418579)."""
    scene = thzmap.load_scene(os.path.join(REPO, "examples", "walker", "scene.json"))
    assert [c.frequency_thz for c in scene.channels] == [0.3, 0.8]
    screen = [o for o in scene.objects if o.name == "screen"][0]
    assert screen.bbox_min_m[0] == -0.6 and screen.bbox_max_m[0] == 0.6
    assert screen.bbox_max_m[2] == 1.8
    assert abs(screen.bbox_min_m[2]) < 1e-7  # the rotation's float rounding: kept, not hidden


def test_measured_planes(tiny_dir, thzmap_binary):
    """measured_radiance and measured_brightness_temperature: None without a sensor
    model, else (rows, columns, channels) equal to the CLI's ENVI files."""
    plain = thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"), seed=SEED,
                            integrator="path")
    assert plain.image("cam").measured_radiance is None
    assert plain.image("cam").measured_brightness_temperature is None
    d = tiny_scene_dict()
    d["sensors"][0].update({"aperture_diameter_m": 0.02, "noise": {"netd_k": 0.5}})
    with open(tiny_dir / "model.json", "w") as f:
        json.dump(d, f)
    out = tiny_dir / "cli-model"
    run_cli(thzmap_binary, "simulate", tiny_dir / "model.json", "-o", out, "--seed", SEED,
            "--integrator", "path", "--threads", 2, "--quiet")
    im = thzmap.simulate(thzmap.load_scene(tiny_dir / "model.json"), seed=SEED,
                         integrator="path", threads=1).image("cam")
    for q in ("measured_radiance", "measured_brightness_temperature"):
        a = getattr(im, q)
        assert a.shape == (im.rows, im.columns, im.n_channels)
        assert_bitwise_equal(a, read_envi(out, "cam", q, im.rows, im.columns), q)
    assert not np.array_equal(im.measured_brightness_temperature, im.brightness_temperature)


def test_maps_hold_minus_one_where_nothing_is_hit(tmp_path):
    """temperature, distance and object_id read -1 where a pixel sees nothing (as the
    ENVI files), and Image's docstring says so (it once said 0 for temperature and
    distance)."""
    d = tiny_scene_dict()
    d["objects"] = [o for o in d["objects"] if o["name"] != "room"]  # open to the sky
    d["render"] = {"integrator": "path", "paths_per_sample": 1}
    d["materials"].pop("table")
    with open(tmp_path / "scene.json", "w") as f:
        json.dump(d, f)
    im = thzmap.simulate(thzmap.load_scene(tmp_path / "scene.json"), seed=SEED).image("cam")
    none = im.object_id == -1
    assert none.any() and (~none).any()
    for q in ("temperature", "distance"):
        assert np.all(getattr(im, q)[none] == -1), q
        assert np.all(getattr(im, q)[~none] > 0), q
    doc = " ".join(thzmap.Image.__doc__.split())
    assert "temperature (K, -1 where nothing is hit), distance (m, -1: none)" in doc


def test_sensors_by_name_or_index_and_their_shapes(tiny_dir):
    """render(sensor=None) renders every sensor, sensor= one of them (a name or a 0-based
    index; -1 is no sensor, not "every sensor" as the C API's -1 means); an image's visual
    is (rows, columns, 3) and its frequencies_thz the channels' centres in THz."""
    d = tiny_scene_dict()
    side = dict(d["sensors"][0], name="side", resolution=[8, 6])
    d["sensors"].append(side)
    scene = thzmap.scene_from_dict(d, base_dir=tiny_dir)
    both = thzmap.render(scene, integrator="path", seed=SEED)
    assert both.sensors == ["cam", "side"]
    for s in ("side", 1):
        one = thzmap.render(scene, integrator="path", seed=SEED, sensor=s)
        assert one.sensors == ["side"]
    for bad in (-1, 2):
        with pytest.raises(thzmap.ArgumentError, match="no sensor"):
            thzmap.render(scene, integrator="path", seed=SEED, sensor=bad)
        with pytest.raises(thzmap.ArgumentError, match="no sensor"):
            both.image(bad)
    im = both.image("side")
    assert (im.rows, im.columns) == (6, 8)
    assert im.visual.shape == (6, 8, 3)
    assert im.temperature.shape == (6, 8)
    assert list(im.frequencies_thz) == [0.35, 0.8]  # the scene's numbers, THz


def test_photon_map_accessors(tiny_dir):
    """A map's seed is the whole 64-bit seed fired with; has_channel takes the scene's
    channels only; maps of two Scene objects of one file merge as maps of one Scene do
    (they were refused: 'different Scene objects'), and those of a scene that differs are
    refused saying what differs; a run's summary says the scene's load time."""
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    seed = (1 << 40) + 3  # above 32 bits
    a = thzmap.fire_photons(scene, photons=500, seed=seed)
    assert a.seed == seed
    assert [a.has_channel(c) for c in (0, 1)] == [True, True]
    with pytest.raises(thzmap.ArgumentError, match=r"channel: expected a whole number in \[0, 1\]"):
        a.has_channel(2)
    other = thzmap.load_scene(tiny_dir / "scene.json")
    b = thzmap.fire_photons(other, photons=500, seed=seed, first_photon=500)
    same = thzmap.fire_photons(scene, photons=500, seed=seed, first_photon=500)
    merged = thzmap.merge_photon_maps([a, b])
    assert merged.scene is scene and merged.photons_per_channel == 1000
    want = thzmap.render(scene, thzmap.merge_photon_maps([a, same]))
    got = thzmap.render(scene, merged)
    assert np.array_equal(got.image("cam").radiance, want.image("cam").radiance)
    with open(tiny_dir / "scene.json") as f:
        warmer = json.load(f)
    for o in warmer["objects"]:
        o["temperature_k"] = o.get("temperature_k", 300) + 1
    c = thzmap.fire_photons(thzmap.scene_from_dict(warmer, base_dir=tiny_dir), photons=500,
                            seed=seed, first_photon=500)
    with pytest.raises(thzmap.Error, match="part 1 .* made from another scene"):
        thzmap.merge_photon_maps([a, c])
    assert scene.seconds_load > 0
    run = thzmap.render(scene, a)
    assert run.summary["timings_s"]["load"] == pytest.approx(scene.seconds_load, rel=1e-6)


def test_stderr_not_estimated_is_zero(tiny_dir):
    """One path per sample in one pass gives each pixel no spread to estimate its error
    from: radiance_stderr holds zeros there (python.md), and a number with 2 paths."""
    for paths, estimated in ((1, False), (2, True)):
        d = tiny_scene_dict()
        d.setdefault("render", {})["paths_per_sample"] = paths
        scene = thzmap.scene_from_dict(d, base_dir=tiny_dir)
        im = thzmap.simulate(scene, integrator="path", seed=SEED, threads=2).image("cam")
        assert im.radiance_stderr is not None
        assert bool((im.radiance_stderr > 0).any()) == estimated, paths
