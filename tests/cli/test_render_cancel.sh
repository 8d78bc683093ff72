#!/usr/bin/env bash
# A 4000 x 4000 render with oversampling 8 (issue 20; docs/reliability.md) prints its
# up-front estimate (time and memory) before it starts, and stops within 1 s of SIGTERM,
# at any moment: 1.0, 2.0 and 3.0 s after the start (the images' first touch, the truth
# pass and the pixel loop, whichever runs then). It must exit 143 (128 + SIGTERM) and
# leave nothing: no OUTDIR, nothing beside it.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
# the stop limit: 1 s; the sanitizer build sets THZ_CANCEL_LIMIT_MS=2000 (CMakeLists.txt)
limit_ms=${THZ_CANCEL_LIMIT_MS:-1000}

cat > "$work/scene.json" <<JSON
{
  "format": "thzmap-scene/1",
  "name": "render-cancel",
  "channels": [{"frequency_thz": 0.35, "relative_width": 0.05}],
$(plate_in_room)
  "sensors": [{"name": "big", "position_m": [0, -0.9, 0], "look_at_m": [0, 0, 0],
               "fov_deg": 60, "resolution": [4000, 4000], "oversampling": 8}],
  "render": {"integrator": "path", "paths_per_sample": 1}
}
JSON

for at in 1.0 2.0 3.0; do
  rm -rf "$work/run" && mkdir "$work/run"
  "$THZMAP" render "$work/scene.json" -o "$work/run/out" --threads 2 2>"$work/err" &
  pid=$!
  sleep "$at"
  kill -0 "$pid" 2>/dev/null || { fail "SIGTERM at $at s: the render ended by itself"; wait "$pid"; continue; }
  t0=$(date +%s%N)
  kill -TERM "$pid"
  wait "$pid"
  rc=$?
  ms=$(( ($(date +%s%N) - t0) / 1000000 ))
  echo "SIGTERM at $at s: exit $rc after $ms ms"
  [ "$rc" = 143 ] || fail "SIGTERM at $at s: exit $rc, expected 143"
  [ "$ms" -le "$limit_ms" ] || fail "SIGTERM at $at s: took $ms ms to stop, more than $limit_ms ms"
  grep -q 'estimate: .* s .*memory .* GiB' "$work/err" ||
    fail "SIGTERM at $at s: no up-front estimate: $(tr '\r' '\n' < "$work/err" | head -3)"
  left=$(ls -A "$work/run")
  [ -z "$left" ] || fail "SIGTERM at $at s: left $left"
done
finish "render cancel: all checks passed"
