#!/usr/bin/env bash
# The paper's test case (examples/teraeye): simulate it and list what was written.
#   usage: scripts/demo.sh THZMAP OUTDIR      (the README's `make demo` calls it)
set -euo pipefail

if [ $# -ne 2 ]; then
    echo "usage: $0 THZMAP OUTDIR" >&2
    exit 2
fi
thzmap=$1
outdir=$2
repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
scene=$repo/examples/teraeye/scene.json

"$thzmap" validate "$scene" >/dev/null
echo "simulating $scene (6 channels x 10 million photons; a few minutes on 2 cores)"
# No --save-photon-map: at 10 M photons per channel the map file is about 1.5 GB.
"$thzmap" simulate "$scene" -o "$outdir"

echo
echo "written to $outdir:"
ls -lh "$outdir"
echo
echo "start with $outdir/cam.spectra.png (the paper's Fig. 6), $outdir/cam.band-01.png ..."
echo "$outdir/cam.band-06.png and $outdir/cam.visual.png; docs/user-guide.md says how to"
echo "read the ENVI cubes (cam.*.hdr) in Python."
