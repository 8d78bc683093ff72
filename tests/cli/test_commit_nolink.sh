#!/usr/bin/env bash
# Committing into an OUTDIR that holds a user's own file keeps that file where hard links
# fail (a file system without them, such as FAT on a USB stick; another user's file under
# fs.protected_hardlinks): the commit links the user's files into the new results, and
# moves those it cannot link afterwards. Without the directory exchange (renameat2's
# RENAME_EXCHANGE, which FAT and NFS lack either), the old OUTDIR was parked and its regular
# files deleted, the user's among them. strace's fault injection plays both file
# systems: link fails with EPERM, and renameat2 with EINVAL. The earlier run's files of a
# sensor the new run writes go, though: its measured cubes, its sensor's noise removed.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

cp -r "$REPO/examples/plate-in-box/." "$work/"
sed -i 's/"resolution": \[[0-9, ]*\]/"resolution": [16, 12]/' "$work/scene.json"
python3 -c 'import json, sys; s = json.load(open(sys.argv[1])); s["sensors"][0]["noise"] = {"netd_k": 0.5}
json.dump(s, open(sys.argv[2], "w"))' "$work/scene.json" "$work/noisy.json"
run() { "$THZMAP" simulate "$work/noisy.json" -o "$work/out" --integrator path --quiet "$@"; }
export ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 # under strace

for mode in exchange parked; do
    rm -rf "$work/out"
    run || fail "$mode: first run exited $?"
    echo "the user's notes" > "$work/out/notes.txt"
    inject=(-e inject=link,linkat:error=EPERM)
    [ $mode = parked ] && inject+=(-e inject=renameat2:error=EINVAL)
    strace -f -qq -o /dev/null "${inject[@]}" "$THZMAP" simulate "$work/scene.json" \
        -o "$work/out" --integrator path --quiet --seed 2 2> "$work/err" ||
        fail "$mode: the run with link failing exited $?: $(cat "$work/err")"
    [ "$(cat "$work/out/notes.txt" 2>/dev/null)" = "the user's notes" ] ||
        fail "$mode: the user's file is lost or changed ($(ls -A "$work/out" | tr '\n' ' '))"
    grep -q '"seed": 2' "$work/out/summary.json" || fail "$mode: the new results are not in place"
    stale=$(ls "$work/out" | grep measured)
    [ -z "$stale" ] || fail "$mode: the earlier run's measured cubes stayed: $stale"
    left=$(ls -A "$work" | grep -v -x -e out -e scene.json -e noisy.json -e materials -e err -e README.md)
    [ -z "$left" ] || fail "$mode: left beside OUTDIR: $left"
done
finish "ok: commit keeps a user's file where hard links fail"
