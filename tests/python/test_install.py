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
    site = prefix / os.environ.get("THZMAP_PYTHON_INSTALL_DIR", "lib/python3/dist-packages")
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


def _import_in_fresh_python(pythonpath, cwd, library=None):
    env = {k: v for k, v in os.environ.items()
           if k not in ("THZMAP_LIBRARY", "PYTHONPATH", "LD_LIBRARY_PATH")}
    env["PYTHONPATH"] = str(pythonpath)
    if library is not None:
        env["THZMAP_LIBRARY"] = library
    return subprocess.run([sys.executable, "-c", "import thzmap; print(thzmap.library_path)"],
                          cwd=cwd, env=env, capture_output=True, text=True)


def test_from_a_repository_the_package_finds_its_build_tree(tmp_path):
    """PYTHONPATH=python is all a built repository needs: the package loads
    build/libthzmap.so of the repository it sits in (a copy of the layout here, with
    this build's library, so that the test holds whatever the build directory)."""
    built = os.environ.get("THZMAP_LIBRARY")
    if not built:
        pytest.fail("THZMAP_LIBRARY is not set (CTest sets it to the built library)")
    import shutil
    from conftest import REPO
    shutil.copytree(os.path.join(REPO, "python", "thzmap"), tmp_path / "python" / "thzmap",
                    ignore=shutil.ignore_patterns("__pycache__", "_installed.py"))
    (tmp_path / "build").mkdir()
    os.symlink(built, tmp_path / "build" / "libthzmap.so")
    p = _import_in_fresh_python(tmp_path / "python", cwd="/")
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip() == str(tmp_path / "build" / "libthzmap.so")


def test_an_explicit_library_that_is_missing_is_an_import_error(tmp_path):
    from conftest import REPO
    p = _import_in_fresh_python(os.path.join(REPO, "python"), cwd=tmp_path,
                                library=str(tmp_path / "nope.so"))
    assert p.returncode != 0
    assert "ImportError" in p.stderr and "THZMAP_LIBRARY" in p.stderr
