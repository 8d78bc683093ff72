# What test_batch.sh and test_batch_inputs.sh share, sourced after lib.sh (not a test:
# CMake registers tests/cli/test_*.sh alone):
#     . "$(dirname "$0")/lib.sh"
#     . "$(dirname "$0")/batch_lib.sh"
# needs ffmpeg and ffprobe (the movies), copies tests/inputs/batch's scene.json (a box,
# "person", in a room, 16 x 12 pixels, integrator path) and sequence.json (the box walking from
# x = -0.5 to 0.5 m while warming from 300 to 308 K, 5 frames at 4 fps) into $work, and
# sets
#     seq   $work/sequence.json
#     PY    the Python with numpy
# and same_files below.
# shellcheck shell=bash disable=SC2034 # (seq and PY are for the tests)
PY=/usr/bin/python3 # Debian's, with numpy
# Every file of the run in $1 (summary.json aside: timings) equals, byte for byte, the
# file of the same name in $2; at least 10 of them ($3 names the comparison).
same_files() {
    local n=0 f b
    for f in "$1"/*; do
        b=$(basename "$f")
        [ "$b" = summary.json ] && continue
        n=$((n + 1))
        cmp -s "$f" "$2/$b" || fail "$3: $b differs"
    done
    [ "$n" -ge 10 ] || fail "$3: only $n files compared"
}
need ffprobe ffmpeg
need ffmpeg

cp "$REPO/tests/inputs/batch/scene.json" "$REPO/tests/inputs/batch/sequence.json" "$work/"
seq="$work/sequence.json"
