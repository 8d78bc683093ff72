"""thzmap.classify_spectra (python/thzmap/classification.py over thz_cube_create and
thz_classify_cube): a run's cube and truth as arrays classify exactly as thzmap.classify
classifies the run's files, for every method; the (pixels, channels) form of the same
pixels gives the same; spectra pooled over two humidities classify as well as each run
alone; bad arrays raise ArgumentError naming the argument."""
import json
import math
import os

import numpy as np
import pytest
from conftest import REPO, assert_bitwise_equal, read_envi

import thzmap
from thzmap.classification import methods

DISTINCT = os.path.join(REPO, "tests", "inputs", "analysis", "distinct.json")


@pytest.fixture(scope="module")
def distinct(tmp_path_factory):
    scene = thzmap.load_scene(DISTINCT)
    result = thzmap.simulate(scene, seed=1)
    out = tmp_path_factory.mktemp("distinct") / "run"
    result.save(out)
    return scene, result, out


def _same(a, b, layout=True):
    """Every result two classifications give (not where their data came from, nor with
    layout False the image's columns and rows)."""
    assert a.method == b.method
    assert a.confusion.dtype == b.confusion.dtype == np.uint64
    assert a.confusion.tolist() == b.confusion.tolist(), a.method
    assert a.accuracy == b.accuracy and a.pixels == b.pixels, a.method
    assert a.held_out_accuracy == b.held_out_accuracy, a.method
    assert a.training_pixels == b.training_pixels, a.method
    assert a.classes == b.classes and a.class_objects == b.class_objects
    assert a.class_accuracy == b.class_accuracy, a.method
    assert np.array_equal(np.array(a.auc), np.array(b.auc), equal_nan=True), a.method
    assert np.array_equal(a.class_map.reshape(-1), b.class_map.reshape(-1)), a.method
    skip = ("run_dir", "sensor", "source") + (() if layout else ("columns", "rows"))
    ra = {k: v for k, v in a.report.items() if k not in skip}
    rb = {k: v for k, v in b.report.items() if k not in skip}
    assert ra == rb, a.method


def test_arrays_classify_as_the_run(distinct):
    scene, result, run_dir = distinct
    image = result.image("cam")
    tb, ids = image.brightness_temperature, image.object_id
    # the arrays are the run's files, bit for bit
    assert_bitwise_equal(tb, read_envi(run_dir, "cam", "brightness_temperature", image.rows,
                                       image.columns), "brightness_temperature")
    assert_bitwise_equal(ids, read_envi(run_dir, "cam", "object_id", image.rows,
                                        image.columns), "object_id")
    hit = ids >= 0
    for method in methods():
        run = thzmap.classify(run_dir, "cam", method=method, netd_k=0.5, seed=2)
        assert run.source == "cam.brightness_temperature"  # the cube compared with
        arrays = thzmap.classify_spectra(tb, ids.astype(np.int64), method=method, netd_k=0.5,
                                         seed=2, names=scene.object_names)
        _same(arrays, run)
        assert arrays.class_map.shape == (image.rows, image.columns)
        assert arrays.sensor is None and arrays.source == "spectra"
        assert arrays.classes == ["room", "A", "B", "C"]
        # the truth as object_id gives it (float32), and the pixels as a list
        flat = thzmap.classify_spectra(tb.reshape(-1, tb.shape[2]), ids.reshape(-1),
                                       method=method, netd_k=0.5, seed=2,
                                       names=scene.object_names)
        _same(flat, run, layout=False)
        assert flat.report["columns"] == ids.size and flat.report["rows"] == 1
        assert flat.class_map.shape == (image.rows * image.columns,)
    # without names the classes are "object N"; the noise-free run is exact with lda
    plain = thzmap.classify_spectra(tb[hit], ids[hit], method="lda")
    assert plain.classes == ["object 0", "object 1", "object 2", "object 3"]
    assert plain.accuracy == 1.0


