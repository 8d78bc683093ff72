#!/usr/bin/env bash
# The README's two set-up commands:
#   bash scripts/setup.sh demo    install what is missing, build, run the paper's test scene
#   bash scripts/setup.sh check   install what is missing, build, run every test (also ASan+UBSan)
# On a fresh Debian 12 machine as root this is all it takes; it installs the Debian
# packages listed in scripts/install-deps.sh (make and the compilers among them).
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
  demo|check) ;;
  *) echo "usage: bash scripts/setup.sh demo|check" >&2; exit 2 ;;
esac
bash scripts/install-deps.sh
exec make "$1"
