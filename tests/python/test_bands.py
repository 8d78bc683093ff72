"""thzmap.bands and thzmap.classify (python/thzmap/band_selection.py, classification.py): the same
results as `thzmap bands` and `thzmap classify` on the analysis test scenes, their
structures match the C headers, and bad arguments raise before any work."""
import ctypes
import json
import math
import os
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest
from conftest import REPO

import thzmap
from thzmap import band_selection as bands_module
from thzmap import classification as classify_module

SCENES = os.path.join(REPO, "tests", "inputs", "analysis")
FEATURES = os.path.join(SCENES, "features.json")
# 5 centres, 2 widths, 2 paths per sample: a second or two
GRID = dict(from_thz=0.2, to_thz=1.0, step_ghz=200, paths=2)


def test_structures_match_the_headers(tmp_path):
    structs = {**bands_module.STRUCTS, **classify_module.STRUCTS}
    expect, lines = {}, ["#include <stddef.h>", "#include <stdio.h>",
                         "#include <thzmap/thzmap.h>", "int main(void) {"]
    for cname, struct in structs.items():
        expect[f"sizeof {cname}"] = ctypes.sizeof(struct)
        lines.append(f'    printf("sizeof {cname} %zu\\n", sizeof({cname}));')
        for field, _ in struct._fields_:
            expect[f"offsetof {cname}.{field}"] = getattr(struct, field).offset
            lines.append(f'    printf("offsetof {cname}.{field} %zu\\n", '
                         f'offsetof({cname}, {field}));')
    lines += ["    return 0;", "}"]
    (tmp_path / "abi.c").write_text("\n".join(lines) + "\n")
    cc = os.environ.get("THZMAP_CC") or shutil.which("cc")
    if not cc:
        pytest.fail("no C compiler (set THZMAP_CC)")
    subprocess.run([cc, "-std=c17", "-I", os.path.join(REPO, "include"),
                    str(tmp_path / "abi.c"), "-o", str(tmp_path / "abi")], check=True)
    out = subprocess.run([str(tmp_path / "abi")], check=True, capture_output=True, text=True)
    got = {k: int(v) for k, v in (line.rsplit(" ", 1) for line in out.stdout.splitlines())}
    assert got == expect


def test_bands_equals_the_command(tmp_path, thzmap_binary):
    sel = thzmap.bands(FEATURES, 2, widths=[0.3, 0.01], netd_k=0.5, threads=1, **GRID)
    subprocess.run([thzmap_binary, "bands", FEATURES, "-o", str(tmp_path / "cli"), "--count",
                    "2", "--from-thz", "0.2", "--to-thz", "1.0", "--step-ghz", "200",
                    "--paths", "2", "--widths", "0.3,0.01", "--netd-k", "0.5", "-q"],
                   check=True)
    with open(tmp_path / "cli" / "bands.json") as f:
        cli = json.load(f)
    assert sel.selected_thz == cli["selected_thz"] == sorted(sel.selected_thz)
    assert sel.selected_relative_width == cli["selected_relative_width"]
    assert len(sel.selected_relative_width) == 2 and sel.count == 2
    assert sel.score == pytest.approx(cli["score"], rel=1e-9)
    assert sel.scores == pytest.approx([e["score"] for e in cli["per_k"]], rel=1e-9)
    assert sel.n_candidates == 10 and sel.n_classes == 4 and sel.search == "exhaustive"
    report, cli_report = dict(sel.report), dict(cli)
    report.pop("seconds"), cli_report.pop("seconds")
    assert report == cli_report
    sel.save(tmp_path / "py")
    assert {"bands.json", "bands-score.png", "bands-spectra.png"} <= \
        set(os.listdir(tmp_path / "py"))
    assert "BandSelection" in repr(sel)
    # each width named as one: "0.4 THz (relative width 0.01)", not "0.4 THz (0.01)"
    for f, w in zip(sel.selected_thz, sel.selected_relative_width):
        assert f"{f:.4g} THz (relative width {w:.3g})" in repr(sel), repr(sel)


def test_bands_progress_counts_renders():
    seen = []
    thzmap.bands(FEATURES, 1, threads=1, progress=seen.append, **GRID)
    assert {p.stage for p in seen} == {"bands"}
    ends = [(p.channel, p.n_channels) for p in seen if p.done == p.total]
    # the nominal render before the nuisances' count is known, then the coarse nominal
    # and one per target (room, A, B, C) of 6
    assert ends == [(0, 0)] + [(i, 6) for i in range(1, 6)], ends
    assert all(p.total == 5 for p in seen)  # the candidates, 0.2 to 1.0 THz by 200 GHz


FLAT_AND_DIP = os.path.join(SCENES, "flat-and-dip.json")
H, K_B, C0 = 6.62607015e-34, 1.380649e-23, 299792458.0


