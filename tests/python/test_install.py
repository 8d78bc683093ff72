"""`cmake --install` puts the package where Debian's python3 finds it, and the installed
package loads the installed library (not the build tree's): installed into a fresh
prefix, imported by a python3 started elsewhere with only that prefix on its path."""
import os
import subprocess
import sys
import textwrap

import pytest
from conftest import PLATE


def test_installed_package_uses_the_installed_library(tmp_path):
    build = os.environ.get("THZMAP_BUILD_DIR")
    if not build:
        pytest.fail("THZMAP_BUILD_DIR is not set (CTest sets it to the build directory)")
    prefix = tmp_path / "prefix"
    p = subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)],
                       capture_output=True, text=True)
    assert p.returncode == 0, p.stdout + p.stderr
    libs = list(prefix.glob("lib*/**/libthzmap.so*"))
    assert libs, "cmake --install did not install libthzmap (issue 11's install rules)"
    site = prefix / "lib" / "python3" / "dist-packages"
    assert (site / "thzmap" / "__init__.py").exists()
    assert (site / "thzmap" / "_installed.py").exists()

    script = textwrap.dedent(f"""
        import thzmap
        print(thzmap.library_path)
        scene = thzmap.load_scene({os.path.join(PLATE, "scene.json")!r})
        r = thzmap.simulate(scene, photons=500, integrator="path", threads=1)
        print(r.image("cam").radiance.shape)
    """)
    env = {k: v for k, v in os.environ.items()
           if k not in ("THZMAP_LIBRARY", "PYTHONPATH", "LD_LIBRARY_PATH")}
    env["PYTHONPATH"] = str(site)
    p = subprocess.run([sys.executable, "-W", "ignore", "-c", script], cwd=tmp_path,
                       env=env, capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    library, shape = p.stdout.splitlines()
    assert library.startswith(str(prefix) + os.sep), library
    assert shape == "(64, 64, 1)"
