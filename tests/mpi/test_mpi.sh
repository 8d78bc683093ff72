#!/usr/bin/env bash
# MPI runs (docs/mpi.md): `mpirun -np N thzmap simulate|render|batch` gives, byte for byte,
# the files of one process with the same seed (summary.json and batch.json aside: wall
# times, threads, mpi_ranks), for 2 and 3 ranks of 1 thread and 2 ranks of 2 threads,
# photon-map and final-gather (with the saved photon map; also an empty deviation map), photon passes (several shared
# phases in one run), path with render passes, render from a saved map, and a batch
# (frames dealt whole by photon groups, fresh and resumed; one frame shared by the ranks;
# a frame failing on rank 1 keeps the frames before it; a dealt frame's seconds and its
# run warnings come with it); the render counts (back-face samples) are every rank's; only
# rank 0 writes; a failed or killed rank fails the run with a message and a non-zero exit,
# never a hang, and leaves no OUTDIR; so does a rank running another command (no hang);
# ranks bound to a core (Open MPI's default for 2) with 2 threads each are warned, once.
# Usage: bash test_mpi.sh THZMAP_BINARY REPO_DIR
set -u
THZMAP=$1
REPO=$(cd "$2" && pwd)
PY=/usr/bin/python3
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }
command -v mpirun >/dev/null || { echo "FAIL: mpirun is missing (scripts/install-deps.sh installs openmpi-bin)"; exit 1; }
# CI runs as root, which Open MPI refuses unless told; --oversubscribe: 3 ranks on 2 cores
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
export OMPI_MCA_rmaps_base_oversubscribe=1
mpi() { timeout 120 mpirun --oversubscribe -np "$@"; }
step() { echo "test_mpi: $(date +%T) $*"; }

# The pid of MPI rank 1 among the thzmap processes whose command line holds $1, waiting
# up to 10 s for it to start; empty when none did.
rank1_of() {
    for _ in $(seq 100); do
        sleep 0.1
        for p in $(pgrep -f -- "$1" 2>/dev/null); do
            if [ "$(cat "/proc/$p/comm" 2>/dev/null)" = thzmap ] &&
                tr '\0' '\n' < "/proc/$p/environ" 2>/dev/null | grep -qx 'OMPI_COMM_WORLD_RANK=1'; then
                echo "$p"
                return
            fi
        done
    done
}

# A small camera on plate-in-box; 140 000 photons are 3 batches of 65 536 (the last
# short), so that 2 ranks fire 2 + 1 and 3 ranks 1 + 1 + 1.
$PY - "$REPO/examples/plate-in-box/scene.json" "$work/scene.json" <<'PY'
import json, os, sys
s = json.load(open(sys.argv[1]))
s["materials"]["table"]["file"] = os.path.join(os.path.dirname(sys.argv[1]), "materials/sample.csv")
s["sensors"][0]["resolution"] = [24, 24]
s["sensors"][0]["oversampling"] = 1
s["photons"]["per_channel"] = 140000
s.setdefault("render", {}).update({"gather_rays": 4, "paths_per_sample": 2}) # cheap passes
json.dump(s, open(sys.argv[2], "w"))
PY
scene=$work/scene.json

