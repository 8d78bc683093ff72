#!/usr/bin/env bash
# Which code made an output: `thzmap --version` prints the source revision the program was
# built from (thz_revision(), cmake/revision.cmake), which for a git checkout is its commit
# (`git rev-parse HEAD`; "-dirty" or not: the tree may change after the build), for a
# build given -DTHZ_REVISION that, and "unknown" outside a checkout; summary.json,
# batch.json, bands.json and classification.json record the same as thzmap_revision beside
# thzmap_version. (Before, they recorded "0.1.0" alone, which names no commit.)
# And cmake/revision.cmake itself, run as the build runs it on repositories made here: a
# commit's hash; "-dirty" with a tracked file edited or staged, not with an untracked
# file; "unknown" outside a checkout, in a directory inside another repository (an
# archive unpacked there), before the first commit, and without git; a given revision
# wins; the file is rewritten only when its content changes (nothing rebuilds needlessly).
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
need git
need cmake
IN=$REPO/tests/inputs/analysis
build=$(cd "$(dirname "$THZMAP")" && pwd)
given=$(sed -n 's/^THZ_REVISION:STRING=//p' "$build/CMakeCache.txt" 2>/dev/null)

# ---- the program's revision against the checkout's ------------------------------------
line=$("$THZMAP" --version) || fail "--version: exit $?"
rev=$(sed -nE 's/^thzmap [0-9]+\.[0-9]+\.[0-9]+ \(revision ([^ ()]+)\)$/\1/p' <<<"$line")
[ -n "$rev" ] || fail "--version printed '$line', expected 'thzmap X.Y.Z (revision R)'"
repo_git() { git -c safe.directory="$REPO" -C "$REPO" "$@" 2>/dev/null; }
if [ -n "$given" ]; then
    [ "$rev" = "$given" ] || fail "built with THZ_REVISION=$given, --version says '$rev'"
elif top=$(repo_git rev-parse --show-toplevel) &&
    [ "$(realpath "$top")" = "$(realpath "$REPO")" ]; then
    head=$(repo_git rev-parse HEAD)
    case $rev in
    "$head" | "$head-dirty") ;;
    *) fail "--version's revision '$rev' is not the checkout's commit $head (or $head-dirty)" \
        "(a build older than the checkout? rebuild)" ;;
    esac
else
    echo "note: $REPO is not a git checkout: the revision must be 'unknown'"
    [ "$rev" = unknown ] || fail "outside a git checkout --version says '$rev', not 'unknown'"
fi

# ---- the outputs record it ---------------------------------------------------------------
# recorded FILE: its thzmap_revision equals --version's, thzmap_version beside it
recorded() {
    /usr/bin/python3 - "$1" "$rev" <<'PY' || fail "$1 does not record the revision '$rev'"
import json, sys
d = json.load(open(sys.argv[1]))
ok = d.get("thzmap_revision") == sys.argv[2] and "thzmap_version" in d
if not ok:
    print(f"{sys.argv[1]}: thzmap_revision {d.get('thzmap_revision')!r}")
sys.exit(0 if ok else 1)
PY
}
"$THZMAP" simulate "$IN/distinct.json" -o "$work/run" -q --seed 3 --threads 1 ||
    fail "simulate: exit $?"
recorded "$work/run/summary.json"
"$THZMAP" classify "$work/run" --sensor cam -o "$work/classes" -q || fail "classify: exit $?"
recorded "$work/classes/classification.json"
"$THZMAP" bands "$IN/features.json" -o "$work/bands" --count 1 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 200 --paths 2 -q --threads 1 2>"$work/bands.err" ||
    fail "bands: exit $?: $(cat "$work/bands.err")"
recorded "$work/bands/bands.json"
cp "$IN/distinct.json" "$work/scene.json"
cat >"$work/seq.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 1}
JSON
"$THZMAP" batch "$work/seq.json" -o "$work/batch" -q --threads 1 --no-movies ||
    fail "batch: exit $?"
recorded "$work/batch/batch.json"
recorded "$work/batch/frame-00000/summary.json"

# ---- cmake/revision.cmake on repositories of its own -----------------------------------
# revision DIR [CMAKE ARGUMENTS]: what the script writes for a source directory DIR
out=$work/thz_revision.c
revision() {
    local dir=$1
    shift
    cmake -DSOURCE_DIR="$dir" -DOUTPUT="$out" "$@" -P "$REPO/cmake/revision.cmake" ||
        { echo "cmake -P exited $?"; return; }
    sed -nE 's/^    return "(.*)";$/\1/p' "$out"
}
r=$work/repo
g() { git -C "$r" -c user.name=t -c user.email=t@t "$@" >/dev/null; }
mkdir -p "$r/sub" && g init -q && echo a >"$r/a.c" && cp "$r/a.c" "$r/sub/b.c"
[ "$(revision "$r")" = unknown ] || fail "no commit yet: $(revision "$r")"
g add a.c sub/b.c && g commit -q -m one
commit=$(git -C "$r" rev-parse HEAD)
[ "$(revision "$r")" = "$commit" ] || fail "a clean checkout: '$(revision "$r")', not $commit"
{ grep -q '^#include "thzmap/thzmap.h"$' "$out" &&
    grep -q '^const char \*thz_revision(void)$' "$out"; } ||
    fail "the generated file does not define thz_revision(): $(cat "$out")"
echo new >"$r/untracked.c"
[ "$(revision "$r")" = "$commit" ] || fail "an untracked file: '$(revision "$r")'"
touch -d 2000-01-01 "$out"
revision "$r" >/dev/null
[ "$(stat -c %Y "$out")" = "$(date -d 2000-01-01 +%s)" ] ||
    fail "the same revision rewrote the file (everything on it would rebuild)"
echo b >>"$r/a.c"
[ "$(revision "$r")" = "$commit-dirty" ] || fail "a tracked file edited: '$(revision "$r")'"
g add a.c
[ "$(revision "$r")" = "$commit-dirty" ] || fail "an edit staged: '$(revision "$r")'"
g commit -q -m two
[ "$(revision "$r")" = "$(git -C "$r" rev-parse HEAD)" ] || fail "after a second commit"
[ "$(stat -c %Y "$out")" != "$(date -d 2000-01-01 +%s)" ] || fail "a new revision left the file"
[ "$(revision "$r/sub")" = unknown ] ||
    fail "a directory inside another repository: '$(revision "$r/sub")', not unknown"
mkdir "$work/plain"
[ "$(revision "$work/plain")" = unknown ] || fail "not a checkout: '$(revision "$work/plain")'"
cmake_bin=$(command -v cmake)
nogit=$(PATH=/nonexistent "$cmake_bin" -DSOURCE_DIR="$r" -DOUTPUT="$out" \
    -P "$REPO/cmake/revision.cmake" 2>&1 && sed -nE 's/^    return "(.*)";$/\1/p' "$out")
[ "$nogit" = unknown ] || fail "without git on the PATH: '$nogit'"
[ "$(revision "$r" -DREVISION=1.2.3+deb1)" = 1.2.3+deb1 ] || fail "a given revision"
finish "the program names its revision; its outputs record it; revision.cmake as documented"
