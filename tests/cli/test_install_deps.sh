#!/usr/bin/env bash
# scripts/install-deps.sh: "build" asks only for what building and running need, so a
# user installing into a prefix of their own is not stopped by a test-only package;
# the full set (no argument) names a missing test package and, without root, exits 1.
# dpkg-query, id and npm are stand-ins on PATH: nothing is installed or asked of apt.
# usage: test_install_deps.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"
mkdir "$work/bin"
# every package installed but chromium (the web page's end-to-end test only)
cat >"$work/bin/dpkg-query" <<'SH'
#!/bin/sh
for last; do :; done
[ "$last" = chromium ] && exit 1
printf 'install ok installed'
SH
printf '#!/bin/sh\necho 1000\n' >"$work/bin/id"  # not root
printf '#!/bin/sh\nexit 0\n' >"$work/bin/npm"
chmod +x "$work/bin/"*
run() {
    PATH=$work/bin:/usr/bin:/bin bash "$REPO/scripts/install-deps.sh" "$@" >"$work/out" 2>&1
}
run build
status=$?
[[ $status -eq 0 ]] || fail "install-deps.sh build without chromium, not root: exit $status: $(cat "$work/out")"
run
status=$?
[[ $status -eq 1 ]] && grep -q 'missing packages: chromium' "$work/out" ||
    fail "install-deps.sh (all) without chromium, not root: exit $status: $(cat "$work/out")"
grep -q 'run as root' "$work/out" || fail "install-deps.sh does not say to run as root: $(cat "$work/out")"
run nonsense
[[ $? -eq 2 ]] || fail "install-deps.sh nonsense: exit $?, expected 2"
# the Makefile: build and install take the build set, the tests the full one
grep -Eq '^build: deps-build$' "$REPO/Makefile" || fail "make build does not depend on deps-build"
grep -Eq '^test: deps build$' "$REPO/Makefile" || fail "make test does not depend on deps"
finish_counted ok
