#!/usr/bin/env bash
# simulate --save-photon-map --ply-max-points N writes a PLY with exactly N points when
# more photons were stored, and refuses a cap of 0.
set -u
thzmap=$1
repo=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail() { echo "FAIL: $*"; exit 1; }

"$thzmap" simulate "$repo/examples/plate-in-box/scene.json" -o "$tmp/out" --integrator photon-map --photons 2000 \
    --save-photon-map --ply-max-points 100 --quiet || fail "simulate exited $?"
header=$(head -c 400 "$tmp/out/photon-map.ply" | tr -d '\0' | sed -n '1,/end_header/p')
grep -q '^format binary_little_endian 1.0' <<<"$header" || fail "not a binary LE PLY: $header"
grep -q '^element vertex 100$' <<<"$header" || fail "expected 100 points: $header"
stored=$(/usr/bin/python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['channels'][0]['photons_stored'])" "$tmp/out/summary.json")
[ "$stored" -gt 100 ] || fail "only $stored photons stored: the cap was not exercised"

"$thzmap" simulate "$repo/examples/plate-in-box/scene.json" -o "$tmp/out2" \
    --save-photon-map --ply-max-points 0 --quiet 2>"$tmp/err"
status=$?
[ $status -eq 2 ] || fail "--ply-max-points 0: exit $status, expected 2"
grep -q -- "--ply-max-points" "$tmp/err" || fail "message does not name the option: $(cat "$tmp/err")"
[ ! -e "$tmp/out2" ] || [ -z "$(ls -A "$tmp/out2")" ] || fail "a refused run wrote files"
echo "1 passed, 0 failed"
