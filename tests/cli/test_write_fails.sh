#!/usr/bin/env bash
# A write that fails part-way (a full disk; here a file-size limit, RLIMIT_FSIZE, with
# SIGXFSZ ignored, so that write() returns EFBIG once a file passes 8 KB) fails the run
# cleanly: exit 1, one message that names the file and the system's reason, nothing of
# the run left in OUTDIR's parent, and an OUTDIR that held an earlier run still holds it
# byte for byte. For simulate, render and batch (whose frames and state file are
# written through other paths). The limit does not apply to the pipes stderr goes to.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

# the example's scene (64 x 64 pixels: 16 KB a plane, past the limit), fewer photons
cp -r "$REPO/examples/plate-in-box/." "$work/"
sed -i 's/"per_channel": [0-9]*/"per_channel": 20000/' "$work/scene.json"
PM="--integrator photon-map"

# limited CMD...: runs CMD with files limited to 8 KB and SIGXFSZ ignored.
limited() { (trap '' XFSZ; ulimit -f 8; exec "$@"); }

# check NAME STATUS ERRFILE PARENT: the exit status is 1, stderr's last line names a
# file and "File too large", and PARENT holds no stage or part files of the run.
check() {
    local name=$1 status=$2 errfile=$3 parent=$4
    [ "$status" -eq 1 ] || fail "$name: exit status $status, expected 1"
    grep -q "File too large" "$errfile" ||
        fail "$name: the message does not give the reason: $(tail -n 2 "$errfile")"
    local left
    left=$(find "$parent" -maxdepth 2 \( -name '.thzmap-*' ! -name .thzmap-batch-lock \) -o \
        -maxdepth 2 -name '*.part' | head -n 3)
    [ -z "$left" ] || fail "$name: left behind: $left"
}

# simulate into a new OUTDIR: no OUTDIR afterwards
limited "$THZMAP" simulate "$work/scene.json" -o "$work/new" -q $PM 2>"$work/err1"
check "simulate, new OUTDIR" $? "$work/err1" "$work"
[ ! -e "$work/new" ] || fail "simulate: a failed run created its OUTDIR: $(ls "$work/new")"

# simulate over an earlier run: that run's files stay as they were
"$THZMAP" simulate "$work/scene.json" -o "$work/old" -q --save-photon-map $PM 2>"$work/err0" ||
    fail "simulate without a limit: $(cat "$work/err0")"
(cd "$work/old" && sha256sum ./* > "$work/old.sums")
limited "$THZMAP" simulate "$work/scene.json" -o "$work/old" -q --seed 2 $PM 2>"$work/err2"
check "simulate over a run" $? "$work/err2" "$work"
(cd "$work/old" && sha256sum -c --quiet "$work/old.sums") >/dev/null 2>&1 ||
    fail "simulate: the earlier run's files changed"
[ "$(ls "$work/old" | wc -l)" -eq "$(wc -l < "$work/old.sums")" ] ||
    fail "simulate: files added to the earlier run's OUTDIR"

# a figure cut short: with files limited to 24 KB every image (16 KB a plane) and header
# is written whole, and only a preview (about 37 KB) passes the limit. PLplot ignores the
# failed write; the run kept the truncated PNG (no IEND chunk) and ended with status 0.
(trap '' XFSZ; ulimit -f 24; exec "$THZMAP" simulate "$work/scene.json" -o "$work/fig" -q $PM) \
    2>"$work/err5"
check "simulate, a figure cut short" $? "$work/err5" "$work"
grep -q "\.png: PLplot wrote an incomplete figure: File too large" "$work/err5" ||
    fail "simulate, a figure cut short: the message does not name the figure: $(cat "$work/err5")"
[ ! -e "$work/fig" ] || fail "simulate: a run with a truncated figure kept its OUTDIR"

# classify: classification.json (13 KB) passes the limit. Its message, as bands.json's and
# summary.json's, gave no reason ("write failed") before.
limited "$THZMAP" classify "$work/old" --sensor cam -o "$work/classified" --method lda -q \
    2>"$work/err6"
check "classify" $? "$work/err6" "$work"
grep -q "classification.json: write failed: File too large" "$work/err6" ||
    fail "classify: the message does not name the file: $(cat "$work/err6")"
[ ! -e "$work/classified" ] || fail "classify: a failed run created its OUTDIR"

# render from the saved map
limited "$THZMAP" render "$work/scene.json" --photon-map "$work/old/photon-map.thzpm" \
    -o "$work/rendered" -q $PM 2>"$work/err3"
check "render" $? "$work/err3" "$work"
[ ! -e "$work/rendered" ] || fail "render: a failed run created its OUTDIR"

# batch: a two-frame sequence
cat > "$work/sequence.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 2, "frames": 2,
 "keyframes": [
   {"time_s": 0, "objects": {"target": {"transform": {"translate_m": [-0.2, 0, 0]}}}},
   {"time_s": 0.5, "objects": {"target": {"transform": {"translate_m": [0.2, 0, 0]}}}}]}
JSON
# batch: a two-frame sequence; OUTDIR keeps its lock and the state that says which frame
# failed (a rerun resumes from it), and no frame directory
limited "$THZMAP" batch "$work/sequence.json" -o "$work/batch" -q 2>"$work/err4"
check "batch" $? "$work/err4" "$work/batch"
[ -z "$(find "$work/batch" -name 'frame-*')" ] || fail "batch: a failed frame left its directory"
grep -q '"status": "failed"' "$work/batch/batch.json" 2>/dev/null ||
    fail "batch: batch.json does not record the failed frame"

finish "write failures: all runs failed cleanly"
