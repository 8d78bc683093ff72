#!/usr/bin/env bash
# Installs the Debian packages thzmap needs, if any is missing.
#   install-deps.sh build   what building, installing and running need (make build,
#                           make install, make demo): a user installing into a prefix
#                           of their own needs only these
#   install-deps.sh         those and what the tests, the fuzzing and the benchmark's
#                           comparisons need (make test, make check, make fuzz)
# Run as root on Debian 12 (bookworm). Idempotent: does nothing when all are present;
# without root it names the missing packages and exits 1.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config
  libembree-dev libjansson-dev libassimp-dev librandom123-dev libpng-dev libzstd-dev
  libplplot-dev plplot-driver-cairo libcmocka-dev libfftw3-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev
  python3 python3-numpy  # the Python package
  libmicrohttpd-dev  # optional: thzmap serve, the browser GUI (docs/gui.md)
  libopenmpi-dev openmpi-bin python3-mpi4py  # optional: MPI runs, also from Python (docs/mpi.md)
  nodejs  # the web page's bundle (three.js, esbuild from npm; docs/gui.md)
)
case "${1:-all}" in
  build) ;;
  all)
    packages+=(
      clang libomp-dev  # the clang build the tests compare (make test-compilers)
      clang-format  # the code's layout (.clang-format: make format, tests/cli/test_format.sh)
      groff-base ffmpeg strace zstd  # the man page's, movies' and I/O checks
      locales  # a comma-decimal locale the library must ignore (tests/python/test_locale.py)
      valgrind  # memcheck over the build for any x86-64 (tests/builds/memcheck.sh)
      python3-spectral gdal-bin python3-gdal  # reading the ENVI cubes back
      python3-pytest python3-matplotlib python3-sklearn python3-tqdm
      libclang-rt-14-dev  # libFuzzer for clang -fsanitize=fuzzer (make fuzz)
      chromium chromium-driver python3-selenium  # the web page's end-to-end test (tests/gui)
    ) ;;
  *) echo "usage: install-deps.sh [build|all]" >&2; exit 2 ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
# Debian's nodejs comes without npm (its package npm); NodeSource's nodejs includes it and
# conflicts with Debian's npm: ask for the package only when there is no npm command.
command -v npm >/dev/null 2>&1 || missing+=(npm)
if [ ${#missing[@]} -eq 0 ]; then
  exit 0
fi
if [ "$(id -u)" -ne 0 ]; then
  echo "install-deps: missing packages: ${missing[*]}" >&2
  echo "install-deps: run as root, or install them with apt-get" >&2
  exit 1
fi
echo "install-deps: installing ${missing[*]}" >&2
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