def test_pooled_humidities_classify_as_each_alone():
    """distinct.json (to 0.96 THz, inside ITU-R P.676's range) in air of 20 % and 80 %
    relative humidity: the water lines change the spectra, not the plates' order. Pooled,
    each method's accuracy lies within three binomial standard errors (of the pooled
    pixel count) of the two runs' range; lda is exact noise-free, alone and pooled."""
    with open(DISTINCT) as f:
        d = json.load(f)
    d["channels"]["to_thz"] = 0.96
    images = []
    for rh in (0.2, 0.8):
        d["atmosphere"] = {"model": "itu-p676", "temperature_k": 296, "pressure_hpa": 1013.25,
                           "relative_humidity": rh}
        scene = thzmap.scene_from_dict(d, base_dir=os.path.dirname(DISTINCT))
        images.append(thzmap.simulate(scene, seed=1).image("cam"))
    dry, humid = (i.brightness_temperature for i in images)
    # the humidity shows: plate A at 0.58 THz is > 0.4 K colder in humid air
    assert dry[8, 3, 2] - humid[8, 3, 2] > 0.4
    channels = dry.shape[2]
    spectra = np.concatenate([i.brightness_temperature.reshape(-1, channels) for i in images])
    truth = np.concatenate([i.object_id.reshape(-1) for i in images]).astype(np.int32)
    names = scene.object_names
    assert thzmap.classify_spectra(spectra, truth, method="lda", names=names).accuracy == 1.0
    n = spectra.shape[0]
    for method in methods():
        alone = [thzmap.classify_spectra(i.brightness_temperature, i.object_id, method=method,
                                         netd_k=2.0).accuracy for i in images]
        pooled = thzmap.classify_spectra(spectra, truth, method=method, netd_k=2.0, names=names)
        assert pooled.pixels == n and int(pooled.confusion.sum()) == n
        p = sum(alone) / 2
        se = math.sqrt(p * (1 - p) / n)
        assert min(alone) - 3 * se <= pooled.accuracy <= max(alone) + 3 * se, \
            (method, alone, pooled.accuracy, se)
        assert pooled.classes == ["room", "A", "B", "C"]


def test_refusals_name_the_argument(distinct):
    _, result, _ = distinct
    image = result.image("cam")
    tb, ids = image.brightness_temperature, image.object_id
    bad = [
        (dict(spectra=tb[0, 0]), "spectra: expected a shape (rows, columns, channels)"),
        (dict(spectra=tb[None]), "spectra: expected a shape"),
        (dict(spectra=tb[:, :0]), "spectra: expected a shape"),
        (dict(spectra=tb.astype(complex)), "spectra: expected real numbers"),
        (dict(spectra=tb > 300), "spectra: expected real numbers"),
        (dict(spectra="cam.brightness_temperature"), "spectra: expected a numpy array"),
        (dict(truth=ids[:, :-1]), "truth: expected the shape (16, 24)"),
        (dict(truth=ids.reshape(-1)), "truth: expected the shape (16, 24)"),
        (dict(truth=ids >= 0), "truth: expected whole class labels"),
        (dict(truth=ids.astype(str)), "truth: expected whole class labels"),
        (dict(truth=ids + 0.5), "truth: the label at [0, 0] is 0.5"),
        (dict(truth=ids - 2), "truth: the label at [0, 0] is -2.0: expected -1"),
        (dict(truth=np.full(ids.shape, 1 << 24)), "truth: the label at [0, 0] is 16777216"),
        (dict(names=["room", "A"]), "names: 2 names, but truth holds the label 3"),
        (dict(names="room"), "names: expected a list"),
        (dict(names=["room", "A", "", "C"]), "names: expected non-empty names, got '' at 2"),
        (dict(method="svm"), "method: expected one of"),
        (dict(train_fraction=0), "train_fraction"),
        (dict(netd_k=-1), "netd_k"),
    ]
    for kwargs, words in bad:
        args = {"spectra": tb, "truth": ids, **kwargs}
        with pytest.raises(thzmap.ArgumentError) as e:
            thzmap.classify_spectra(**args)
        assert words in str(e.value), (kwargs.keys(), str(e.value))
    for value, words in ((np.nan, "nan: not finite"), (np.inf, "inf: not finite"),
                         (1e39, "1e+39: beyond float32's range")):
        spectra = tb.astype(np.float64)
        spectra[3, 4, 1] = value
        with pytest.raises(thzmap.ArgumentError) as e:
            thzmap.classify_spectra(spectra, ids)
        assert f"spectra: the value at [3, 4, 1] is {words}" in str(e.value)
    # what the library refuses: one class (nothing to tell apart), sam on one channel
    with pytest.raises(thzmap.Error, match="truth: the truth map shows one object only"):
        thzmap.classify_spectra(tb, np.where(ids == 1, 1, -1))
    with pytest.raises(thzmap.Error, match="spectra has 1 channel: sam compares"):
        thzmap.classify_spectra(tb[:, :, :1], ids)


