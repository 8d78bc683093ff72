#!/usr/bin/env bash
# README.md's command synopsis against --help: for the commands whose synopsis lists every
# option (validate, batch, serve; the others show the common ones and point to --help),
# every long option --help describes is in the command's synopsis lines (batch lacked
# --no-movies, serve --host).
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"

for cmd in validate batch serve; do
    "$THZMAP" $cmd --help > "$work/$cmd.help" || fail "$cmd --help: exit $?"
    # the synopsis block's lines from "thzmap CMD" to the next command's line
    awk -v c="thzmap $cmd" '/^```/ { inb = !inb; next }
        inb && /^(thzmap|mpirun) / { on = index($0, c " ") == 1 || $0 == c }
        inb && on' "$REPO/README.md" > "$work/$cmd.synopsis"
    [ -s "$work/$cmd.synopsis" ] || fail "README.md has no synopsis line for thzmap $cmd"
    for o in $(grep -oE -- '--[a-z][a-z-]*' "$work/$cmd.help" | sort -u); do
        case $o in --help | --output) continue ;; esac # -h, -o in the synopsis
        grep -q -- "\[$o\b" "$work/$cmd.synopsis" ||
            fail "README.md's synopsis of thzmap $cmd lacks $o: $(cat "$work/$cmd.synopsis")"
    done
done
finish "readme synopsis: all checks passed"
