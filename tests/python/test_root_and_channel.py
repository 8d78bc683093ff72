"""Scenes confined to a root directory (load_scene/scene_from_json/scene_from_dict with
root=, thz_scene_load_within) and one channel of a photon-map file (load_photon_map with
channel=, thz_photons_load_channel)."""
import json
import os

import pytest
import thzmap
from conftest import REPO, tiny_scene_dict

SEED = 5


def test_a_scene_inside_its_root_loads(tiny_dir):
    plain = thzmap.load_scene(tiny_dir / "scene.json")
    rooted = thzmap.load_scene(tiny_dir / "scene.json", root=tiny_dir)
    assert rooted.object_names == plain.object_names
    assert [m.name for m in rooted.materials] == [m.name for m in plain.materials]


def test_a_scene_outside_its_root_is_refused(tiny_dir, tmp_path_factory):
    elsewhere = tmp_path_factory.mktemp("elsewhere")
    with pytest.raises(thzmap.SceneError):
        thzmap.load_scene(tiny_dir / "scene.json", root=elsewhere)


def test_a_named_file_outside_the_root_is_refused_at_its_key(tiny_dir, tmp_path_factory):
    """The scene text lies nowhere; its material table lies outside root: refused at the
    JSON path of the key naming the file, and accepted with the root that holds it."""
    elsewhere = tmp_path_factory.mktemp("elsewhere")
    text = json.dumps(tiny_scene_dict())
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.scene_from_json(text, base_dir=tiny_dir, root=elsewhere)
    assert e.value.path == "materials.table.file"
    assert str(tiny_dir) not in str(e.value)  # quotes nothing of the file system
    thzmap.scene_from_json(text, base_dir=tiny_dir, root=tiny_dir)
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.scene_from_dict(tiny_scene_dict(), base_dir=tiny_dir, root=elsewhere)
    assert e.value.path == "materials.table.file"
    # a link inside root to the file outside is followed, and refused
    os.makedirs(elsewhere / "materials")
    os.symlink(tiny_dir / "materials" / "sample.csv", elsewhere / "materials" / "sample.csv")
    with pytest.raises(thzmap.SceneError):
        thzmap.scene_from_json(text, base_dir=elsewhere, root=elsewhere)


def test_root_must_be_a_path(tiny_dir):
    with pytest.raises(thzmap.ArgumentError):
        thzmap.load_scene(tiny_dir / "scene.json", root=3)


def test_one_channel_of_a_photon_map_file(tiny_dir):
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    path = tiny_dir / "map.thzpm"
    full = thzmap.fire_photons(scene, photons=2000, seed=SEED)
    full.save(path)
    one = thzmap.load_photon_map(scene, path, channel=1)
    assert [one.has_channel(c) for c in range(2)] == [False, True]
    assert [s.fired for s in one.stats] == [2000, 2000]  # every channel's statistics
    assert one.stats[1].stored == full.stats[1].stored
    # the channel renders as from the whole file (channel 0 has no map: refused)
    with pytest.raises(thzmap.Error):
        thzmap.render(scene, one)
    for bad in (2, -1, "1"):
        with pytest.raises(thzmap.ArgumentError):
            thzmap.load_photon_map(scene, path, channel=bad)


def test_load_photon_map_progress_and_cancel(tiny_dir):
    """load_photon_map reports "read" per channel and a true return cancels it (it
    reported nothing: progress was accepted and never called, Ctrl-C waited)."""
    scene = thzmap.load_scene(tiny_dir / "scene.json")
    path = tiny_dir / "progress.thzpm"
    full = thzmap.fire_photons(scene, photons=2000, seed=SEED)
    full.save(path)
    seen = []
    thzmap.load_photon_map(scene, path, progress=seen.append)
    stored = [s.stored for s in full.stats]
    assert [(p.stage, p.channel, p.done, p.total) for p in seen] == \
        [("read", 0, 0, stored[0]), ("read", 1, 0, stored[1]),
         ("read", 0, stored[0], stored[0]), ("read", 1, stored[1], stored[1])], seen
    with pytest.raises(thzmap.CancelledError):
        thzmap.load_photon_map(scene, path, progress=lambda p: True)


def test_a_sequence_outside_its_root_is_refused(tmp_path):
    """load_sequence(root=...) confines the sequence file as load_scene's root does."""
    seq = os.path.join(REPO, "tests", "inputs", "batch", "sequence.json")
    assert len(thzmap.load_sequence(seq, root=os.path.dirname(seq))) == 5
    with pytest.raises(thzmap.SceneError):
        thzmap.load_sequence(seq, root=tmp_path)
