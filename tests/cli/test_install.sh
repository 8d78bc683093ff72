#!/usr/bin/env bash
# cmake --install: installs the already built tree (the one holding THZMAP_BINARY) into
# a fresh temporary prefix P and checks what a user gets there: the shared library
# with its soname links, the public headers, thzmap.pc, the CLI, the man page (every
# command and option of the CLI's --help in it) and the run-time data. Builds every
# examples/api/*.c against P with pkg-config alone and runs it on the installed
# library. Proves that the installed library and CLI read their data from
# P/share/thzmap (a catalogue missing there makes them fail, exit 1 as an I/O error and
# not bad input, naming that path and the remedy, while the build's data/ is complete), also after P is moved, and that THZMAP_DATA_DIR
# overrides; and that scripts/uninstall.sh (make uninstall) removes it all again. Writes
# nothing into the build tree but what `cmake --install` writes.
# usage: test_install.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
build=$(cd "$(dirname "$THZMAP")" && pwd)
work=$(realpath "$work")

# brief FILE: the start of FILE, for a failure message.
brief() {
    head -c 400 "$1"
}

[[ -f $build/cmake_install.cmake ]] || {
    fail "$build (the directory of $THZMAP) is not a CMake build tree"
    finish_counted ok
}
unset THZMAP_DATA_DIR
version_line=$("$THZMAP" --version)
version=$(awk '{print $2}' <<<"$version_line")
[[ $version =~ ^[0-9]+\.[0-9]+\.[0-9]+$ ]] || fail "thzmap --version gave '$version'"
major=${version%%.*}

# --- install ----------------------------------------------------------------------------
P=$work/prefix
if ! cmake --install "$build" --prefix "$P" >"$work/install.log" 2>&1; then
    fail "cmake --install failed: $(cat "$work/install.log")"
    finish_counted ok
fi

# --- the file list ------------------------------------------------------------------------
lib=$P/lib
[[ -f $lib/libthzmap.so.$version && ! -L $lib/libthzmap.so.$version ]] ||
    fail "no regular file lib/libthzmap.so.$version"
[[ $(readlink "$lib/libthzmap.so.$major") == "libthzmap.so.$version" ]] ||
    fail "lib/libthzmap.so.$major is not a link to libthzmap.so.$version"
[[ $(readlink "$lib/libthzmap.so") == "libthzmap.so.$major" ]] ||
    fail "lib/libthzmap.so is not a link to libthzmap.so.$major"