def _class_mean_stderr_k(path, name, thz, seed, paths):
    """The Monte Carlo standard error (K) of object `name`'s mean Tb, per frequency, in
    a render made as bands makes its nuisances' (1 sample per pixel, paths // 4 paths):
    its pixels' spread over sqrt(pixels), the object being of one flat reflectivity
    (a Lambertian plate of uniform Tb but for the render's noise)."""
    d = json.loads(Path(path).read_text())
    d["channels"] = [{"frequency_thz": f, "relative_width": 0.01} for f in thz]
    d["render"] = {"integrator": "path", "paths_per_sample": max(1, paths // 4)}
    d["sensors"][0]["oversampling"] = 1
    scene = thzmap.scene_from_dict(d, base_dir=os.path.dirname(path))
    image = thzmap.render(scene, integrator="path", seed=seed, threads=1).image("cam")
    names = [o["name"] for o in d["objects"]]
    mask = np.asarray(image.object_id).astype(int) == names.index(name)
    tb = np.asarray(image.brightness_temperature, dtype=np.float64)[mask]
    return tb.std(axis=0, ddof=1) / math.sqrt(mask.sum())


def test_each_target_temperature_varies_alone():
    # X (emissivity 0.4, reflectivity 0.6) in a closed room of 293 K: every object seen
    # is a target, each raised by 2 K in its own render. X's Tb moves by 0.4 x 2 K when
    # X is raised and by 0.6 x 2 K when the room is (X sees nothing else), so its spread
    # is sqrt(0.8^2 + 1.2^2) / sqrt(3) = 0.833 K; raised together (one render) it was
    # 2 / sqrt(3) = 1.155 K.
    thz = [0.2, 0.6, 1.0]
    sel = thzmap.bands(FLAT_AND_DIP, 1, from_thz=0.2, to_thz=1.0, step_ghz=400, paths=4,
                       threads=1)
    rep = sel.report
    assert [c["name"] for c in rep["classes"]] == ["room", "X", "Y"]
    assert rep["candidates"]["frequency_thz"] == thz
    x = next(c for c in rep["classes"] if c["name"] == "X")
    expect = math.hypot(0.4 * 2.0, 0.6 * 2.0) / math.sqrt(3.0)
    # the change of a class mean is the difference of two renders of the same seed: its
    # noise is at most sqrt(2) x the mean's standard error (the common seed only lowers
    # it); 3 of those, and 0.01 K for what the closed form leaves out (the room's view
    # of the plates, 1.5 % of its surface)
    se = _class_mean_stderr_k(FLAT_AND_DIP, "X", thz, rep["seed"], rep["paths_per_sample"])
    for f, got, s in zip(thz, x["nuisance_sd_k"], se):
        tol = max(3.0 * math.sqrt(2.0) * s, 0.01)
        assert abs(got - expect) <= tol, (f, got, expect, tol)
    # the nominal render, the coarse nominal one and one per target (no air, so the
    # ambient range changes nothing)
    assert rep["renders"] == 5


def test_air_temperature_varied_when_it_follows_the_room(tmp_path):
    # an emitting atmosphere without temperature_k takes the enclosure's: the ambient
    # nuisance that raises the room raises the air, and bands.json says so; without
    # targets the room is a target and its render holds the air, which the ambient
    # render raises alone
    d = json.loads(Path(FEATURES).read_text())
    d["atmosphere"] = {"model": "constant", "attenuation_per_m": 1.0}
    path = tmp_path / "air.json"
    path.write_text(json.dumps(d))
    grid = dict(from_thz=0.4, to_thz=0.8, step_ghz=400, paths=2, threads=1)
    sel = thzmap.bands(path, 1, targets=["A", "B"], **grid)
    assert sel.report["nuisances"]["air_temperature_varied"] is True
    sel = thzmap.bands(path, 1, **grid)
    assert sel.report["nuisances"]["air_temperature_varied"] is True
    # nominal, coarse nominal, room, A, B, C, the air
    assert sel.report["renders"] == 7
    d["atmosphere"]["emitting"] = False
    path.write_text(json.dumps(d))
    sel = thzmap.bands(path, 1, targets=["A", "B"], **grid)
    assert sel.report["nuisances"]["air_temperature_varied"] is False


def test_bands_takes_a_loaded_scene_and_targets():
    scene = thzmap.load_scene(FEATURES)
    sel = thzmap.bands(scene, 1, targets=["A", "B"], seed=3, **GRID)
    assert [c["name"] for c in sel.report["classes"]] == ["A", "B", "background"]
    assert sel.report["seed"] == 3 and 0.0 <= sel.score <= 2.0
    # every object seen a target: no "background" class (docs/analysis.md: every other
    # object seen forms it); one without pixels (a mutant that always added it passed
    # every test) would be a class of no pixels in every pair
    sel = thzmap.bands(scene, 1, targets=["room", "A", "B", "C"], seed=3, **GRID)
    assert [c["name"] for c in sel.report["classes"]] == ["room", "A", "B", "C"]


def test_bands_says_the_scene_warnings():
    """The scene's warnings reach the caller, as simulate's and render's do: those of the
    scene with the candidates as its channels, here candidates at 1.2 and 1.3 THz whose
    bands leave the tables of features.json, which end at 1.2 THz (the end values are
    used there). bands
    used to drop them, and the run warnings that refer to them ("see the scene
    warning") came alone."""
    with pytest.warns(thzmap.RunWarning) as caught:
        thzmap.bands(FEATURES, 1, from_thz=1.1, to_thz=1.3, step_ghz=100, paths=2)
    said = [str(w.message) for w in caught]
    assert any('material "a", reflectivity: the table covers 0.1 to 1.2 THz' in m
               and 'channel "1.200 THz"' in m for m in said), said
    # each points at the line that called bands, not into the package
    assert {w.filename for w in caught} == {__file__}


def test_bands_errors(tmp_path):
    for kwargs in (dict(count=0), dict(count=1, widths=[0.6]), dict(count=1, widths=[]),
                   dict(count=1, angle_range_deg=91), dict(count=1, targets=[""]),
                   dict(count=1, netd_k=-1), dict(count=1, netd_k=0), dict(count=True),
                   dict(count=1, from_thz=1.0, to_thz=0.5), dict(count=1, widths=[0.01, 0.01]),
                   dict(count=2, from_thz=0.5, to_thz=0.5), dict(count=1, targets=["A", "A"]),
                   dict(count=1, relative_width=0.01, widths=[0.02]),
                   dict(count=1, widths=0.01), dict(count=1, targets=5),
                   # the CLI's bounds: --from-thz > 0, --humidity-range 0 to 0.99,
                   # --count 1 to 32
                   dict(count=1, humidity_range=1.0), dict(count=33)):
        with pytest.raises(thzmap.ArgumentError):
            thzmap.bands(FEATURES, **kwargs)
    # bytes are not a list of names (they were taken apart: 'expected a non-empty name,
    # got 65', the code of their first letter)
    with pytest.raises(thzmap.ArgumentError, match=r"targets: expected object names, got b'A'"):
        thzmap.bands(FEATURES, 1, targets=b"A")
    with pytest.raises(thzmap.ArgumentError, match=r"from_thz: expected a number in \(0"):
        thzmap.bands(FEATURES, 1, from_thz=0)
    with pytest.raises(thzmap.ArgumentError):
        thzmap.bands(thzmap.scene_from_json(Path(FEATURES).read_text()), 1)
    # a Scene made from a dict labelled with the file's name is not the file: refused,
    # not run on the file as it is on disk
    d = json.loads(Path(FEATURES).read_text())
    d["objects"] = d["objects"][:2]
    made = thzmap.scene_from_dict(d, base_dir=os.path.dirname(FEATURES), label=FEATURES)
    with pytest.raises(thzmap.ArgumentError, match="not loaded from one"):
        thzmap.bands(made, 1, **GRID)
    # a Scene loaded from a file that changed since, or by a relative path from another
    # working directory, is the file it was loaded from, or refused
    copy = tmp_path / "scene.json"
    copy.write_text(Path(FEATURES).read_text())
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        loaded = thzmap.load_scene("scene.json")
    finally:
        os.chdir(cwd)
    assert thzmap.bands(loaded, 1, seed=3, **GRID).score >= 0.0
    copy.write_text(copy.read_text() + "\n")
    with pytest.raises(thzmap.ArgumentError, match="has changed since"):
        thzmap.bands(loaded, 1, **GRID)
    # an unknown target or sensor is an argument the scene lacks, not a bad scene file:
    # thzmap.Error (the sensor's was a SceneError, as if the file were broken)
    for kwargs in (dict(targets=["A", "nope"]), dict(sensor="nope")):
        with pytest.raises(thzmap.Error, match="nope") as e:
            thzmap.bands(FEATURES, 1, **kwargs, **GRID)
        assert not isinstance(e.value, thzmap.SceneError), (kwargs, e.value)
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "thzmap-scene/1",\n "name": }\n')
    with pytest.raises(thzmap.SceneError) as e:
        thzmap.bands(bad, 1, **GRID)
    assert e.value.line == 2
    # a scene file that cannot be read is a SceneError too, as load_scene's
    for path in (tmp_path / "missing.json", tmp_path):
        with pytest.raises(thzmap.SceneError) as e:
            thzmap.bands(path, 1, **GRID)
        assert e.value.file == str(path)


@pytest.fixture(scope="module")
def distinct_run(tmp_path_factory):
    scene = thzmap.load_scene(os.path.join(SCENES, "distinct.json"))
    result = thzmap.simulate(scene, seed=1)
    out = tmp_path_factory.mktemp("distinct") / "run"
    result.save(out)
    return result, out


def test_classify_equals_the_command(distinct_run, tmp_path, thzmap_binary):
    result, run_dir = distinct_run
    c = thzmap.classify(run_dir, "cam", method="lda", netd_k=0.5, seed=2)
    subprocess.run([thzmap_binary, "classify", str(run_dir), "--sensor", "cam", "-o",
                    str(tmp_path / "cli"), "--method", "lda", "--netd-k", "0.5", "--seed", "2"],
                   check=True, capture_output=True)
    with open(tmp_path / "cli" / "classification.json") as f:
        cli = json.load(f)
    assert c.accuracy == pytest.approx(cli["accuracy"], rel=1e-12)
    assert c.confusion.tolist() == cli["confusion"]
    assert int(c.confusion.sum()) == c.pixels == cli["pixels"]
    assert c.classes == [k["name"] for k in cli["classes"]]
    assert c.report["seed"] == cli["seed"] == 2
    image = result.image("cam")
    assert c.class_map.shape == (image.rows, image.columns)
    truth = image.object_id.astype(np.int32)
    assert np.array_equal(c.class_map < 0, truth < 0)
    # a Result is classified as the directory it saves
    same = thzmap.classify(result, "cam", method="lda", netd_k=0.5, seed=2)
    assert same.confusion.tolist() == c.confusion.tolist()
    assert same.method == "lda" and same.sensor == "cam"
    same.save(tmp_path / "py")
    assert {"classification.json", "cam.class.hdr", "cam.class.img", "cam.class.png"} <= \
        set(os.listdir(tmp_path / "py"))


def test_classify_noise_free_is_exact_and_noise_lowers_accuracy(distinct_run):
    _, run_dir = distinct_run
    exact = thzmap.classify(run_dir, "cam", method="lda")
    assert exact.accuracy == 1.0 and all(a == 1.0 for a in exact.class_accuracy)
    assert all(not math.isnan(a) for a in exact.auc)
    noisy = thzmap.classify(run_dir, "cam", method="lda", netd_k=8.0)
    assert noisy.accuracy < exact.accuracy
    # a class's accuracy is over all its pixels (training ones too): its confusion row
    rows = noisy.confusion.sum(axis=1)
    assert noisy.class_accuracy == pytest.approx(list(np.diag(noisy.confusion) / rows), rel=1e-12)
    assert noisy.held_out_pixels < int(rows.sum())
    doc = " ".join(thzmap.Classification.__doc__.split())
    assert "class_accuracy (per class, over all its pixels" in doc
    assert "auc (per class, one against the rest on the held-out pixels)" in doc


def test_classify_errors(distinct_run, tmp_path):
    _, run_dir = distinct_run
    assert "sam" in classify_module.methods()
    for kwargs in (dict(method="nope"), dict(train_fraction=1.0), dict(seed=-1),
                   dict(netd_k=float("nan"))):
        with pytest.raises(thzmap.ArgumentError):
            thzmap.classify(run_dir, "cam", **kwargs)
    with pytest.raises(thzmap.ArgumentError):
        thzmap.classify(run_dir, "")
    # a sensor the run lacks: said so, with the sensors it has (was: the cube file that
    # could not be opened, nope.brightness_temperature.hdr)
    with pytest.raises(thzmap.Error, match='the run there has no sensor "nope"; its sensor: "cam"'):
        thzmap.classify(run_dir, "nope")
    with pytest.raises(thzmap.Error):
        thzmap.classify(tmp_path / "missing", "cam")
    # a Result's sensors are checked before it is saved
    result, _ = distinct_run
    with pytest.raises(thzmap.ArgumentError, match="the run has no sensor 'nope'"):
        thzmap.classify(result, "nope")


def test_classify_fields_and_netd_zero(distinct_run):
    """held_out_accuracy is the held-out pixels' (not the whole accuracy: they differ
    when a tenth trains), as classification.json says; netd_k=0 adds no noise."""
    result, run_dir = distinct_run
    c = thzmap.classify(run_dir, "cam", method="lda", netd_k=0.5, seed=2, train_fraction=0.1)
    assert c.training_pixels + c.held_out_pixels == c.pixels
    # the JSON's 10 significant digits
    assert c.accuracy == pytest.approx(c.report["accuracy"], rel=1e-9)
    assert c.held_out_accuracy == pytest.approx(c.report["held_out_accuracy"], rel=1e-9)
    assert c.accuracy != c.held_out_accuracy
    plain = thzmap.classify(run_dir, "cam", method="lda", seed=2)
    zero = thzmap.classify(run_dir, "cam", method="lda", seed=2, netd_k=0)
    assert zero.confusion.tolist() == plain.confusion.tolist()
