#!/usr/bin/env bash
# Under an address-space limit (`ulimit -v`, RLIMIT_AS, which some clusters set) a run
# fails up front with thzmap's own message naming the limit, or runs; never late, never
# with a library's message. Until 2026-12-08:
# - the memory check compared the resident memory (18 MB at the check of a render) with
#   the limit, where the address space counts (291 MB mapped: Embree's 128 MiB pool,
#   thread stacks, malloc arenas). A render of a 10^6-photon map under ulimit -v 250000
#   passed it and failed reading the map ("out of memory for 1304207 photons", exit 1).
#   Now it is refused (exit 2) naming the limit and the limit that would do, and under
#   that limit it runs;
# - libgomp ended `validate` of a 1.3 M-triangle mesh under ulimit -v 250000 with its own
#   "Thread creation failed: Resource temporarily unavailable" (exit 1): the mesh had
#   taken the room its first thread's stack needed. The threads now start before any work,
#   as many as fit (OMP_STACKSIZE=200M under ulimit -v 400000 ended `simulate` so too;
#   now it runs on fewer threads, with a warning, and its images are the same bytes).
# The sanitizer builds reserve terabytes of address space: they cannot run under a limit.
# usage: test_address_space_limit.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
if grep -q '^THZ_SANITIZE:BOOL=ON' "$(dirname "$THZMAP")/CMakeCache.txt" 2>/dev/null; then
    echo "skipped: a sanitizer build (its shadow memory cannot run under ulimit -v)"
    exit 0
fi
# limited KIB ARGS...: thzmap ARGS under ulimit -v KIB; stderr in $work/err, exit in $rc
limited() {
    local kib=$1
    shift
    (ulimit -v "$kib" && exec "$THZMAP" "$@") > /dev/null 2> "$work/err"
    rc=$?
}

cp -r "$REPO/examples/teraeye" "$work/scene"
python3 - "$work" <<'PY' || exit 1
import json, math, struct, sys
work = sys.argv[1]
path = f"{work}/scene/scene.json"
d = json.load(open(path))
d["channels"] = {"from_thz": 0.3, "to_thz": 1.2, "count": 2, "relative_width": 0.01}
d["photons"]["per_channel"] = 1000000
d["sensors"][0]["resolution"] = [16, 16]
d["render"] = {"integrator": "photon-map"}
json.dump(d, open(path, "w"))
d["photons"]["per_channel"] = 20000
d["sensors"][0]["resolution"] = [8, 8]
json.dump(d, open(f"{work}/scene/small.json", "w"))
# a UV sphere of 810 x 810 quads: 1 310 580 triangles, binary PLY
n = m = 810
r = 0.2
v = bytearray()
for i in range(1, n):
    th = math.pi * i / n
    for j in range(m):
        ph = 2 * math.pi * j / m
        v += struct.pack("<3f", r * math.sin(th) * math.cos(ph), r * math.sin(th) * math.sin(ph),
                         r * math.cos(th))
top, bot = (n - 1) * m, (n - 1) * m + 1
v += struct.pack("<6f", 0, 0, r, 0, 0, -r)
tri = struct.Struct("<B3i")
idx = lambda i, j: (i - 1) * m + j % m
f = [tri.pack(3, top, idx(1, j + 1), idx(1, j)) for j in range(m)]
f += [tri.pack(3, bot, idx(n - 1, j), idx(n - 1, j + 1)) for j in range(m)]
for i in range(1, n - 1):
    for j in range(m):
        a, b, c, e = idx(i, j), idx(i, j + 1), idx(i + 1, j + 1), idx(i + 1, j)
        f += [tri.pack(3, a, b, c), tri.pack(3, a, c, e)]
with open(f"{work}/sphere.ply", "wb") as out:
    out.write(f"ply\nformat binary_little_endian 1.0\nelement vertex {len(v) // 12}\n"
              "property float x\nproperty float y\nproperty float z\n"
              f"element face {len(f)}\nproperty list uchar int vertex_indices\nend_header\n"
              .encode())
    out.write(v)
    out.write(b"".join(f))
d["objects"].append({"name": "ball", "type": "solid", "material": "wall",
                     "temperature_k": 300, "shape": {"type": "mesh", "file": "../sphere.ply"},
                     "transform": {"translate_m": [0, 1.0, 0.5]}})
