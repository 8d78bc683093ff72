"""A PhotonMap made for one Scene renders another Scene of the same geometry, materials
and channels (another viewpoint) without firing again: thzmap.render(scene2, pm) gives
the bits `thzmap render scene2.json --photon-map map.thzpm` writes, whether the map was
kept by simulate or loaded for the first Scene; a map of another geometry or channel set
is refused saying which, as the file is."""
import gc
import json

import pytest

import thzmap
from conftest import CUBES, MAPS, assert_bitwise_equal, read_envi, run_cli, tiny_scene_dict


def _write(directory, name, d):
    path = directory / name
    path.write_text(json.dumps(d))
    return path


def _second_view(d):
    """The scene seen from elsewhere in the same room: cam moved and a second sensor."""
    d = json.loads(json.dumps(d))
    d["sensors"][0].update({"position_m": [0.2, -0.4, 0.6], "look_at_m": [0, 0, 0.35]})
    d["sensors"].append(dict(d["sensors"][0], name="top", position_m=[0.3, 0.3, 1.5],
                             look_at_m=[0, 0, 0.4], resolution=[10, 14]))
    return d


def test_render_another_scene_from_a_photon_map(tiny_dir, thzmap_binary, tmp_path):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    path2 = _write(tiny_dir, "scene2.json", _second_view(tiny_scene_dict()))
    scene2 = thzmap.load_scene(path2)
    result = thzmap.simulate(scene, photons=3000, seed=5, keep_photons=True, threads=1)
    map_path = tmp_path / "map.thzpm"
    result.photon_map.save(map_path)
    out = tmp_path / "cli"
    run_cli(thzmap_binary, "render", path2, "--photon-map", map_path, "-o", out,
            "--threads", "2", "--quiet")

    loaded = thzmap.load_photon_map(scene, map_path)
    del scene  # the PhotonMap holds the Scene it was made for
    gc.collect()
    for what, pm in (("kept", result.photon_map), ("loaded", loaded)):
        again = thzmap.render(scene2, pm, threads=1)
        assert again.sensors == ["cam", "top"], what
        assert again.totals.photons_fired == 0, what
        for name in again.sensors:
            im = again.image(name)
            for q in CUBES + MAPS:
                assert_bitwise_equal(getattr(im, q), read_envi(out, name, q, im.rows,
                                                               im.columns), f"{what} {name} {q}")
    one = thzmap.render(scene2, loaded, sensor="top", threads=1)
    assert one.sensors == ["top"]
    im = one.image("top")
    assert_bitwise_equal(im.brightness_temperature,
                         read_envi(out, "top", "brightness_temperature", im.rows, im.columns),
                         "top alone")


@pytest.mark.parametrize("change, differs", [
    (lambda d: d["objects"][1]["shape"].update(radius_m=0.12), "another scene geometry"),
    (lambda d: d["channels"][1].update(frequency_thz=0.7), "another channel set"),
    (lambda d: d["objects"][1].update(temperature_k=320), "another scene \\(materials"),
])
def test_a_photon_map_of_another_scene_is_refused(tiny_dir, tmp_path, change, differs):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    pm = thzmap.fire_photons(scene, photons=500)
    map_path = tmp_path / "map.thzpm"
    pm.save(map_path)
    d = _second_view(tiny_scene_dict())
    change(d)
    other = thzmap.load_scene(_write(tiny_dir, "other.json", d))
    with pytest.raises(thzmap.Error, match=differs + ".*other.json") as in_memory:
        thzmap.render(other, pm)
    with pytest.raises(thzmap.Error, match=differs + ".*other.json") as from_file:
        thzmap.render(other, map_path)
    assert not isinstance(in_memory.value, thzmap.ArgumentError)
    # the same words for what differs, from memory and from the file
    said = str(from_file.value).split(" was made from ", 1)[1].split(";")[0]
    assert said in str(in_memory.value), (str(in_memory.value), said)