soname=$(readelf -d "$lib/libthzmap.so.$version" 2>/dev/null | sed -n 's/.*Library soname: \[\(.*\)\]/\1/p')
[[ $soname == "libthzmap.so.$major" ]] || fail "soname is '$soname', expected libthzmap.so.$major"
[[ -x $P/bin/thzmap ]] || fail "no executable bin/thzmap"
for h in "$REPO"/include/thzmap/*.h; do
    cmp -s "$h" "$P/include/thzmap/$(basename "$h")" || fail "header $(basename "$h") not installed as is"
done
[[ -f $lib/pkgconfig/thzmap.pc ]] || fail "no lib/pkgconfig/thzmap.pc"
# the docs the headers, the man page and the Python package name as docs/
for d in "$REPO"/docs/*.md; do
    cmp -s "$d" "$P/share/doc/thzmap/docs/$(basename "$d")" || fail "$(basename "$d") not installed under share/doc/thzmap/docs"
done
cmp -s "$REPO/README.md" "$P/share/doc/thzmap/README.md" || fail "README.md not installed under share/doc/thzmap"
[[ -e $P/share/doc/thzmap/docs/thzmap.1 ]] && fail "the man page is also under share/doc/thzmap/docs"
# every relative link of the installed documents leads to an installed file
/usr/bin/python3 - "$P/share/doc/thzmap" <<'PY' || fail "installed documents link to files not installed"
import os, re, sys
root, bad = sys.argv[1], []
for d, _, files in os.walk(root):
    for f in files:
        if not f.endswith(".md"):
            continue
        text = open(os.path.join(d, f), encoding="utf-8").read()
        text = re.sub(r"```.*?```", "", text, flags=re.S)  # code blocks hold no links
        for target in re.findall(r"\]\(([^)\s]+)\)", text):
            if re.match(r"[a-z]+:", target) or target.startswith("#"):
                continue
            path = os.path.normpath(os.path.join(d, target.split("#")[0]))
            if not os.path.exists(path):
                bad.append(f"{os.path.relpath(os.path.join(d, f), root)}: {target}")
print("\n".join(bad), file=sys.stderr)
sys.exit(1 if bad else 0)
PY
(cd "$REPO/data" && find . -type f) | sort >"$work/data.list"
[[ -s $work/data.list ]] || fail "the repository has no data/ files"
while read -r f; do
    cmp -s "$REPO/data/$f" "$P/share/thzmap/$f" || fail "data file $f not installed as is under share/thzmap"
done <"$work/data.list"
grep -q 'AER' "$P/share/thzmap/atmosphere/README.md" 2>/dev/null ||
    fail "the data's README with its licence notices is not installed"

# --- the CLI runs from the prefix, without the environment's help -----------------------
# (the same line as the build tree's: "thzmap X.Y.Z (revision R)")
[[ $("$P/bin/thzmap" --version 2>&1) == "$version_line" ]] || fail "installed thzmap --version: $("$P/bin/thzmap" --version 2>&1)"
"$P/bin/thzmap" materials water >"$work/materials.out" 2>&1 && grep -q '^source: ' "$work/materials.out" ||
    fail "installed thzmap materials water: $(cat "$work/materials.out")"

# --- the man page: renders without warnings, names every command and option ---------------
man1=$P/share/man/man1/thzmap.1
if [[ ! -f $man1 ]]; then
    fail "no share/man/man1/thzmap.1"
elif ! command -v groff >/dev/null; then
    fail "groff is not installed (package groff-base, in scripts/install-deps.sh): cannot check the man page"
else
    LC_ALL=C groff -man -Tutf8 -ww -z "$man1" 2>"$work/groff.err" || fail "groff failed on thzmap.1"
    [[ -s $work/groff.err ]] && fail "groff warnings on thzmap.1: $(cat "$work/groff.err")"
    LC_ALL=C groff -man -Tutf8 -P-cbou "$man1" 2>/dev/null >"$work/man.txt"
    for section in NAME SYNOPSIS DESCRIPTION COMMANDS FILES ENVIRONMENT 'EXIT STATUS'; do
        grep -q "^$section" "$work/man.txt" || fail "thzmap.1 has no $section section"
    done
    # every environment variable the program reads
    awk '/^ENVIRONMENT/ {f = 1; next} /^[A-Z]/ {f = 0} f' "$work/man.txt" >"$work/man.environment"
    variables=$(grep -rhoE 'getenv\("[A-Z_]+"\)' "$REPO/src" | sed -E 's/getenv\("([A-Z_]+)"\)/\1/' | sort -u)
    [[ $variables == *THZMAP_DATA_DIR* ]] || fail "no getenv(\"THZMAP_DATA_DIR\") found in src/"
    for v in $variables; do
        grep -Eq "^ +$v( |\$)" "$work/man.environment" || fail "thzmap.1 ENVIRONMENT does not describe $v (src/ reads it)"
    done
    commands=$("$THZMAP" --help | awk '/^commands:/ {f = 1; next} f && /^  [a-z]/ {print $1}')
    [[ -n $commands ]] || fail "no commands in thzmap --help"
    awk '/^COMMANDS/ {f = 1; next} /^[A-Z]/ {f = 0} f' "$work/man.txt" >"$work/man.commands"
    for c in $commands; do
        grep -Eq "^ +$c( |\$)" "$work/man.commands" || fail "thzmap.1 COMMANDS does not describe '$c'"
        options=$("$THZMAP" "$c" --help | grep -oE -- '(^| )--?[a-z0-9][a-z0-9-]*' | tr -d ' ' | sort -u)
        [[ -n $options ]] || fail "no options in 'thzmap $c --help'"
        for o in $options; do
            [[ $o == -h || $o == --help ]] && continue
            grep -Eq -- "(^|[^a-z0-9-])$o([^a-z0-9-]|\$)" "$work/man.txt" ||
                fail "thzmap.1 does not mention option $o of '$c'"
        done
    done
fi

# --- pkg-config -------------------------------------------------------------------------------
export PKG_CONFIG_PATH=$lib/pkgconfig
[[ $(pkg-config --modversion thzmap 2>&1) == "$version" ]] || fail "pkg-config --modversion thzmap: $(pkg-config --modversion thzmap 2>&1)"
[[ $(pkg-config --variable=prefix thzmap) == "$P" ]] || fail "thzmap.pc has prefix $(pkg-config --variable=prefix thzmap), expected $P"
flags=$(pkg-config --cflags --libs thzmap) || fail "pkg-config --cflags --libs thzmap failed"
[[ $flags == *"-I$P/include"* && $flags == *"-L$lib"* && $flags == *"-lthzmap"* ]] ||
    fail "pkg-config --cflags --libs thzmap gave: $flags"
[[ $flags == *"$REPO"* || $flags == *"$build"* ]] && fail "pkg-config flags point into the source or build tree: $flags"
pkg-config --static --libs thzmap | grep -q -- -lembree3 || fail "pkg-config --static --libs lacks -lembree3"

# --- every examples/api/*.c, built against P alone --------------------------------------------
cc=${CC:-cc}
extra=()
if grep -q '^THZ_SANITIZE:BOOL=ON' "$build/CMakeCache.txt"; then
    # An instrumented library needs the sanitizer runtime in the program too.
    cc=$(sed -n 's/^CMAKE_C_COMPILER:[A-Z]*=//p' "$build/CMakeCache.txt")
    extra=(-fsanitize=address,undefined)
fi
scene=$REPO/examples/plate-in-box/scene.json
examples=("$REPO"/examples/api/*.c)
[[ -f ${examples[0]} ]] || fail "no examples/api/*.c"
for src in "${examples[@]}"; do
    name=$(basename "$src" .c)
    # shellcheck disable=SC2046 # the flags are words
    if ! "$cc" -std=c17 -Wall -Wextra -Wpedantic -Werror "${extra[@]}" "$src" -o "$work/$name" \
        $(pkg-config --cflags --libs thzmap) >"$work/$name.cc" 2>&1; then
        fail "examples/api/$name.c does not build against the installed tree: $(cat "$work/$name.cc")"
        continue
    fi
    resolved=$(LD_LIBRARY_PATH=$lib ldd "$work/$name" | awk '/libthzmap/ {print $3}')
    [[ $resolved == "$lib/libthzmap.so.$major" ]] || fail "$name loads libthzmap from '$resolved', not $lib"
    mkdir -p "$work/run-$name"
    if ! (cd "$work/run-$name" && LD_LIBRARY_PATH=$lib "$work/$name" "$scene") >"$work/$name.out" 2>&1; then
        fail "examples/api/$name on plate-in-box: $(cat "$work/$name.out")"
    fi
done

# --- the installed data directory is the one used ----------------------------------------------
# A scene with the line-by-line atmosphere reads the catalogues while it loads.
mkdir -p "$work/lines"
cp -r "$REPO/examples/plate-in-box/." "$work/lines/"
sed 's/"model": "constant", "attenuation_per_m": 0.05/"model": "lines", "temperature_k": 293, "pressure_hpa": 1000, "relative_humidity": 0.5/' \
    "$scene" >"$work/lines/scene.json"
grep -q '"model": "lines"' "$work/lines/scene.json" || fail "could not make the lines scene"
load=$work/load_scene
catalogue=atmosphere/am14_h2o_lines.csv

# expect_load WHAT STATUS PATTERN [ENV...]: load_scene on the lines scene exits STATUS and
# its output matches PATTERN (fixed string, empty: anything).
expect_load() {
    local what=$1 want=$2 pattern=$3
    shift 3
    env "$@" LD_LIBRARY_PATH="$lib" "$load" "$work/lines/scene.json" >"$work/load.out" 2>&1
    local status=$?
    [[ $status -eq $want ]] || fail "$what: load_scene exit $status, expected $want: $(brief "$work/load.out")"
    [[ -z $pattern ]] || grep -qF -- "$pattern" "$work/load.out" ||
        fail "$what: expected '$pattern' in: $(brief "$work/load.out")"
}

# expect_cli WHAT STATUS PATTERN: the installed CLI validates the lines scene likewise.
expect_cli() {
    "$P/bin/thzmap" validate "$work/lines/scene.json" >"$work/cli.out" 2>&1
    local status=$?
    [[ $status -eq $2 ]] || fail "$1: installed thzmap validate exit $status, expected $2: $(brief "$work/cli.out")"
    [[ -z $3 ]] || grep -qF -- "$3" "$work/cli.out" || fail "$1: expected '$3' in: $(brief "$work/cli.out")"
}

if [[ -x $load ]]; then
    expect_load "installed, complete" 0 ""
    expect_cli "installed, complete" 0 ""
    # The build's data/ stays complete: only the installed copy loses a catalogue.
    mv "$P/share/thzmap/$catalogue" "$work/catalogue.csv"
    "$THZMAP" validate "$work/lines/scene.json" >/dev/null 2>&1 ||
        fail "the build tree's thzmap no longer loads the lines scene (its data/ must be untouched)"
    expect_load "installed, catalogue missing" 1 "$P/share/thzmap/$catalogue: cannot read thzmap's own data file"
    expect_cli "installed, catalogue missing" 1 "(installed with the library) lacks it: reinstall thzmap, or set THZMAP_DATA_DIR"
    # Moved as a whole, the tree still finds its own data (nothing of P compiled in).
    mv "$P" "$work/moved"
    P=$work/moved lib=$work/moved/lib
    expect_load "moved prefix, catalogue missing" 1 "$P/share/thzmap/$catalogue"
    expect_cli "moved prefix, catalogue missing" 1 "$P/share/thzmap/$catalogue"
    mv "$work/catalogue.csv" "$P/share/thzmap/$catalogue"
    expect_load "moved prefix, complete" 0 ""
    # THZMAP_DATA_DIR overrides the installed directory, also to fail.
    mkdir -p "$work/alt"
    cp -r "$REPO/data/." "$work/alt/"
    rm "$work/alt/$catalogue"
    expect_load "THZMAP_DATA_DIR without the catalogue" 1 "$work/alt (from THZMAP_DATA_DIR) lacks it" THZMAP_DATA_DIR="$work/alt"
    cp "$REPO/data/$catalogue" "$work/alt/$catalogue"
    mv "$P/share/thzmap/$catalogue" "$work/catalogue.csv"
    expect_load "THZMAP_DATA_DIR complete, installed incomplete" 0 "" THZMAP_DATA_DIR="$work/alt"
    mv "$work/catalogue.csv" "$P/share/thzmap/$catalogue"
    # Without an installed data directory the build's data/ is the fallback.
    mv "$P/share/thzmap" "$work/share-aside"
    expect_load "no installed data directory" 0 ""
else
    fail "examples/api/load_scene.c did not build: cannot check the data directory"
fi

# --- make uninstall (scripts/uninstall.sh) removes what the install put there, no more --------
U=$work/uninstall
if cmake --install "$build" --prefix "$U" >"$work/install2.log" 2>&1; then
    python_dir=$(find "$U" -type d -path '*-packages/thzmap' | head -1)
    [[ -n $python_dir ]] && mkdir -p "$python_dir/__pycache__" && touch "$python_dir/__pycache__/x.pyc"
    touch "$U/lib/someone-else.so"
    mkdir -p "$U/share/man/man1"
    if bash "$REPO/scripts/uninstall.sh" "$build" "$U" >"$work/uninstall.log" 2>&1; then
        (cd "$U" && find . -type f) >"$work/left"
        [[ $(cat "$work/left") == "./lib/someone-else.so" ]] ||
            fail "uninstall left (or removed) files: $(tr '\n' ' ' <"$work/left")"
        for d in include/thzmap share/thzmap share/doc/thzmap "${python_dir#"$U"/}"; do
            [[ -e $U/$d ]] && fail "uninstall left the directory $d"
        done
        [[ -d $U/share/man/man1 && -d $U/lib ]] || fail "uninstall removed a shared directory"
    else
        fail "uninstall.sh failed: $(cat "$work/uninstall.log")"
    fi
else
    fail "the second cmake --install failed: $(cat "$work/install2.log")"
fi

finish_counted ok
