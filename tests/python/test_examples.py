"""The examples in examples/python run (in their small form) and say what they did."""
import os
import subprocess
import sys

from conftest import REPO

EXAMPLES = os.path.join(REPO, "examples", "python")


def run_example(name, *args, cwd):
    env = dict(os.environ, THZMAP_EXAMPLE_SMALL="1", MPLBACKEND="Agg",
               PYTHONPATH=os.pathsep.join([os.path.join(REPO, "python"),
                                           os.environ.get("PYTHONPATH", "")]))
    p = subprocess.run([sys.executable, os.path.join(EXAMPLES, name), *args], cwd=cwd,
                       env=env, capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_simulate_teraeye_plots_a_png(tmp_path):
    out = run_example("simulate_teraeye.py", "--out", "spectra.png", cwd=tmp_path)
    png = tmp_path / "spectra.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert png.stat().st_size > 10_000, "the figure is suspiciously small"
    assert "6 channels" in out


def test_classify_pixels_prints_an_accuracy(tmp_path):
    out = run_example("classify_pixels.py", cwd=tmp_path)
    line = [x for x in out.splitlines() if x.startswith("accuracy:")]
    assert line, out
    accuracy = float(line[0].split()[1])
    # Five materials; guessing the largest class would score about 0.39.
    assert accuracy > 0.8, out
