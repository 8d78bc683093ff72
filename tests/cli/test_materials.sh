#!/usr/bin/env bash
# thzmap materials: the list names every entry of data/materials/library.json with its
# source; one entry's description (water's n, k at 1 THz against the Liebe 1991 model
# computed here independently; P.2040 rows; units); usage errors; and scenes using the
# library: P.2040 outside its range refused with exit 2, the JSON path and the range.
# usage: test_materials.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"

# --- the list: every entry, each followed by its source -----------------------------
"$THZMAP" materials >"$work/list" 2>"$work/err" || fail "materials: exit $?: $(cat "$work/err")"
python3 - "$REPO/data/materials/library.json" "$work/list" <<'PY' || fail "the list does not match library.json"
import json, sys
lib = json.load(open(sys.argv[1]))["materials"]
lines = open(sys.argv[2]).read().splitlines()
ok = True
for name, e in lib.items():
    rows = [i for i, l in enumerate(lines) if l.split(" ")[0] == name]
    if len(rows) != 1:
        print(f"entry {name}: {len(rows)} lines"); ok = False; continue
    src = lines[rows[0] + 1].strip()
    if src != "source: " + e["source"]:
        print(f"entry {name}: source line '{src}'"); ok = False
if not lines[0].startswith(f"{len(lib)} materials"):
    print("first line:", lines[0]); ok = False
sys.exit(0 if ok else 1)
PY

# --- one entry: water (Liebe 1991 double Debye at 25 C), computed independently -------
"$THZMAP" materials water --at-thz 0.5,1 >"$work/water" 2>"$work/err" || fail "materials water: exit $?"
python3 - "$work/water" <<'PY' || fail "water's n, k differ from Liebe's model: $(cat "$work/water")"
import cmath, sys
T = 298.15; th = 1 - 300 / T
e0 = 77.66 - 103.3 * th; e1 = 0.0671 * e0; e2 = 3.52 + 7.52 * th
f1 = 20.2 + 146.4 * th + 316 * th ** 2; f2 = 39.8 * f1
rows = {}
for l in open(sys.argv[1]):
    p = l.split()
    if len(p) >= 7 and p[0] in ("0.5", "1"):
        rows[float(p[0])] = [float(x) for x in p[1:7]]
ok = len(rows) == 2
for f, r in rows.items():
    eps = e2 + (e1 - e2) / (1 - 1j * f * 1e3 / f2) + (e0 - e1) / (1 - 1j * f * 1e3 / f1)
    nk = cmath.sqrt(eps)
    alpha = 4 * cmath.pi * nk.imag * f * 1e12 / 299792458.0
    R = abs((nk - 1) / (nk + 1)) ** 2
    # the printed values have 5 significant digits; the library rounds Liebe's numbers to 5
    for got, want in ((r[0], nk.real), (r[1], nk.imag), (r[4], alpha), (r[5], R)):
        if abs(got - want) > 2e-4 * abs(want):
            print(f, got, want); ok = False
sys.exit(0 if ok else 1)
PY
grep -q '^source: H. J. Liebe' "$work/water" || fail "water: no source line"
grep -q 'alpha (1/m)' "$work/water" || fail "water: the attenuation column has no unit"
grep -q '^stated validity: 0.001 to 1 THz' "$work/water" || fail "water: no stated range"
grep -q '^reflection: not part of the entry' "$work/water" || fail "water: no reflection line"
# the stated validity's end is inside it (1 THz unmarked), past it is marked; the list
# gives n and k at 1 THz, as the row of 1 THz (checked against Liebe's model above) does
grep -Eq '^ +1 [^*]*[0-9]$' "$work/water" || fail "water: 1 THz, its validity's end, marked outside"
"$THZMAP" materials water --at-thz 1.5,1000 >"$work/water2" 2>"$work/err" ||
    fail "materials water --at-thz 1.5,1000 (1000 THz: the end of the option's range): exit $?: $(cat "$work/err")"
