"""The complete example of docs/python.md, its section on the air, materials and
Planck's law, its band selection, classify_spectra and sequence examples, run as
written (from a scratch directory, with the repository's examples/ and tests/ paths made
absolute), and the values the page gives in their comments checked; and the README's
Python lines."""
import os
import re
import subprocess
import sys

from conftest import REPO


def _run_section(title, cwd, *flags, timeout, then="", page=("docs", "python.md")):
    """Runs the first python block after the heading `title` of the page (docs/python.md),
    and `then` after it (checks of what the page says the block's lines give)."""
    with open(os.path.join(REPO, *page)) as f:
        text = f.read()
    section = text.split(title, 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    for folder in ("examples", "tests"):
        code = code.replace(f'"{folder}/', '"' + os.path.join(REPO, folder) + "/")
    code += then
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.join(REPO, "python"), os.environ.get("PYTHONPATH", "")]))
    p = subprocess.run([sys.executable, *flags, "-c", code], cwd=cwd, env=env,
                       capture_output=True, text=True, timeout=timeout)
    assert p.returncode == 0, p.stderr
    return p


def test_the_docs_example_runs(tmp_path):
    p = _run_section("## A complete example", tmp_path, "-W", "ignore", timeout=600)
    assert (tmp_path / "out" / "teraeye-py" / "cam.radiance.img").exists()
    assert (tmp_path / "map.thzpm").exists()
    assert "cylinder-A" in p.stdout
    # the second viewpoint, from the kept map of the first Scene, as from its file
    assert "['side'] 0\nTrue\n" in p.stdout


def test_the_docs_optics_snippet_runs(tmp_path):
    _run_section("## The air, materials and Planck's law at chosen frequencies", tmp_path,
                 timeout=120)


def test_the_docs_classify_spectra_example_runs(tmp_path):
    """The accuracies the page quotes are what the example prints."""
    p = _run_section("### Spectra you hold: classify_spectra", tmp_path, timeout=120)
    for line in ("sam             accuracy 0.639", "mahalanobis     accuracy 0.960",
                 "lda             accuracy 0.961", "matched-filter  accuracy 0.736",
                 "ace             accuracy 0.768", "['room', 'A', 'B', 'C'] (768,)"):
        assert line in p.stdout, p.stdout


def test_the_docs_bands_and_classify_example_gives_what_it_says(tmp_path):
    _run_section("## Band selection and classification", tmp_path, "-W", "ignore", timeout=300,
                 then="""
assert sel.selected_thz == [0.4, 0.8] and sel.selected_relative_width == [0.01, 0.01], sel
assert len(sel.scores) == 2 and 0 <= sel.score <= 2
assert c.confusion.dtype.name == "uint64" and c.class_map.dtype.name == "int32"
assert 0 <= c.accuracy <= 1
""")
    assert (tmp_path / "out" / "bands" / "bands.json").exists()
    assert (tmp_path / "out" / "classified" / "classification.json").exists()


def test_the_docs_sequence_example_gives_what_it_says(tmp_path):
    _run_section("## Sequences and batches", tmp_path, "-W", "ignore", timeout=600, then="""
assert (len(seq), seq.n_sweeps, seq.frames_per_sweep) == (25, 1, 25)
f = seq.frame(10)
assert (f.sweep, f.index, f.time_s, f.dir) == (0, 10, 1.25, "frame-00010"), f
assert (done.computed, done.reused, done.movies) == (25, 0, 2), done
again = thzmap.batch(seq, "out/walker", threads=2)
assert (again.computed, again.reused, again.movies) == (0, 25, 2), again
assert done.summary["frames"][10]["dir"] == "frame-00010"
""")


def test_the_readme_python_lines_run(tmp_path):
    _run_section("## Using it", tmp_path, "-W", "ignore", timeout=600, page=("README.md",), then="""
assert tb.shape == (64, 64, 1) and str(tb.dtype) == "float32", tb.shape
""")
    assert (tmp_path / "out" / "walker" / "batch.json").exists()
