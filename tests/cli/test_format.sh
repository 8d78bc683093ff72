#!/usr/bin/env bash
# The C sources are laid out as .clang-format says (`make format` applies it): every
# tracked .c and .h file (or, outside a git checkout, those under the source folders)
# passes clang-format --dry-run without a change.
# usage: test_format.sh THZMAP_BINARY REPO_DIR
set -u
repo=$2
cd "$repo" || exit 1
if ! command -v clang-format >/dev/null 2>&1; then
    echo "FAIL: no clang-format (scripts/install-deps.sh installs it)"
    exit 1
fi
if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    mapfile -t files < <(git ls-files '*.c' '*.h')
else
    mapfile -t files < <(find src include tests bench examples python -name '*.[ch]' | sort)
fi
if [[ ${#files[@]} -lt 100 ]]; then
    echo "FAIL: only ${#files[@]} C files found under $repo"
    exit 1
fi
if ! clang-format --dry-run -Werror "${files[@]}"; then
    echo "FAIL: the files above differ from .clang-format's layout (run: make format)"
    exit 1
fi
echo "ok: ${#files[@]} C files as .clang-format lays them out ($(clang-format --version))"
