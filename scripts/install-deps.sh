#!/usr/bin/env bash
# Installs the Debian packages thzmap needs to build, test and run, if any is missing.
# Run as root on Debian 12 (bookworm). Idempotent: does nothing when all are present.
set -euo pipefail
packages=(
  build-essential cmake ninja-build pkg-config clang libomp-dev groff-base
  libembree-dev libjansson-dev libassimp-dev librandom123-dev libpng-dev libzstd-dev
  libplplot-dev plplot-driver-cairo libcmocka-dev libfftw3-dev
  libavcodec-dev libavformat-dev libavutil-dev libswscale-dev ffmpeg
  python3 python3-numpy python3-spectral gdal-bin python3-gdal
  python3-pytest python3-matplotlib python3-sklearn python3-tqdm
  strace zstd
  libmicrohttpd-dev  # optional: thzmap serve, the browser GUI (docs/gui.md)
  libopenmpi-dev openmpi-bin  # optional: MPI runs (docs/mpi.md)
  libclang-rt-14-dev  # libFuzzer for clang -fsanitize=fuzzer (make fuzz)
  nodejs  # the web page's bundle (three.js, esbuild from npm; docs/gui.md)
  chromium chromium-driver python3-selenium  # its end-to-end test (tests/gui)
)
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
