#!/usr/bin/env bash
# Table-driven test of bad scenes: for every row of tests/inputs/bad_scenes.tsv
# (file, expected exit status, text the message must contain), `thzmap validate`
# must exit with that status, print nothing to stdout, print exactly one line to
# stderr naming the file, and that line must contain the text. Lists every mismatch.
# usage: test_bad_scenes.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
table=$REPO/tests/inputs/bad_scenes.tsv
dir=$REPO/tests/inputs/bad

rows=0
while IFS=$'\t' read -r file status expect; do
    [[ -z $file || $file == \#* ]] && continue
    rows=$((rows + 1))
    "$THZMAP" validate "$dir/$file" >"$work/out" 2>"$work/err"
    got=$?
    msg=$(cat "$work/err")
    problem=""
    if [[ $got -ne $status ]]; then
        problem="exit status $got, expected $status"
    elif [[ -s $work/out ]]; then
        problem="printed to stdout"
    elif [[ $(wc -l <"$work/err") -ne 1 ]]; then
        problem="expected one line on stderr, got $(wc -l <"$work/err")"
    elif [[ $msg != *"$file"* && $msg != *"$dir"* ]]; then
        problem="message does not name the file"
    elif [[ $msg != *"$expect"* ]]; then
        problem="message lacks '$expect'"
    fi
    if [[ -n $problem ]]; then
        echo "FAIL $file: $problem"
        echo "     message: $msg"
        fails=$((fails + 1))
    fi
done <"$table"

if [[ $rows -lt 30 ]]; then
    echo "FAIL: only $rows bad scenes in $table (expected at least 30)"
    exit 1
fi
# every bad scene file is in the table, so none is silently skipped
for f in "$dir"/*.json; do
    name=$(basename "$f")
    if ! cut -f1 "$table" | grep -qxF "$name"; then
        echo "FAIL $name: not listed in bad_scenes.tsv"
        fails=$((fails + 1))
    fi
done
echo "$rows bad scenes, $fails failure(s)"
[[ $fails -eq 0 ]]