# Every file of $1 equals the one of the same name in $2 (summary.json without what
# depends on the host and the ranks); at least 15 files ($3 names the comparison).
same_run() {
    local n=0 f b
    for f in "$1"/*; do
        b=$(basename "$f")
        n=$((n + 1))
        if [ "$b" = summary.json ]; then
            $PY - "$f" "$2/$b" <<'PY' || fail "$3: summary.json differs beyond times and ranks"
import json, sys
def strip(path):
    d = json.load(open(path))
    for k in ("timings_s", "threads", "mpi_ranks"):
        d.pop(k)
    for c in d["channels"]:
        c.pop("photon_phase_s", None); c.pop("render_s", None)
    return d
a, b = strip(sys.argv[1]), strip(sys.argv[2])
if a != b:
    for k in a:
        if a[k] != b.get(k):
            print("summary.json key", k, "differs")
    sys.exit(1)
PY
        else
            cmp -s "$f" "$2/$b" || fail "$3: $b differs"
        fi
    done
    [ "$n" -ge 15 ] || fail "$3: only $n files compared"
    [ "$(ls "$1" | wc -l)" = "$(ls "$2" | wc -l)" ] || fail "$3: not the same files"
}
ranks_of() { $PY -c 'import json,sys; print(json.load(open(sys.argv[1]))["mpi_ranks"])' "$1/summary.json"; }

step "bit-identical"
# --- bit-identical to one process ----------------------------------------------------
"$THZMAP" simulate "$scene" -o "$work/pm1" --integrator photon-map --threads 1 --quiet ||
    fail "one process, photon-map: exit $?"
[ "$(ranks_of "$work/pm1")" = 1 ] || fail "one process: mpi_ranks is not 1"
mpi 2 "$THZMAP" simulate "$scene" -o "$work/pm2" --integrator photon-map --threads 1 \
    > "$work/pm2.out" 2>&1 || { fail "2 ranks, photon-map: exit $?"; cat "$work/pm2.out"; }
same_run "$work/pm2" "$work/pm1" "2 ranks x 1 thread, photon-map"
[ "$(ranks_of "$work/pm2")" = 2 ] || fail "2 ranks: mpi_ranks is not 2"
grep -q "2 MPI ranks (.* MB communicated)" "$work/pm2.out" || fail "2 ranks: no closing line naming the ranks"
mpi 2 "$THZMAP" simulate "$scene" -o "$work/pm22" --integrator photon-map --threads 2 --quiet ||
    fail "2 ranks x 2 threads: exit $?"
same_run "$work/pm22" "$work/pm1" "2 ranks x 2 threads, photon-map"

"$THZMAP" simulate "$scene" -o "$work/fg1" --integrator final-gather --save-photon-map \
    --threads 2 --quiet || fail "one process, final-gather: exit $?"
mpi 3 "$THZMAP" simulate "$scene" -o "$work/fg3" --integrator final-gather --save-photon-map \
    --threads 1 --quiet || fail "3 ranks, final-gather: exit $?"
[ -f "$work/fg3/photon-map.thzpm" ] || fail "3 ranks: no photon-map.thzpm"
same_run "$work/fg3" "$work/fg1" "3 ranks x 1 thread, final-gather and its photon map"

# photon passes (photon-map with a noise target): one shared phase per pass, 70 000
# photons each (p95 5.5 K after one pass, so a 5 K target takes two or more)
"$THZMAP" simulate "$scene" -o "$work/pp1" --integrator photon-map --photons 70000 \
    --target-noise-k 5 --threads 1 --quiet || fail "one process, photon passes: exit $?"
mpi 2 "$THZMAP" simulate "$scene" -o "$work/pp2" --integrator photon-map --photons 70000 \
    --target-noise-k 5 --threads 1 --quiet || fail "2 ranks, photon passes: exit $?"
same_run "$work/pp2" "$work/pp1" "2 ranks, photon passes"
$PY -c 'import json,sys; sys.exit(json.load(open(sys.argv[1]))["channels"][0]["render_passes"] < 2)' \
    "$work/pp2/summary.json" || fail "photon passes: fewer than 2 passes (the test tests one phase)"

step "render"
# --- render by pixel tiles: render from a saved map, path with several passes --------
"$THZMAP" render "$scene" --photon-map "$work/fg1/photon-map.thzpm" -o "$work/re1" \
    --integrator final-gather --threads 1 --quiet || fail "one process, render: exit $?"
mpi 2 "$THZMAP" render "$scene" --photon-map "$work/fg1/photon-map.thzpm" -o "$work/re2" \
    --integrator final-gather --threads 1 --quiet || fail "2 ranks, render: exit $?"
same_run "$work/re2" "$work/re1" "2 ranks, render final-gather from a saved map"
[ "$(ranks_of "$work/re2")" = 2 ] || fail "render with 2 ranks: mpi_ranks is not 2"
step "path"
"$THZMAP" simulate "$scene" -o "$work/pa1" --integrator path --target-noise-k 0.06 \
    --threads 2 --quiet || fail "one process, path: exit $?"
mpi 3 "$THZMAP" simulate "$scene" -o "$work/pa3" --integrator path --target-noise-k 0.06 \
    --threads 1 > "$work/pa3.out" 2>&1 || { fail "3 ranks, path: exit $?"; cat "$work/pa3.out"; }
same_run "$work/pa3" "$work/pa1" "3 ranks, path with passes"
$PY -c 'import json,sys; sys.exit(json.load(open(sys.argv[1]))["channels"][0]["render_passes"] < 2)' \
    "$work/pa3/summary.json" || fail "path: fewer than 2 passes (the test tests one pass)"
grep -q "warning" "$work/pa3.out" && fail "path under mpirun warned: $(grep warning "$work/pa3.out")"
# the bytes its closing line says (docs/mpi.md "What moves"): per channel a request to
# begin, one per pass and one to end, 152 B to each other rank; per pass each other rank's
# tiles, 88 B of counts, the objects seen from the back and size + 16 B per pixel, its
# pixels those of the 16 x 16 tiles
# (tx + ty) mod 3 gives it (24 x 24 pixels)
$PY - "$work/pa3/summary.json" "$work/pa3.out" <<'PY' || fail "3 ranks, path: the bytes communicated differ from docs/mpi.md's"
import json, re, sys
passes = json.load(open(sys.argv[1]))["channels"][0]["render_passes"]
N, W, H, T = 3, 24, 24, 16
px = [0] * N
for y in range(H):
    for x in range(W):
        px[(x // T + y // T) % N] += 1
total = (2 + passes) * 152 * (N - 1) + passes * sum(88 + 16 * p for p in px[1:])
said = re.search(r"3 MPI ranks \(([0-9.e+-]+) MB communicated\)", open(sys.argv[2]).read())
if not said or said.group(1) != "%.3g" % (1e-6 * total):
    sys.exit(f"said {said and said.group(1)} MB, expected {total} B in {passes} passes")
PY

# An isothermal room: final-gather's deviation map holds no photon at all, which the other
# ranks must render from as one process does (an empty map, not "no map").
step "empty deviation map"
mkdir -p "$work/in"
$PY - "$scene" "$work/in/iso.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for o in s["objects"]:
    o["temperature_k"] = 295
s["atmosphere"] = {"model": "none"}
s["photons"]["per_channel"] = 20000
json.dump(s, open(sys.argv[2], "w"))
PY
"$THZMAP" simulate "$work/in/iso.json" -o "$work/iso1" --integrator final-gather --threads 1 --quiet ||
    fail "one process, isothermal final-gather: exit $?"
mpi 2 "$THZMAP" simulate "$work/in/iso.json" -o "$work/iso2" --integrator final-gather \
    --threads 1 > "$work/iso2.out" 2>&1 || { fail "2 ranks, empty map: exit $?"; cat "$work/iso2.out"; }
same_run "$work/iso2" "$work/iso1" "2 ranks, final-gather from an empty deviation map"

step "counts of every rank"
# The render counts behind summary.json's back_face_samples and its warning ("N of M
# samples saw the back side of one-sided solid 'NAME'") are every rank's: a target turned
# inside out, across both ranks' tiles (rank 0 counted its own tiles alone); the warning
# names it whichever rank's tiles saw it
$PY - "$scene" "$work/in/inside.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
t = [o for o in s["objects"] if o["name"] == "target"][0]
t["shape"] = {"type": "box", "size_m": [0.2, 0.2, 0.75], "inward": True}
json.dump(s, open(sys.argv[2], "w"))
PY
"$THZMAP" simulate "$work/in/inside.json" -o "$work/bk1" --integrator path --threads 1 --quiet \
    2> /dev/null || fail "one process, back faces: exit $?"
grep -q '"back_face_samples"' "$work/bk1/summary.json" || fail "test set-up: no back-face samples"
mpi 2 "$THZMAP" simulate "$work/in/inside.json" -o "$work/bk2" --integrator path --threads 1 \
    --quiet 2> /dev/null || fail "2 ranks, back faces: exit $?"
same_run "$work/bk2" "$work/bk1" "2 ranks, samples that saw back faces"
grep -q "samples saw the back side of one-sided solid 'target' (radiance 0); check its mesh" \
    "$work/bk2/summary.json" || fail "2 ranks: the back-face warning does not name the target"

step "batch"
# --- batch: whole frames dealt to the ranks by photon groups (frames 0 and 1 fire, 2
# fires and 3 renders from its photons: 3 groups), then resumed under mpirun after
# losing frames 1 and 3 (2 groups for 2 ranks: rank 1 fires frame 2's photons again),
# then after losing frame 3 (1 group for 3 ranks: rank 0 runs it, shared within the
# frame); each against one process, byte for byte ---------------------------------------
mkdir "$work/bt"
cp "$REPO/tests/inputs/batch/scene.json" "$work/bt/"
$PY - "$work/bt/scene.json" "$work/bt/seq.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["render"] = {"integrator": "photon-map"}
s["photons"] = {"seed": 7, "per_channel": 20000}
json.dump(s, open(sys.argv[1], "w"), indent=1)
q = {"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 2, "frames": 4,
     "keyframes": [{"time_s": 0, "objects": {"person": {"transform": {"translate_m": [-0.5, 0, 0.8]}}},
                    "sensors": {"cam": {"position_m": [-0.3, -1.4, 0.9]}}},
                   {"time_s": 1, "objects": {"person": {"transform": {"translate_m": [0.5, 0, 0.8]}}},
                    "sensors": {"cam": {"position_m": [-0.3, -1.4, 0.9]}}},
                   {"time_s": 1.5, "sensors": {"cam": {"position_m": [0.3, -1.4, 0.9]}}}]}
json.dump(q, open(sys.argv[2], "w"))
PY
# Every file below $1 equals $2's (summary.json and batch.json: timings aside; $4 = 1:
# batch.json's record of which run computed what, too).
same_batch() {
    local n=0 f r
    while IFS= read -r f; do
        r=${f#"$1"/}
        n=$((n + 1))
        case $(basename "$r") in
        summary.json | batch.json)
            $PY - "$f" "$2/$r" "$4" <<'PY' || fail "$3: $r differs beyond timings"
import json, sys
def strip(path):
    d = json.load(open(path))
    for k in ("timings_s", "threads", "mpi_ranks"):
        d.pop(k, None)
    for c in d.get("channels", []):
        c.pop("photon_phase_s", None); c.pop("render_s", None)
    for fr in d.get("frames", []) if isinstance(d.get("frames"), list) else []:
        fr.pop("seconds", None)
        if sys.argv[3] == "1":
            fr.pop("computed", None); fr.pop("photons", None)
    if sys.argv[3] == "1":
        for k in ("frames_computed", "frames_reused", "photon_phases_fired", "frames_rerendered"):
            d.pop(k, None)
    return d
sys.exit(strip(sys.argv[1]) != strip(sys.argv[2]))
PY
            ;;
        *) cmp -s "$f" "$2/$r" || fail "$3: $r differs" ;;
        esac
    done < <(find "$1" -type f ! -name '.thzmap-batch-lock')
    [ "$n" -ge 40 ] || fail "$3: only $n files compared"
    [ "$(cd "$1" && find . -type f | sort)" = "$(cd "$2" && find . -type f | sort)" ] ||
        fail "$3: not the same files"
}
# mpi_ranks of each frame of $1 in frame order: 1 for a frame computed by one rank (dealt
# whole), N for one the N ranks shared
frame_ranks() {
    local d
    for d in "$1"/frame-*/; do ranks_of "$d"; done | tr '\n' ' ' | sed 's/ $//'
}
# the frames that fired photons, as batch.json says ($1), e.g. "0 1 2"
fired_frames() {
    $PY -c 'import json,sys; print(*[f["frame"] for f in json.load(open(sys.argv[1]))["frames"] if f.get("photons") == "fired"])' "$1"
}
"$THZMAP" batch "$work/bt/seq.json" -o "$work/bt1" --threads 1 --quiet > /dev/null ||
    fail "one process, batch: exit $?"
