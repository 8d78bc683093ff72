"""The complete example of docs/python.md, and its section on the air, materials and
Planck's law, run as written (from a scratch directory, with the repository's examples/
path made absolute)."""
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
    code = code.replace('"examples/', '"' + os.path.join(REPO, "examples") + "/")
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
    assert "['side'] 0\n" in p.stdout  # the second viewpoint, from the saved map


def test_the_docs_optics_snippet_runs(tmp_path):
    _run_section("## The air, materials and Planck's law at chosen frequencies", tmp_path,
                 timeout=120)
