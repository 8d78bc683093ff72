"""The library reads and writes numbers as JSON writes them whatever the host's locale.

A program that calls setlocale(LC_ALL, "") under a comma-decimal locale (GTK, Qt and
some Python programs do) made strtod refuse the scene's "0.100" in a material table
and printf write "352,5" into the ENVI headers. The test builds a German locale with
localedef (Debian's `locales` package, which scripts/install-deps.sh installs) and runs
the package in a child process under it: the scene must load and the headers must be
the bytes written under the "C" locale.
"""
import json
import os
import subprocess
import sys

import pytest

CHILD = r"""
import json, locale, sys
import thzmap
locale.setlocale(locale.LC_ALL, sys.argv[3])
if sys.argv[3] != "C":
    assert locale.localeconv()["decimal_point"] == ",", locale.localeconv()
scene = thzmap.load_scene(sys.argv[1])
thzmap.simulate(scene, integrator="photon-map", photons=2000, seed=3, threads=1).save(sys.argv[2])
# a sweep's label writes its numbers shortest ("0.1"), through printf
seq = sys.argv[1].replace("scene.json", "sequence.json")
with open(seq, "w") as f:
    json.dump({"format": "thzmap-sequence/1", "scene": "scene.json",
               "sweep": {"objects.target.temperature_k": [300.5, 310.25]}}, f)
thzmap.batch(seq, sys.argv[2] + "-batch", threads=1, movies=False)
"""


def _german_locale(tmp_path):
    source = "/usr/share/i18n/locales/de_DE"
    if not os.path.exists(source):
        pytest.fail(f"{source} is missing: install Debian's 'locales' package "
                    "(scripts/install-deps.sh all)")
    where = tmp_path / "locale"
    where.mkdir()
    subprocess.run(["localedef", "-i", "de_DE", "-f", "UTF-8", str(where / "de_DE.UTF-8")],
                   check=True, capture_output=True)
    return str(where)


def _run(tmp_path, scene, out, locale_name, locpath):
    env = dict(os.environ, LOCPATH=locpath)
    done = subprocess.run([sys.executable, "-c", CHILD, str(scene), str(out), locale_name],
                          env=env, capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_a_comma_decimal_locale_changes_no_file(tiny_dir, tmp_path):
    locpath = _german_locale(tmp_path)
    scene = tiny_dir / "scene.json"
    _run(tmp_path, scene, tmp_path / "c", "C", locpath)
    _run(tmp_path, scene, tmp_path / "de", "de_DE.UTF-8", locpath)
    headers = sorted(p for p in os.listdir(tmp_path / "c") if p.endswith(".hdr"))
    assert headers, os.listdir(tmp_path / "c")
    for name in headers:
        c = (tmp_path / "c" / name).read_bytes()
        de = (tmp_path / "de" / name).read_bytes()
        assert b"wavelength = {350, 800}" in c or b"wavelength" not in c, c
        assert de == c, (name, de)
        image = name[:-4] + ".img"
        assert (tmp_path / "de" / image).read_bytes() == \
            (tmp_path / "c" / image).read_bytes()
    for name in ("c-batch", "de-batch"):
        label = json.loads((tmp_path / name / "batch.json").read_text())["sweeps"][1]["label"]
        assert label == "objects.target.temperature_k = 310.25", (name, label)