[ "$(fired_frames "$work/bt1/batch.json")" = "0 1 2" ] && [ "$(ls -d "$work/bt1"/frame-* | wc -l)" = 4 ] ||
    fail "test set-up: frames $(fired_frames "$work/bt1/batch.json") fire photons, not 0 1 2 (3 groups)"
mpi 3 "$THZMAP" batch "$work/bt/seq.json" -o "$work/bt3" --threads 1 > "$work/bt3.out" 2>&1 ||
    { fail "3 ranks, batch: exit $?"; cat "$work/bt3.out"; }
same_batch "$work/bt3" "$work/bt1" "3 ranks, frames dealt" 0
ls "$work/bt3"/*.mp4 > /dev/null 2>&1 || fail "3 ranks, batch: no movie"
[ "$(frame_ranks "$work/bt3")" = "1 1 1 1" ] ||
    fail "3 ranks: frames not dealt whole (mpi_ranks per frame: $(frame_ranks "$work/bt3"))"
# each frame's seconds (docs/mpi.md "Outputs"): for a frame dealt to another rank, its time
# there, which comes with the frame (it was 0 for every frame rank 0 did not compute),
# plus its writing on rank 0: as a frame of rank 0's, at least the sum of its summary.json's
# timings_s (the computing alone was 0.009 to 0.036 s against sums of 0.066 to 0.085 s,
# most of them timings_s.output, which rank 0 spends writing the frame)
$PY - "$work/bt3" <<'PY' || fail "3 ranks: a frame's seconds is not its time: $(grep seconds "$work/bt3/batch.json" | tr -d ' \n')"
import json, sys
frames = json.load(open(sys.argv[1] + "/batch.json"))["frames"]
assert len(frames) == 4
for f in frames:
    t = json.load(open(f"{sys.argv[1]}/{f['dir']}/summary.json"))["timings_s"]
    assert f["seconds"] > 0 and f["seconds"] >= sum(t.values()) - 1e-4, (f["frame"], f["seconds"], t)
PY
rm -rf "$work/bt3/frame-00001" "$work/bt3/frame-00003"
mpi 2 "$THZMAP" batch "$work/bt/seq.json" -o "$work/bt3" --threads 1 > "$work/bt2.out" 2>&1 ||
    { fail "2 ranks, resumed batch: exit $?"; cat "$work/bt2.out"; }
same_batch "$work/bt3" "$work/bt1" "2 ranks, frames 1 and 3 dealt after losing them" 1
grep -q '"frames_reused": 2' "$work/bt3/batch.json" || fail "resumed batch: 2 frames not reused"
[ "$(frame_ranks "$work/bt3")" = "1 1 1 1" ] ||
    fail "resumed with 2 ranks: frames 1 and 3 not dealt (mpi_ranks: $(frame_ranks "$work/bt3"))"
rm -rf "$work/bt3/frame-00003"
mpi 3 "$THZMAP" batch "$work/bt/seq.json" -o "$work/bt3" --threads 1 > "$work/bt1s.out" 2>&1 ||
    { fail "3 ranks, one frame to redo: exit $?"; cat "$work/bt1s.out"; }
same_batch "$work/bt3" "$work/bt1" "3 ranks sharing frame 3 (1 group)" 1
[ "$(frame_ranks "$work/bt3")" = "1 1 1 3" ] ||
    fail "1 group for 3 ranks: frame 3 not shared by the 3 (mpi_ranks: $(frame_ranks "$work/bt3"))"

# A frame that fails on rank 1 (frame 1 asks for 10^8 photons a channel, about 5 GiB of
# maps: rank 0's check before the frames passes, rank 1 may have 3 GiB (ulimit -v) and
# refuses it for memory when it runs it): the run fails naming it, non-zero exit, frame
# 0 (rank 0's) stays committed. (Asking 10^12 photons of every rank no longer reaches a
# rank: rank 0 refuses the batch before any frame, as one process does.)
mkdir "$work/bf"
$PY - "$work/bt/scene.json" "$work/bf" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
json.dump(s, open(f"{sys.argv[2]}/s0.json", "w"))
s["photons"]["per_channel"] = 10**8
json.dump(s, open(f"{sys.argv[2]}/s1.json", "w"))
json.dump({"format": "thzmap-sequence/1", "scenes": ["s0.json", "s1.json"]},
          open(f"{sys.argv[2]}/seq.json", "w"))
PY
timeout 120 mpirun --oversubscribe -np 1 "$THZMAP" batch "$work/bf/seq.json" -o "$work/bf/out" \
    --threads 1 --quiet : -np 1 bash -c 'ulimit -v 3145728 && exec "$@"' limited "$THZMAP" \
    batch "$work/bf/seq.json" -o "$work/bf/out" --threads 1 --quiet > "$work/bf.out" 2>&1
rc=$?
[ $rc != 0 ] && [ $rc != 124 ] || fail "a frame failing on rank 1: exit $rc"
grep -q "frame-00001 (MPI rank 1)" "$work/bf.out" || { fail "rank 1's failure not said"; cat "$work/bf.out"; }
[ -f "$work/bf/out/frame-00000/frame.json" ] || fail "a frame failing on rank 1: frame 0 not kept"
[ ! -e "$work/bf/out/frame-00001" ] || fail "a frame failing on rank 1: frame 1 written"
grep -q '"status": "failed"' "$work/bf/out/batch.json" || fail "a frame failing on rank 1: not failed in batch.json"

step "only rank 0"
# --- only rank 0 writes: nothing else beside the outputs -----------------------------
extra=$(ls "$work" | grep -vxE 'scene.json|pm1|pm2|pm2.out|pm22|fg1|fg3|pp1|pp2|re1|re2|pa1|pa3|pa3.out|in|iso1|iso2|iso2.out|bk1|bk2|bt|bt1|bt3|bt3.out|bt2.out|bt1s.out|bf|bf.out')
[ -z "$extra" ] || fail "files beside the outputs: $extra"


# --- failures --------------------------------------------------------------------------
step "bad input"
# bad input on every rank: one message, exit 2, no OUTDIR
echo '{"format": "thzmap-scene/1", "channels": 3}' > "$work/bad.json"
mpi 2 "$THZMAP" simulate "$work/bad.json" -o "$work/bad" > "$work/bad.out" 2>&1
rc=$?
[ $rc = 2 ] || fail "bad scene under mpirun: exit $rc, not 2"
[ "$(grep -c 'bad.json' "$work/bad.out")" = 1 ] || { fail "bad scene: not one message"; cat "$work/bad.out"; }
[ ! -e "$work/bad" ] || fail "bad scene: OUTDIR created"
# an option wrong for the scene (render --sensor of no sensor) likewise: every rank checks
# it before they work together (rank 0 alone found it, after: MPI_ABORT and its banner)
mpi 2 "$THZMAP" render "$scene" --integrator path --sensor nope -o "$work/nos" > "$work/nos.out" 2>&1
rc=$?
[ $rc = 2 ] || fail "render --sensor nope under mpirun: exit $rc, not 2"
[ "$(grep -c "no sensor named 'nope'" "$work/nos.out")" = 1 ] || { fail "--sensor nope: not one message"; cat "$work/nos.out"; }
! grep -qE 'MPI_ABORT|MPI_COMM_WORLD|ORTE_ERROR_LOG' "$work/nos.out" || { fail "--sensor nope: the job was aborted"; cat "$work/nos.out"; }
[ ! -e "$work/nos" ] || fail "--sensor nope: OUTDIR created"
# and a noise target for an integrator whose render has no passes (photon-map)
mpi 2 "$THZMAP" render "$scene" --integrator photon-map --photon-map "$work/fg1/photon-map.thzpm" \
    --target-noise-k 0.1 -o "$work/not" > "$work/not.out" 2>&1
rc=$?
[ $rc = 2 ] || fail "render photon-map --target-noise-k under mpirun: exit $rc, not 2"
[ "$(grep -c "target-noise-k" "$work/not.out")" = 1 ] || { fail "--target-noise-k: not one message"; cat "$work/not.out"; }
! grep -qE 'MPI_ABORT|MPI_COMM_WORLD|ORTE_ERROR_LOG' "$work/not.out" || { fail "--target-noise-k: the job was aborted"; cat "$work/not.out"; }
[ ! -e "$work/not" ] || fail "--target-noise-k: OUTDIR created"
# an OUTDIR that is a file: rank 0 opens OUTDIR before the ranks work together (found
# after, it aborted the job: MPI_ABORT's banner, or Open MPI's ORTE_ERROR_LOG where the
# banner itself failed; an abort's traces are what the checks of these refusals look for)
touch "$work/afile"
mpi 2 "$THZMAP" simulate "$scene" -o "$work/afile" > "$work/af.out" 2>&1
rc=$?
[ $rc = 2 ] || fail "an OUTDIR that is a file under mpirun: exit $rc, not 2"
[ "$(grep -c 'afile: exists and is not a directory' "$work/af.out")" = 1 ] || { fail "OUTDIR a file: not one message"; cat "$work/af.out"; }
! grep -qE 'MPI_ABORT|MPI_COMM_WORLD|ORTE_ERROR_LOG' "$work/af.out" || { fail "OUTDIR a file: the job was aborted"; cat "$work/af.out"; }
step "rank 1 loads"
# rank 1 loads another scene (a different seed): it refuses rank 0's request, the job ends
sed 's/"seed": 1/"seed": 2/' "$scene" > "$work/other.json"
grep -q '"seed": 2' "$work/other.json" || fail "test set-up: no seed in the scene"
timeout 120 mpirun --oversubscribe -np 1 "$THZMAP" simulate "$scene" -o "$work/mix" --quiet \
    --integrator photon-map : -np 1 "$THZMAP" simulate "$work/other.json" -o "$work/mix" \
    --quiet --integrator photon-map > "$work/mix.out" 2>&1
rc=$?
[ $rc != 0 ] && [ $rc != 124 ] || fail "rank 1 with another seed: exit $rc"
grep -q "MPI rank 1.*seed 2" "$work/mix.out" || { fail "rank 1's refusal not said"; cat "$work/mix.out"; }
[ ! -e "$work/mix" ] || fail "rank 1 with another seed: OUTDIR created"
step "rank 1 renders"
# rank 1 with another integrator that fires photons too (final-gather against photon-map):
# refused at the render's start; it ran and wrote images of nonsense, exit 0
timeout 120 mpirun --oversubscribe -np 1 "$THZMAP" simulate "$scene" -o "$work/mixi" --quiet \
    --integrator final-gather : -np 1 "$THZMAP" simulate "$scene" -o "$work/mixi" \
    --quiet --integrator photon-map > "$work/mixi.out" 2>&1
rc=$?
[ $rc != 0 ] && [ $rc != 124 ] || fail "rank 1 with another integrator: exit $rc"
grep -q "the lead renders with final-gather, process 1 with photon-map" "$work/mixi.out" ||
    { fail "rank 1's other integrator not said"; cat "$work/mixi.out"; }
[ ! -e "$work/mixi" ] || fail "rank 1 with another integrator: OUTDIR created"
step "rank 1's scene differs"
# rank 1 loads a scene that differs where no earlier check looked: a warmer target (path:
# it wrote rank 1's tiles into the images, exit 0) and a larger sensor (its tiles were
# written past the lead's buffer: "double free or corruption"). Both are refused.
$PY - "$scene" "$work/warm.json" "$work/wide.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
w = json.loads(json.dumps(s))
w["objects"][1]["temperature_k"] += 90
json.dump(w, open(sys.argv[2], "w"))
w = json.loads(json.dumps(s))
w["sensors"][0]["resolution"] = [36, 36]
json.dump(w, open(sys.argv[3], "w"))
PY
for other in warm wide; do
    timeout 120 mpirun --oversubscribe -np 1 "$THZMAP" simulate "$scene" -o "$work/mix$other" \
        --quiet --integrator path : -np 1 "$THZMAP" simulate "$work/$other.json" \
        -o "$work/mix$other" --quiet --integrator path > "$work/mix$other.out" 2>&1
    rc=$?
    [ $rc != 0 ] && [ $rc != 124 ] || fail "rank 1 with the $other scene: exit $rc"
    grep -q "process 1's scene differs from the lead's" "$work/mix$other.out" ||
        { fail "rank 1's $other scene not said"; cat "$work/mix$other.out"; }
    [ ! -e "$work/mix$other" ] || fail "rank 1 with the $other scene: OUTDIR created"
done
step "rank 1 cannot"
# rank 1 cannot load its scene (missing on its node): rank 0 says so, exit non-zero
timeout 120 mpirun --oversubscribe -np 1 "$THZMAP" simulate "$scene" -o "$work/miss" --quiet \
    : -np 1 "$THZMAP" simulate "$work/missing.json" -o "$work/miss" --quiet > "$work/miss.out" 2>&1
rc=$?
[ $rc != 0 ] && [ $rc != 124 ] || fail "rank 1 without its scene: exit $rc"
grep -q "MPI rank 1 could not load" "$work/miss.out" || { fail "rank 1's failure not said"; cat "$work/miss.out"; }
[ ! -e "$work/miss" ] || fail "rank 1 without its scene: OUTDIR created"
step "a killed"
# a killed rank: the job ends non-zero within the timeout, no results
mpi 2 "$THZMAP" simulate "$scene" -o "$work/kill" --photons 3000000 --threads 1 --quiet \
    --integrator photon-map > "$work/kill.out" 2>&1 &
job=$!
victim=$(rank1_of "-o $work/kill")
if [ -n "$victim" ]; then
    sleep 0.5
    kill -KILL "$victim"
    wait $job
    rc=$?
    [ $rc != 0 ] && [ $rc != 124 ] || fail "killed rank 1: exit $rc"
    [ ! -e "$work/kill" ] || fail "killed rank 1: results in OUTDIR"
else
    fail "test set-up: rank 1's process not found"
    kill $job
fi
step "a stopped"
# a rank that stops and then dies while rank 0 waits for it: mpirun's SIGTERM reaches rank
# 0 in its wait, which cleans up (no lock or stage beside OUTDIR, OUTDIR as it was) and
# says so, naming mpirun's SIGTERM; it ignored the signal and was killed, leaving both
mkdir -p "$work/stopped/out" && echo keep > "$work/stopped/out/marker"
mpi 2 "$THZMAP" simulate "$scene" -o "$work/stopped/out" --integrator path --threads 1 \
    --target-noise-k 0.0001 --max-seconds 60 --quiet > "$work/stopped.out" 2>&1 &
job=$!
victim=$(rank1_of "-o $work/stopped/out")
if [ -n "$victim" ]; then
    sleep 1
    kill -STOP "$victim"
    sleep 1
    kill -KILL "$victim"
    wait $job
    rc=$?
    [ $rc != 0 ] && [ $rc != 124 ] || fail "stopped rank 1: exit $rc"
    [ "$(ls -A "$work/stopped")" = out ] ||
        fail "stopped rank 1: left beside OUTDIR: $(ls -A "$work/stopped")"
    [ "$(ls -A "$work/stopped/out")" = marker ] || fail "stopped rank 1: OUTDIR changed"
    # and why: mpirun's SIGTERM after rank 1's end, not a user's interrupt (it said
    # "interrupted; no results written", as if the user had stopped the job)
    grep -q "interrupted by SIGTERM, which mpirun sends every rank when one has ended .*; no results written" \
        "$work/stopped.out" ||
        { fail "stopped rank 1: rank 0 did not say it was stopped by mpirun"; cat "$work/stopped.out"; }
else
    fail "test set-up: rank 1's process not found"
    kill $job
fi
step "dealt warnings"
# A dealt batch says every frame's scene and run warnings, also of the frames other ranks
# computed (they were lost; the run's went to summary.json alone), and blames rank 0's own failure to write a frame on no other rank.
mkdir -p "$work/dw"
$PY - "$REPO/tests/inputs/batch/scene.json" "$work/dw" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["render"] = {"integrator": "photon-map"}
s["photons"] = {"seed": 7, "per_channel": 20000}
json.dump(s, open(sys.argv[2] + "/s0.json", "w"))
s["atmosphere"] = {"model": "constant", "attenuation_per_m": 0.05, "emitting": False}
s["materials"]["skin"]["reflection"] = {"model": "ward", "alpha_x": 0.1, "alpha_y": 0.1}
json.dump(s, open(sys.argv[2] + "/s1.json", "w"))
json.dump({"format": "thzmap-sequence/1", "scenes": ["s0.json", "s1.json"]},
          open(sys.argv[2] + "/seq.json", "w"))
PY
mpi 2 "$THZMAP" batch "$work/dw/seq.json" -o "$work/dw/two" -q --threads 1 > "$work/dw.out" 2>&1 ||
    fail "dealt batch of two scenes: exit $?: $(tail -3 "$work/dw.out")"
grep -q 'warning: frame-00001: atmosphere: "emitting": false' "$work/dw.out" ||
    { fail "dealt batch: frame 2's scene warning not said"; cat "$work/dw.out"; }
grep -q 'warning: frame-00001: material "skin": photon-map cannot resolve its glossy lobe' "$work/dw.out" ||
    { fail "dealt batch: frame 2's run warning not said"; cat "$work/dw.out"; }
mkdir "$work/dw/o2" && touch "$work/dw/o2/frame-00001"
mpi 2 "$THZMAP" batch "$work/dw/seq.json" -o "$work/dw/o2" -q --threads 1 > "$work/dw2.out" 2>&1
grep -q "frame-00001: .*exists and is not a directory" "$work/dw2.out" &&
    ! grep -q "MPI rank 1" "$work/dw2.out" ||
    { fail "rank 0's own write failure: message"; cat "$work/dw2.out"; }
step "rank 1 runs another command"
# rank 0 runs a batch while rank 1 simulates one scene: refused with a message naming it,
# non-zero exit, no hang; frames dealt (seq.json: 3 groups) or shared (the same scene
# twice: one group, each frame's scene sent to rank 1, which returned as if stopped)
echo '{"format": "thzmap-sequence/1", "scenes": ["scene.json", "scene.json"]}' > "$work/bt/two.json"
for seqf in seq two; do
    timeout 120 mpirun --oversubscribe -np 1 "$THZMAP" batch "$work/bt/$seqf.json" \
        -o "$work/mixb-$seqf" --quiet --threads 1 : -np 1 "$THZMAP" simulate "$work/bt/scene.json" \
        -o "$work/mixb-$seqf" --quiet --threads 1 > "$work/mixb.out" 2>&1
    rc=$?
    [ $rc != 0 ] && [ $rc != 124 ] || fail "rank 1 simulating while rank 0 runs a batch ($seqf): exit $rc"
    grep -q "the lead runs several scenes (batch) while process 1 serves one" "$work/mixb.out" ||
        { fail "rank 1's other command not said ($seqf)"; cat "$work/mixb.out"; }
done
step "other commands"
# other commands refuse several ranks
mpi 2 "$THZMAP" validate "$scene" > "$work/val.out" 2>&1
rc=$?
[ $rc = 2 ] || fail "validate under mpirun: exit $rc, not 2"
grep -q "simulate, render and batch do" "$work/val.out" || fail "validate under mpirun: no message"
[ "$(grep -c "simulate, render and batch do" "$work/val.out")" = 1 ] ||
    fail "validate under mpirun: the message more than once"
# an unknown command: exit 2, the message and the usage once (each rank printed both)
mpi 2 "$THZMAP" bogus > "$work/bogus.out" 2>&1
rc=$?
[ $rc = 2 ] || fail "unknown command under mpirun: exit $rc, not 2"
[ "$(grep -c "unknown command 'bogus'" "$work/bogus.out")" = 1 ] &&
    [ "$(grep -c "^usage: thzmap" "$work/bogus.out")" = 1 ] ||
    { fail "unknown command under mpirun: not printed once"; cat "$work/bogus.out"; }

step "threads bound"
# Open MPI binds each of 2 ranks to a core: --threads 2 then runs both threads on it.
# Rank 0 says so, once (it said nothing: docs/mpi.md's hybrid example ran so); with
# --bind-to none, nothing.
timeout 120 mpirun --bind-to core:overload-allowed -np 2 "$THZMAP" simulate "$scene" \
    -o "$work/bound" --threads 2 --quiet > "$work/bound.out" 2>&1 || fail "bound ranks: exit $?"
[ "$(grep -c "warning: --threads 2, but this process may run on only 1 CPU" "$work/bound.out")" = 1 ] ||
    { fail "2 ranks bound to a core, 2 threads: not warned once"; cat "$work/bound.out"; }
timeout 120 mpirun --bind-to none -np 2 "$THZMAP" simulate "$scene" -o "$work/unbound" \
    --threads 2 --quiet > "$work/unbound.out" 2>&1 || fail "unbound ranks: exit $?"
if [ "$(nproc)" -ge 2 ] && grep -q "may run on only" "$work/unbound.out"; then
    fail "--bind-to none: warned: $(cat "$work/unbound.out")"
fi

[ $fails = 0 ] && echo "test_mpi: all passed"
exit $((fails > 0))
