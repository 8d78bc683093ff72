#!/usr/bin/env bash
# Removes what `cmake --install BUILD --prefix PREFIX` (make install) puts under PREFIX:
# the list comes from installing the same build into a scratch DESTDIR, so it does not
# depend on which install ran last. Then the directories of thzmap's own (a path
# component named "thzmap": include/thzmap, share/thzmap/..., the Python package, with
# the __pycache__ Python left there) go when empty; shared ones (bin, lib, share/man/man1)
# stay. Honours DESTDIR as make install does.
# usage: uninstall.sh BUILD PREFIX
set -euo pipefail
[[ $# -eq 2 ]] || { echo "usage: uninstall.sh BUILD PREFIX" >&2; exit 2; }
build=$1
prefix=$2
[[ -f $build/cmake_install.cmake ]] || { echo "uninstall: $build is not a CMake build tree" >&2; exit 2; }
[[ $prefix == /* ]] || { echo "uninstall: PREFIX must be an absolute path, not '$prefix'" >&2; exit 2; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
DESTDIR=$stage cmake --install "$build" --prefix "$prefix" >/dev/null
target=${DESTDIR:-}
removed=0
while IFS= read -r -d '' f; do
    f=${f#.}
    if [[ -e $target$f || -L $target$f ]]; then
        rm -f -- "$target$f"
        removed=$((removed + 1))
    fi
done < <(cd "$stage" && find . \( -type f -o -type l \) -print0)
while IFS= read -r -d '' d; do
    d=${d#.}
    [[ /$d/ == */thzmap/* && -d $target$d ]] || continue
    rm -rf -- "$target$d/__pycache__"
    rmdir -- "$target$d" 2>/dev/null || true
done < <(cd "$stage" && find . -depth -mindepth 1 -type d -print0)
echo "uninstall: removed $removed files of thzmap from $target$prefix"
