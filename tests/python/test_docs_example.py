"""The complete example of docs/python.md, its section on the air, materials and
Planck's law, and its classify_spectra example, run as written (from a scratch
directory, with the repository's examples/ and tests/ paths made absolute)."""
import os
import re
import subprocess
import sys

from conftest import REPO


def _run_section(title, cwd, *flags, timeout):
    """Runs the first python block after the heading `title` of docs/python.md."""
    with open(os.path.join(REPO, "docs", "python.md")) as f:
        text = f.read()
    section = text.split(title, 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    for folder in ("examples", "tests"):
        code = code.replace(f'"{folder}/', '"' + os.path.join(REPO, folder) + "/")
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
