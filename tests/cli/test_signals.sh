#!/usr/bin/env bash
# Signals other than Ctrl-C (test_render_cancel.sh and the commit-kill tests cover SIGINT
# and SIGKILL): a reader of the progress that leaves (SIGPIPE) does not stop the run
# mid-commit; a closed terminal (SIGHUP) stops it as Ctrl-C does, exit 128 + 1, nothing
# written and nothing left beside OUTDIR, but not when SIGHUP was ignored at start (nohup); SIGINT to the program alone while it draws its
# figures stops the drawing at once. `atmosphere --plot` stopped early keeps an
# existing figure (it was emptied before the work).
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
scene=$REPO/examples/plate-in-box/scene.json

# SIGPIPE: the progress goes to `head -1`, which exits after the first line
"$THZMAP" simulate "$scene" -o "$work/pipe" --photons 300000 --integrator photon-map 2>&1 |
    head -n 1 > /dev/null
rc=${PIPESTATUS[0]}
[ "$rc" = 0 ] || fail "simulate into a closed pipe: exit $rc, expected 0"
[ -s "$work/pipe/summary.json" ] || fail "simulate into a closed pipe: no results"
[ -z "$(leftovers)" ] || fail "simulate into a closed pipe left: $(leftovers)"

# SIGHUP during the photon phase
"$THZMAP" simulate "$scene" -o "$work/hup" --photons 50000000 --integrator photon-map \
    2> "$work/hup.err" &
pid=$!
for _ in $(seq 600); do # the estimate's line: the run (and its handler) has begun
    grep -q "estimate:" "$work/hup.err" 2>/dev/null && break
    sleep 0.1
done
sleep 0.3
kill -HUP $pid
wait $pid
rc=$?
[ "$rc" = 129 ] || fail "SIGHUP: exit $rc, expected 129"
grep -q "interrupted; no results written" "$work/hup.err" ||
    fail "SIGHUP: no message: $(tail -n 1 "$work/hup.err")"
[ ! -e "$work/hup" ] || fail "SIGHUP: OUTDIR written"
[ -z "$(leftovers)" ] || fail "SIGHUP left: $(leftovers)"

# SIGHUP ignored when thzmap starts (`nohup`) stays ignored: the run goes on to its end
# (closing the terminal of a nohup run stopped it)
(trap '' HUP; exec "$THZMAP" simulate "$scene" -o "$work/nohup" --photons 3000000 \
    --integrator photon-map 2> "$work/nohup.err") &
pid=$!
for _ in $(seq 600); do
    grep -q "estimate:" "$work/nohup.err" 2>/dev/null && break
    sleep 0.1
done
sleep 0.3
kill -HUP $pid 2>/dev/null || fail "nohup: the run ended before the test sent SIGHUP (too short)"
wait $pid
rc=$?
[ "$rc" = 0 ] || fail "SIGHUP ignored at start: exit $rc, expected 0: $(tail -n 1 "$work/nohup.err")"
[ -s "$work/nohup/summary.json" ] || fail "SIGHUP ignored at start: no results"

# SIGINT to the program alone (`kill -INT`, as a batch system may send it; a terminal's
# Ctrl-C also ends the figure children) while hundreds of figures are drawn: it stops
# drawing and exits 130 at once, not when every figure is done
/usr/bin/python3 - "$scene" "$work/many.json" <<'PY'
import json, os, sys
sc = json.load(open(sys.argv[1]))
base = os.path.dirname(os.path.abspath(sys.argv[1]))
for m in sc["materials"].values():
    for k, v in list(m.items()):
        if k == "file" or k.endswith("_file"):
            m[k] = os.path.join(base, v)
sc["channels"] = {"from_thz": 0.3, "to_thz": 1.2, "count": 900, "relative_width": 0.01}
sc["sensors"][0]["resolution"] = [16, 12]
sc["render"] = {"integrator": "path", "paths_per_sample": 1}
json.dump(sc, open(sys.argv[2], "w"))
PY
"$THZMAP" simulate "$work/many.json" -o "$work/many" --threads 2 2> "$work/many.err" &
pid=$!
for _ in $(seq 1200); do # a figure child: the drawing has begun
    kill -0 $pid 2>/dev/null || break
    [ -n "$(pgrep -P $pid)" ] && grep -q "channel 900/900, render" "$work/many.err" && break
    sleep 0.05