grep -Eq '^ +1\.5 .* \*$' "$work/water2" || fail "water: 1.5 THz not marked outside its validity"
awk '$1 == "water" { n = $4; k = $5 } END { print n, k }' "$work/list" >"$work/listed"
awk '$1 == "1" { printf "%.4g %.4g\n", $2, $3 }' "$work/water" >"$work/row"
cmp -s "$work/listed" "$work/row" ||
    fail "the list's water (n k: $(cat "$work/listed")) is not its 1 THz row ($(cat "$work/row"))"

"$THZMAP" materials concrete >"$work/concrete" || fail "materials concrete: exit $?"
grep -q '^data: 0.001 to 0.1 THz, 0.11 to 0.33 THz' "$work/concrete" ||
    fail "concrete: P.2040 rows not listed: $(cat "$work/concrete")"
grep -Eq '^ +1 .* \*$' "$work/concrete" || fail "concrete: 1 THz not marked outside the range"
# the footnote says what the stars mark: concrete states no validity, its rows' ranges do
grep -qx '\* outside the ranges the data cover' "$work/concrete" ||
    fail "concrete: the footnote does not name the data's ranges: $(tail -1 "$work/concrete")"
"$THZMAP" materials rdx >"$work/rdx" || fail "materials rdx: exit $?"
grep -qx '\* outside the stated validity' "$work/rdx" ||
    fail "rdx: the footnote does not name the stated validity: $(tail -1 "$work/rdx")"

# --- usage errors ------------------------------------------------------------------
expect_exit() { # expect_exit STATUS PATTERN ARGS...
    local want=$1 pattern=$2
    shift 2
    "$THZMAP" materials "$@" >"$work/out" 2>"$work/err"
    local got=$?
    [[ $got -eq $want ]] || fail "materials $*: exit $got, want $want"
    grep -q -- "$pattern" "$work/err" || fail "materials $*: stderr lacks '$pattern': $(cat "$work/err")"
    [[ -s $work/out ]] && fail "materials $*: printed to stdout on error"
}
expect_exit 2 'no material "unobtainium"' unobtainium
expect_exit 2 "unknown option '--bogus'" --bogus
expect_exit 2 -- '--at-thz: expected' water --at-thz 1,-2
# beyond 1000 THz refused (water printed a row of -nan at 1e308 THz, exit 0); 1000 is finite
expect_exit 2 -- 'at most 1000 THz' water --at-thz 1e308
"$THZMAP" materials water --at-thz 1000 | grep -qi nan && fail "materials water at 1000 THz: NaN"
expect_exit 2 'one material name at most' water ice
"$THZMAP" materials --help | grep -q '^usage: thzmap materials' || fail "materials --help"

# --- scenes with library materials ------------------------------------------------------
scene() { # scene FILE FREQUENCY_THZ MATERIAL_JSON
    cat >"$1" <<JSON
{"format": "thzmap-scene/1", "channels": [{"frequency_thz": $2, "relative_width": 0.01}],
 "materials": {"m": $3},
 "objects": [{"name": "o", "type": "solid", "material": "m", "temperature_k": 300,
              "shape": {"type": "box", "size_m": [1, 1, 1]}}],
 "sensors": [{"name": "c", "position_m": [0, -5, 0], "look_at_m": [0, 0, 0],
              "fov_deg": 40, "resolution": [16, 8]}]}
JSON
}
scene "$work/ok.json" 0.3 '{"library": "skin"}'
"$THZMAP" validate "$work/ok.json" >/dev/null 2>"$work/err" || fail "skin scene: exit $?: $(cat "$work/err")"
scene "$work/far.json" 0.5 '{"library": "wood"}'
"$THZMAP" validate "$work/far.json" >/dev/null 2>"$work/err"
status=$?
[[ $status -eq 2 ]] || fail "wood at 0.5 THz: exit $status, want 2"
grep -q 'far.json: materials.m.library: ITU-R P.2040 gives "wood" only for 0.001 to 100 GHz, 110 to 330 GHz, 100 to 400 GHz, but channel "0.500 THz" (band 490 to 510 GHz' "$work/err" ||
    fail "wood at 0.5 THz: message: $(cat "$work/err")"

