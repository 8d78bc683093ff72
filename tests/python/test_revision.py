"""thzmap.revision names the source revision of the library the package loaded, as
`thzmap --version` prints it and as summary.json's thzmap_revision records it: for a build
of this git checkout its commit ("-dirty" or not: the tree may change after the build).
(Before, the package had __version__, "0.1.0", alone, which names no commit.)"""
import os
import re
import subprocess

import pytest
import thzmap
from conftest import REPO, run_cli


def _checkout_commit():
    """This repository's HEAD, or None when it is not the top of a git checkout."""
    git = ["git", "-c", f"safe.directory={REPO}", "-C", REPO]
    try:
        top = subprocess.run(git + ["rev-parse", "--show-toplevel"], capture_output=True,
                             text=True)
        head = subprocess.run(git + ["rev-parse", "HEAD"], capture_output=True, text=True)
    except FileNotFoundError:
        return None
    if top.returncode or head.returncode:
        return None
    if os.path.realpath(top.stdout.strip()) != os.path.realpath(REPO):
        return None
    return head.stdout.strip()


def test_revision_is_the_programs_and_the_summarys(thzmap_binary, tiny_dir):
    line = run_cli(thzmap_binary, "--version").stdout.strip()
    assert line == f"thzmap {thzmap.__version__} (revision {thzmap.revision})"
    result = thzmap.simulate(thzmap.load_scene(tiny_dir / "scene.json"), integrator="path",
                             threads=1)
    assert result.summary["thzmap_revision"] == thzmap.revision
    assert result.summary["thzmap_version"] == thzmap.__version__


def test_revision_is_the_checkouts_commit():
    if os.environ.get("THZMAP_REVISION_GIVEN"):
        pytest.skip("the build was given its revision (-DTHZ_REVISION)")
    commit = _checkout_commit()
    if commit is None:
        assert thzmap.revision == "unknown"
        pytest.skip(f"{REPO} is not a git checkout")
    assert re.fullmatch(r"[0-9a-f]{40}", commit)
    assert thzmap.revision in (commit, commit + "-dirty"), \
        f"the library's revision {thzmap.revision} is not the checkout's {commit} (rebuild?)"
