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
echo "simulating $scene with the paper's method (photon-map: 6 channels x 10 million"
echo "photons; 12-15 s on 2 idle cores)"
# No --save-photon-map: at 10 M photons per channel the map file is about 1.6 GB.
"$thzmap" simulate "$scene" --integrator photon-map -o "$outdir"

echo
echo "rendering it again with the converged backward integrator (path, the default, to a"
echo "95th percentile of the pixels' standard error of 0.1 K; a few seconds)"
"$thzmap" render "$scene" --integrator path -o "$outdir/path"

echo
echo "written to $outdir (photon-map) and $outdir/path (path):"
ls -lh "$outdir" "$outdir/path"
echo
echo "start with $outdir/path/cam.spectra.png (the paper's Fig. 6), then compare"
echo "$outdir/cam.band-06.png (photon-map, the paper's estimate) with"
echo "$outdir/path/cam.band-06.png (converged); docs/user-guide.md says how to read the"
echo "ENVI cubes (cam.*.hdr) in Python."
