#!/usr/bin/env bash
# The library's public surface, three ways that must agree: the THZ_API declarations
# in include/thzmap/*.h, the dynamic symbols libthzmap.so exports (exactly those: a
# named OpenMP critical section once exported a lock of its own), and docs/api.md's
# function list (every function, nothing else). docs/api.md's complete example is
# examples/api/simulate.c as it stands. And every public header compiles on its own, as
# C17 and as C++17, with the warnings as errors.
# usage: test_api_surface.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
build=$(cd "$(dirname "$THZMAP")" && pwd)

lib=$build/libthzmap.so
[[ -f $lib ]] || fail "no $lib"

# --- declared, exported, documented ----------------------------------------------------------
/usr/bin/python3 - "$REPO" >"$work/declared" <<'PY' || fail "could not read the headers"
import glob, re, sys
text = "".join(open(h).read() for h in sorted(glob.glob(sys.argv[1] + "/include/thzmap/*.h")))
text = re.sub(r"/\*.*?\*/", " ", text, flags=re.S)
for name in sorted(set(re.findall(r"\bTHZ_API\b[^;{]*?\b(thz_\w+)\s*\(", text))):
    print(name)
PY
[[ $(wc -l <"$work/declared") -gt 100 ]] || fail "only $(wc -l <"$work/declared") THZ_API functions found in include/thzmap/"

nm -D --defined-only "$lib" | awk '{print $3}' | sort -u >"$work/exported"
comm -13 "$work/declared" "$work/exported" >"$work/extra"
comm -23 "$work/declared" "$work/exported" >"$work/missing"
[[ -s $work/extra ]] && fail "libthzmap.so exports symbols no header declares: $(tr '\n' ' ' <"$work/extra")"
[[ -s $work/missing ]] && fail "declared but not exported: $(tr '\n' ' ' <"$work/missing")"

# docs/api.md's table: "thz_photons_fire, _fire_channel": a name starting with "_" continues
# a prefix of the last full name (thz_photons + _fire_channel)
/usr/bin/python3 - "$REPO/docs/api.md" "$work/declared" >"$work/docs.check" <<'PY'
import re, sys
doc = open(sys.argv[1]).read()
declared = set(open(sys.argv[2]).read().split())
table = doc.split("## Function list", 1)[1].split("\n## ", 1)[0]
listed, bad = set(), []
for row in table.splitlines():
    cells = row.split("|")
    if len(cells) < 3:
        continue
    last = None
    for name in re.findall(r"`([A-Za-z_]\w*)`", cells[2]):
        if name.startswith("thz_"):
            last = name
            full = name
        elif name.startswith("_") and last:
            parts = last.split("_")
            full = next((p + name for p in ("_".join(parts[:k]) for k in range(len(parts), 1, -1))
                         if p + name in declared), None)
        else:
            full = None
        if full in declared:
            listed.add(full)
        else:
            bad.append(name if full is None else full)
for name in sorted(declared - listed):
    print("not in docs/api.md's function list:", name)
for name in bad:
    print("docs/api.md's function list names no declared function:", name)
PY
[[ -s $work/docs.check ]] && fail "$(cat "$work/docs.check")"

# --- docs/api.md's complete example is examples/api/simulate.c, which test_install.sh builds
# and runs: a listing edited on the page alone would show a program no test compiles
/usr/bin/python3 - "$REPO" <<'PY' || fail "docs/api.md's complete example is not examples/api/simulate.c"
import re, sys
doc = open(sys.argv[1] + "/docs/api.md").read()
m = re.search(r"`examples/api/simulate.c`[^\n]*\n\n```c\n(.*?)^```", doc, re.M | re.S)
if not m:
    sys.exit("docs/api.md: no listing of examples/api/simulate.c under 'A complete example'")
if m.group(1) != open(sys.argv[1] + "/examples/api/simulate.c").read():
    sys.exit("docs/api.md's listing differs from examples/api/simulate.c")
PY

# --- each header alone ---------------------------------------------------------------------
for h in "$REPO"/include/thzmap/*.h; do
    name=$(basename "$h")
    printf '#include <thzmap/%s>\nint thz_surface_test_unused;\n' "$name" >"$work/alone.c"
    cc -std=c17 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I"$REPO/include" "$work/alone.c" \
        >"$work/cc.out" 2>&1 || fail "<thzmap/$name> alone does not compile as C17: $(head -c 600 "$work/cc.out")"
    c++ -std=c++17 -Wall -Wextra -Wpedantic -Werror -fsyntax-only -I"$REPO/include" -x c++ \
        "$work/alone.c" >"$work/cxx.out" 2>&1 ||
        fail "<thzmap/$name> alone does not compile as C++17: $(head -c 600 "$work/cxx.out")"
done

finish_counted "ok: $(wc -l <"$work/declared") functions declared, exported and listed; every header compiles alone"
