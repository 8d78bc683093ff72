"""The complete example of docs/python.md runs as written (from a scratch directory,
with the repository's examples/ path made absolute)."""
import os
import re
import subprocess
import sys

from conftest import REPO


def test_the_docs_example_runs(tmp_path):
    with open(os.path.join(REPO, "docs", "python.md")) as f:
        text = f.read()
    section = text.split("## A complete example", 1)[1]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    code = code.replace('"examples/', '"' + os.path.join(REPO, "examples") + "/")
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(
        [os.path.join(REPO, "python"), os.environ.get("PYTHONPATH", "")]))
    p = subprocess.run([sys.executable, "-W", "ignore", "-c", code], cwd=tmp_path, env=env,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    assert (tmp_path / "out" / "teraeye-py" / "cam.radiance.img").exists()
    assert (tmp_path / "map.thzpm").exists()
    assert "cylinder-A" in p.stdout
