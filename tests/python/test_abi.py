"""The ctypes declarations of python/thzmap/_lib.py match include/thzmap/: a C program
compiled against the headers prints each structure's size and each field's offset, and
the values of the enums the package uses. A header change not made in _lib.py fails
here instead of corrupting memory."""
import ctypes
import os
import shutil
import subprocess

import pytest
from conftest import REPO
from thzmap import _lib, optics, sequence

ENUMS = {"THZ_OK": _lib.OK, "THZ_ERR_INPUT": _lib.ERR_INPUT, "THZ_ERR_IO": _lib.ERR_IO,
         "THZ_ERR_NOMEM": _lib.ERR_NOMEM, "THZ_ERR_LIMIT": _lib.ERR_LIMIT,
         "THZ_ERR_CANCELLED": _lib.ERR_CANCELLED, "THZ_ERR_INTERNAL": _lib.ERR_INTERNAL,
         "THZ_PLANE_RADIANCE": _lib.PLANE_RADIANCE,
         "THZ_PLANE_RADIANCE_STDERR": _lib.PLANE_RADIANCE_STDERR,
         "THZ_PLANE_POWER": _lib.PLANE_POWER,
         "THZ_PLANE_BRIGHTNESS_TEMPERATURE": _lib.PLANE_BRIGHTNESS_TEMPERATURE,
         "THZ_PLANE_NORMALIZED": _lib.PLANE_NORMALIZED,
         "THZ_PLANE_TEMPERATURE": _lib.PLANE_TEMPERATURE,
         "THZ_PLANE_DISTANCE": _lib.PLANE_DISTANCE, "THZ_PLANE_OBJECT_ID": _lib.PLANE_OBJECT_ID,
         "THZ_PLANE_VISUAL_RGB": _lib.PLANE_VISUAL_RGB,
         "THZ_PLANE_MEASURED_RADIANCE": _lib.PLANE_MEASURED_RADIANCE,
         "THZ_PLANE_MEASURED_BRIGHTNESS_TEMPERATURE":
             _lib.PLANE_MEASURED_BRIGHTNESS_TEMPERATURE,
         **{f"THZ_FILE_{name.upper().replace('-', '_')}": value
            for value, name in _lib.FILE_KINDS.items()},
         **{f"THZ_HUMIDITY_{name.upper()}": value
            for name, value in optics.HUMIDITY_KINDS.items()}}


def expected():
    out = {}
    for cname, struct in {**_lib.STRUCTS, **sequence.STRUCTS, **optics.STRUCTS}.items():
        out[f"sizeof {cname}"] = ctypes.sizeof(struct)
        for field, _ in struct._fields_:
            out[f"offsetof {cname}.{field}"] = getattr(struct, field).offset
    out.update({f"enum {k}": v for k, v in ENUMS.items()})
    return out


def test_structures_and_enums_match_the_headers(tmp_path):
    cc = os.environ.get("THZMAP_CC") or shutil.which("cc")
    if not cc:
        pytest.fail("no C compiler (set THZMAP_CC)")
    lines = ["#include <stddef.h>", "#include <stdio.h>", "#include <thzmap/thzmap.h>",
             "int main(void) {"]
    for key in expected():
        kind, what = key.split(" ", 1)
        if kind == "sizeof":
            expr = f"sizeof({what})"
        elif kind == "offsetof":
            struct, field = what.split(".")
            expr = f"offsetof({struct}, {field})"
        else:
            expr = f"(size_t){what}"
        lines.append(f'    printf("%s %zu\\n", "{key}", (size_t)({expr}));')
    lines += ["    return 0;", "}"]
    src = tmp_path / "abi.c"
    src.write_text("\n".join(lines) + "\n")
    exe = tmp_path / "abi"
    subprocess.run([cc, "-std=c17", "-I", os.path.join(REPO, "include"), str(src), "-o",
                    str(exe)], check=True)
    got = {}
    for line in subprocess.run([str(exe)], check=True, capture_output=True,
                               text=True).stdout.splitlines():
        key, value = line.rsplit(" ", 1)
        got[key] = int(value)
    assert got == expected()
