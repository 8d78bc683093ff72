# What the shell tests tests/cli/test_*.sh share. Not a test itself: CMake registers
# tests/cli/test_*.sh alone, each run as `bash SCRIPT THZMAP_BINARY REPO_DIR`. A test
# sources it first, from the directory it stands in:
#     . "$(dirname "$0")/lib.sh"
# which turns on `set -u` and sets
#     THZMAP   the thzmap binary under test ($1)
#     REPO     the repository directory ($2)
#     work     a new empty directory, removed when the script exits (its EXIT trap)
#     fails    the count of failed checks, 0
# and defines the functions below. A test with a variant of its own (a fail that stops
# at the first failure, another final message) defines it after sourcing.
# (.shellcheckrc here lets shellcheck read this file where a test sources it.)
# shellcheck shell=bash disable=SC2034 # (THZMAP and REPO are for the tests)
set -u
THZMAP=$1
REPO=$2
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fails=0

# fail MESSAGE...: prints "FAIL: MESSAGE" and counts a failed check; the test goes on.
fail() { echo "FAIL: $*"; fails=$((fails + 1)); }

# need TOOL [PACKAGE]: fails the test at once (exit 1) when TOOL is not on PATH;
# PACKAGE is what scripts/install-deps.sh installs for it (default: TOOL itself).
need() {
    command -v "$1" >/dev/null ||
        { echo "FAIL: $1 is missing (scripts/install-deps.sh installs ${2:-it})"; exit 1; }
}

# expect_line FILE PATTERN: some line of FILE matches the extended regex PATTERN.
expect_line() {
    grep -Eq -- "$2" "$1" || fail "no line matching '$2' in $(basename "$1"):" "$(cat "$1")"
}

# leftovers: up to three of thzmap's staging or lock files (.thzmap-*) left in $work.
leftovers() { find "$work" -maxdepth 1 -name '.thzmap-*' | head -n 3; }

# plate_in_room: a scene's "materials" and "objects" members, comma after, indented for
# a heredoc's `$(plate_in_room)` line: a closed 2 m room at 295 K (R 0.2) and a painted
# 0.5 x 0.05 x 0.5 m plate at 310 K (R 0.5) at its centre.
plate_in_room() {
    cat <<'JSON'
  "materials": {"wall": {"reflectivity": 0.2}, "paint": {"reflectivity": 0.5}},
  "objects": [
    {"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
     "shape": {"type": "box", "size_m": [2, 2, 2], "inward": true}},
    {"name": "plate", "type": "solid", "material": "paint", "temperature_k": 310,
     "shape": {"type": "box", "size_m": [0.5, 0.05, 0.5]}}
  ],
JSON
}

# finish MESSAGE: the end of a test: prints MESSAGE when no check failed; exits 0 if
# none failed, else 1.
finish() {
    [ "$fails" -eq 0 ] && echo "$1"
    exit $((fails > 0))
}

# finish_counted MESSAGE: the same, but when checks failed it prints their number
# ("N failure(s)") instead of MESSAGE.
finish_counted() {
    if [ "$fails" -ne 0 ]; then
        echo "$fails failure(s)"
        exit 1
    fi
    echo "$1"
    exit 0
}