json.dump(d, open(f"{work}/scene/mesh.json", "w"))
PY
S=$work/scene/scene.json
"$THZMAP" simulate "$S" -o "$work/sim" --save-photon-map --quiet --threads 2 || { echo "FAIL: simulate"; exit 1; }

# --- 1. a render of a 10^6-photon map: refused up front, the limit named --------------
limited 250000 render "$S" -o "$work/r" --photon-map "$work/sim/photon-map.thzpm" --threads 2 --quiet
cp "$work/err" "$work/r250.err"
if grep -q 'would need' "$work/err"; then
    [ $rc -eq 2 ] || fail "render under ulimit -v 250000: refused with exit $rc, not 2"
    expect_line "$work/err" 'of address space .* but ulimit -v limits this process to 250000 KiB \(244 MiB\)'
    expect_line "$work/err" 'render from a map of fewer photons'
    enough=$(sed -n 's/.*(ulimit -v \([0-9]*\) or more would do).*/\1/p' "$work/err")
    if [[ ! $enough =~ ^[0-9]+$ ]]; then
        fail "the refusal names no limit that would do: $(cat "$work/err")"
    else
        limited "$enough" render "$S" -o "$work/r" --photon-map "$work/sim/photon-map.thzpm" \
            --threads 2 --quiet
        [ $rc -eq 0 ] || fail "under ulimit -v $enough, the limit the refusal named: exit $rc: $(cat "$work/err")"
        echo "render of a 10^6-photon map refused under ulimit -v 250000 KiB; runs under $enough"
    fi
else
    # a machine whose libraries leave less room: Embree's pool fails, but named so
    [ $rc -eq 1 ] && grep -q 'out of memory (the address space is limited: ulimit -v 250000 KiB)$' \
        "$work/err" || fail "render under ulimit -v 250000: exit $rc: $(cat "$work/err")"
fi
[ -z "$(ls -A "$work/r" 2>/dev/null)" ] || [ -f "$work/r/summary.json" ] ||
    fail "a refused render left files in OUTDIR"
# and no limit from 230000 to 330000 KiB fails late (reading the map) or unnamed
for kib in 230000 260000 290000 330000; do
    limited $kib render "$S" -o "$work/s$kib" --photon-map "$work/sim/photon-map.thzpm" \
        --threads 2 --quiet
    case $rc in
    0) ;;
    2) grep -q "ulimit -v limits this process to $kib KiB" "$work/err" ||
        fail "ulimit -v $kib: exit 2 without the limit: $(cat "$work/err")" ;;
    *) grep -q "(the address space is limited: ulimit -v $kib KiB)$" "$work/err" &&
        ! grep -q 'cannot read photon map' "$work/err" ||
        fail "ulimit -v $kib: exit $rc, late or unnamed: $(cat "$work/err")" ;;
    esac
done

# --- 2. threads: libgomp never ends the process --------------------------------------
limited 250000 validate "$work/scene/mesh.json"
if grep -qi 'libgomp\|thread creation' "$work/err"; then
    fail "validate of 1.3 M triangles under ulimit -v 250000: libgomp's message: $(cat "$work/err")"
elif [ $rc -ne 0 ] && ! grep -q '(the address space is limited: ulimit -v 250000 KiB)$' "$work/err"; then
    fail "validate of 1.3 M triangles under ulimit -v 250000: exit $rc: $(cat "$work/err")"
fi
"$THZMAP" simulate "$work/scene/small.json" -o "$work/t0" --quiet --threads 2 2> "$work/err" ||
    fail "simulate without a limit: $(cat "$work/err")"
! grep -q 'address space' "$work/err" || fail "a warning without a limit: $(cat "$work/err")"
export OMP_STACKSIZE=200M
limited 400000 simulate "$work/scene/small.json" -o "$work/t1" --quiet --threads 2
unset OMP_STACKSIZE
if [ $rc -ne 0 ]; then
    fail "simulate with OMP_STACKSIZE=200M under ulimit -v 400000: exit $rc: $(cat "$work/err")"
else
    expect_line "$work/err" '^thzmap simulate: warning: the address space is limited \(ulimit -v 400000 KiB\).*running with 1 thread, as many as fit'
    cmp -s "$work/t0/cam.radiance.img" "$work/t1/cam.radiance.img" ||
        fail "the images on the threads that fit differ from those on 2"
fi
[ $fails -eq 0 ] && echo "ok"
exit $((fails > 0))