# --- an entry of the library that tables n and k (a data directory's library.json): its
#     data range is the table's, printed with what is done beyond it; n and k between the
#     points interpolated linearly (physics.md "Complex indices") ----------------------------
cp -r "$REPO/data" "$work/dt"
python3 - "$work/dt/materials/library.json" <<'PY' || fail "cannot add a tabled entry"
import json, sys
lib = json.load(open(sys.argv[1]))
lib["materials"]["tabled"] = {"description": "an index from a table", "basis": "measured",
                              "source": "test_materials.sh",
                              "refractive_index": [[0.2, 1.5, 0.01], [1, 1.6, 0.03], [2, 2, 0.05]]}
json.dump(lib, open(sys.argv[1], "w"))
PY
THZMAP_DATA_DIR="$work/dt" "$THZMAP" materials tabled --at-thz 0.6 >"$work/tabled" 2>"$work/err" ||
    fail "materials tabled: exit $?: $(cat "$work/err")"
grep -qx 'data: 0.2 to 2 THz (end values held beyond the ends)' "$work/tabled" ||
    fail "tabled: no data range: $(cat "$work/tabled")"
awk '$1 == "0.6" && $2 == 1.55 && $3 == 0.02 { ok = 1 } END { exit !ok }' "$work/tabled" ||
    fail "tabled: n, k at 0.6 THz are not 1.55, 0.02: $(cat "$work/tabled")"

# --- an entry whose valid_thz is empty (from = to) or runs backwards: the library is
#     refused at load, naming the key (an empty range would have made every channel
#     "leave" it, and thz_library_in_range hold at one frequency only) -------------------
for range in "[0.5, 0.5]" "[0.6, 0.5]"; do
    rm -rf "$work/dv" && cp -r "$REPO/data" "$work/dv"
    python3 - "$work/dv/materials/library.json" "$range" <<'PY' || fail "cannot set valid_thz"
import json, sys
lib = json.load(open(sys.argv[1]))
lib["materials"]["water"]["valid_thz"] = json.loads(sys.argv[2])
json.dump(lib, open(sys.argv[1], "w"))
PY
    THZMAP_DATA_DIR="$work/dv" "$THZMAP" materials >"$work/out" 2>"$work/err"
    rc=$?
    [[ $rc -eq 1 ]] && grep -q 'library.json: materials.water.valid_thz: expected \[from_thz, to_thz\] with from < to' "$work/err" ||
        fail "valid_thz $range: exit $rc: $(cat "$work/err")"
done

# --- a data directory whose JSON files are a FIFO or a directory: refused, no hang; a
#     damaged installation is an I/O error (exit 1), not bad input -------------------------
cp -r "$REPO/data" "$work/dd"
rm "$work/dd/materials/library.json"
mkfifo "$work/dd/materials/library.json"
THZMAP_DATA_DIR="$work/dd" timeout 30 "$THZMAP" materials >"$work/out" 2>"$work/err"
rc=$?
[[ $rc -eq 1 ]] || fail "library.json a FIFO: exit $rc (124: it hung), expected 1"
grep -q 'library.json.*FIFO' "$work/err" || fail "library.json a FIFO: message: $(cat "$work/err")"
rm "$work/dd/materials/library.json"
mkdir "$work/dd/materials/library.json"
THZMAP_DATA_DIR="$work/dd" timeout 30 "$THZMAP" materials >"$work/out" 2>"$work/err"
rc=$?
[[ $rc -eq 1 ]] && grep -q 'library.json.*directory' "$work/err" ||
    fail "library.json a directory: exit $rc: $(cat "$work/err")"

finish_counted "materials: all checks passed"