def test_save_writes_the_cube_files(distinct, tmp_path):
    scene, result, _ = distinct
    image = result.image("cam")
    c = thzmap.classify_spectra(image.brightness_temperature, image.object_id, method="lda",
                                names=scene.object_names)
    c.save(tmp_path / "out")
    with open(tmp_path / "out" / "classification.json") as f:
        doc = json.load(f)
    assert doc["source"] == "spectra" and doc["sensor"] is None
    assert doc["confusion"] == c.confusion.tolist()
    saved = read_envi(tmp_path / "out", "cube", "class", image.rows, image.columns)
    assert np.array_equal(saved.reshape(image.rows, image.columns), c.class_map)
    assert "object names = {room, A, B, C}" in (tmp_path / "out" / "cube.class.hdr").read_text()


def test_save_of_more_pixels_than_a_png_row_takes(tmp_path):
    """(pixels, channels) is one row of pixels in cube.class.png. When the PNG was the map
    itself, libpng's limit of 10^6 a side refused one more pixel; the PNG is now a figure
    of the map with its legend (scene-format.md: 960 pixels wide), whatever the map's
    size, so the row saves and its map is the ENVI file's."""
    n = 1_000_001
    labels = np.arange(n) % 2
    spectra = np.stack([300.0 + 2 * labels, 290.0 - labels], axis=1)
    c = thzmap.classify_spectra(spectra, labels, method="lda")
    assert c.accuracy == 1.0 and c.class_map.shape == (n,)
    c.save(tmp_path / "out")
    png = (tmp_path / "out" / "cube.class.png").read_bytes()
    assert png[:8] == b"\x89PNG\r\n\x1a\n" and png[12:16] == b"IHDR"
    assert int.from_bytes(png[16:20], "big") == 960, int.from_bytes(png[16:20], "big")
    saved = np.fromfile(tmp_path / "out" / "cube.class.img", "<f4")
    assert np.array_equal(saved, c.class_map)


def test_training_mask_is_the_split_the_figures_use(distinct):
    """training_mask: the pixels that trained. Each class trains round(0.3 n) of its n
    pixels (at least 1), no unclassified pixel trains, and the held-out accuracy and the
    confusion matrix recomputed from class_map over the pixels outside the mask are the
    library's: a user's own classifier can be scored on the same split."""
    _, result, run_dir = distinct
    ids = result.image("cam").object_id.astype(np.int32)
    for method in ("sam", "lda"):
        c = thzmap.classify(run_dir, "cam", method=method, train_fraction=0.3, netd_k=1.0,
                            seed=5)
        m = c.training_mask
        assert m.dtype == bool and m.shape == c.class_map.shape == ids.shape
        assert int(m.sum()) == c.training_pixels and not m[ids < 0].any()
        for obj in c.class_objects:
            n = int((ids == obj).sum())
            assert int(m[ids == obj].sum()) == max(1, math.floor(0.3 * n + 0.5)), obj
        held = (ids >= 0) & ~m
        assert int(held.sum()) == c.held_out_pixels
        right = int((c.class_map[held] == ids[held]).sum())
        assert c.held_out_accuracy == pytest.approx(right / int(held.sum()), rel=1e-12)
        # another seed, another split
        other = thzmap.classify(run_dir, "cam", method=method, train_fraction=0.3,
                                netd_k=1.0, seed=6)
        assert not np.array_equal(other.training_mask, m)
    tb = result.image("cam").brightness_temperature
    flat = thzmap.classify_spectra(tb.reshape(-1, tb.shape[-1]), ids.reshape(-1), method="lda",
                                   train_fraction=0.3, netd_k=1.0, seed=5)
    assert flat.training_mask.shape == (ids.size,)
    assert np.array_equal(flat.training_mask, c.training_mask.reshape(-1))