done
t0=$(date +%s%N)
kill -INT $pid
wait $pid
rc=$?
ms=$((($(date +%s%N) - t0) / 1000000))
[ "$rc" = 130 ] || fail "SIGINT while drawing: exit $rc, expected 130: $(tail -n 1 "$work/many.err")"
[ "$ms" -lt 1500 ] || fail "SIGINT while drawing: exit after $ms ms"
[ ! -e "$work/many" ] || fail "SIGINT while drawing: OUTDIR written"
[ -z "$(leftovers)" ] || fail "SIGINT while drawing left: $(leftovers)"
sleep 0.2
[ -z "$(pgrep -P $pid)" ] || fail "SIGINT while drawing: figure children left running"

# SIGTERM to bands after its last render, while it searches and writes: its progress
# callback, which alone carried a stop, is called no more. The stop was ignored: bands
# wrote its results and ended with status 0.
"$THZMAP" bands "$REPO/tests/inputs/batch/scene.json" -o "$work/bands" --count 5 \
    --from-thz 0.1 --to-thz 1.5 --step-ghz 20 --paths 1 2> "$work/bands.err" &
pid=$!
for _ in $(seq 1200); do
    grep -q "render 4/4" "$work/bands.err" 2>/dev/null && break
    sleep 0.02
done
kill -TERM $pid
wait $pid
rc=$?
[ "$rc" = 143 ] || fail "SIGTERM to bands after its renders: exit $rc, expected 143"
grep -q "^thzmap bands: interrupted" "$work/bands.err" ||
    fail "SIGTERM to bands after its renders: no message: $(tail -n 1 "$work/bands.err")"
[ -z "$(leftovers)" ] || fail "SIGTERM to bands left: $(leftovers)"
if [ -e "$work/bands" ]; then # only when the stop came while it wrote: then whole
    grep -q "results in .* are complete" "$work/bands.err" ||
        fail "SIGTERM to bands: OUTDIR written, yet the message says $(tail -n 1 "$work/bands.err")"
    [ -s "$work/bands/bands.json" ] || fail "SIGTERM to bands: OUTDIR without bands.json"
fi

# SIGTERM while simulate commits (its last check for a stop already made): the commit,
# slowed by strace (200 ms per link, rename and unlink), goes on and the results are whole;
# the process still ends by the signal. It ended with status 0, saying nothing.
if command -v strace > /dev/null; then
    "$THZMAP" simulate "$scene" -o "$work/commit" --photons 20000 --integrator photon-map \
        -q 2> /dev/null || fail "simulate into commit/: exit status $?"
    strace -f -qq -o /dev/null -e trace=renameat2,linkat,link,unlinkat,unlink \
        -e inject=renameat2,linkat,link,unlinkat,unlink:delay_enter=200000 \
        "$THZMAP" simulate "$scene" -o "$work/commit" --photons 20000 --seed 2 \
        --integrator photon-map -q 2> "$work/commit.err" &
    tracer=$!
    for _ in $(seq 1200); do # summary.json staged: the last check is made right after it
        compgen -G "$work/.thzmap-*-stage-*/summary.json" > /dev/null && break
        sleep 0.02
    done
    sleep 0.1
    kill -TERM "$(pgrep -P $tracer)"
    wait $tracer
    rc=$?
    [ "$rc" = 143 ] || fail "SIGTERM while committing: exit $rc, expected 143"
    grep -q "interrupted; the results in .* are complete" "$work/commit.err" ||
        fail "SIGTERM while committing: $(tail -n 1 "$work/commit.err")"
    grep -q '"seed": 2' "$work/commit/summary.json" ||
        fail "SIGTERM while committing: OUTDIR does not hold the committed run"
    [ -z "$(leftovers)" ] || fail "SIGTERM while committing left: $(leftovers)"
fi

# atmosphere --plot into a closed pipe: the figure there stays as it was
if "$THZMAP" atmosphere --from-thz 0.1 --to-thz 1 --step-ghz 10 --plot "$work/atm.png" \
    > /dev/null 2>&1; then
    size=$(stat -c %s "$work/atm.png")
    "$THZMAP" atmosphere --from-thz 0.1 --to-thz 1 --step-ghz 0.1 --plot "$work/atm.png" |
        head -n 1 > /dev/null
    [ "$(stat -c %s "$work/atm.png")" = "$size" ] ||
        fail "atmosphere --plot stopped early changed the figure ($size bytes before)"
fi

finish "signals: all passed"
