#!/usr/bin/env bash
# The README's two set-up commands:
#   bash scripts/setup.sh demo    install what is missing, build, run the paper's test scene
#   bash scripts/setup.sh check   install what is missing, build, run every test (also ASan+UBSan),
#                                 then fuzz each file reader for 20 s
# On a fresh Debian 12 machine as root this is all it takes; it installs the Debian
# packages listed in scripts/install-deps.sh (make and the compilers among them).
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
  demo|check) ;;
  *) echo "usage: bash scripts/setup.sh demo|check" >&2; exit 2 ;;
esac
bash scripts/install-deps.sh
# Build and install under /usr/local (CLI, libthzmap, headers, thzmap.pc, man page, data,
# and the Python package where Debian's python3 finds it), then check that a python3
# started elsewhere, with no PYTHONPATH, imports the installed package.
make install PREFIX=/usr/local
ldconfig 2>/dev/null || true
(cd / && env -u PYTHONPATH -u THZMAP_LIBRARY /usr/bin/python3 -c \
  'import thzmap; print("setup: python3 imports thzmap from", thzmap.__file__, "using", thzmap.library_path)')
exec make "$1"
