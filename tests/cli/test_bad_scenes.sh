#!/usr/bin/env bash
# Table-driven test of bad scenes: for every row of tests/inputs/bad_scenes.tsv
# (file, expected exit status, text the message must contain), `thzmap validate`
# must exit with that status, print nothing to stdout, print exactly one line to
# stderr naming the file, and that line must contain the text. Lists every mismatch.
# usage: test_bad_scenes.sh THZMAP_BINARY REPO_DIR
set -u
thzmap=$1
repo=$2
table=$repo/tests/inputs/bad_scenes.tsv
dir=$repo/tests/inputs/bad
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT

failures=0
rows=0
while IFS=$'\t' read -r file status expect; do
    [[ -z $file || $file == \#* ]] && continue
    rows=$((rows + 1))
    "$thzmap" validate "$dir/$file" >"$tmp/out" 2>"$tmp/err"
    got=$?
    msg=$(cat "$tmp/err")
    problem=""
    if [[ $got -ne $status ]]; then
        problem="exit status $got, expected $status"
    elif [[ -s $tmp/out ]]; then
        problem="printed to stdout"
    elif [[ $(wc -l <"$tmp/err") -ne 1 ]]; then
        problem="expected one line on stderr, got $(wc -l <"$tmp/err")"
    elif [[ $msg != *"$file"* && $msg != *"$dir"* ]]; then
        problem="message does not name the file"
    elif [[ $msg != *"$expect"* ]]; then
        problem="message lacks '$expect'"
    fi
    if [[ -n $problem ]]; then
        echo "FAIL $file: $problem"
        echo "     message: $msg"
        failures=$((failures + 1))
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
        failures=$((failures + 1))
    fi
done
echo "$rows bad scenes, $failures failure(s)"
[[ $failures -eq 0 ]]
