#!/usr/bin/env python3
"""Simulates the paper's test scene (examples/teraeye) with photon mapping on every rank
of an MPI job: the ranks share each channel's photons and the pixels, rank 0 writes the
files `thzmap simulate` writes, the same bytes as one process would.

    mpirun -np 4 python3 -m mpi4py examples/python/simulate_mpi.py [--out DIR]
        [--photons N] [--threads T]

(`python3 -m mpi4py` ends the whole job when any rank raises.) Without mpirun it runs as
one process. THZMAP_EXAMPLE_SMALL=1 fires 200 000 photons per channel instead of the
scene's 10 million, for tests.
"""
import argparse
import os

import thzmap

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "..", "teraeye", "scene.json")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/teraeye-mpi", help="the output directory")
    small = os.environ.get("THZMAP_EXAMPLE_SMALL") == "1"
    ap.add_argument("--photons", type=int, default=200_000 if small else None,
                    help="photons per channel (default: the scene's)")
    ap.add_argument("--threads", type=int, default=1, help="threads per rank")
    args = ap.parse_args()

    scene = thzmap.load_scene(SCENE)  # every rank loads the same scene
    result = thzmap.simulate(scene, integrator="photon-map", photons=args.photons,
                             threads=args.threads, mpi=True)
    if result is None:  # a rank other than 0: its share is done
        return
    result.save(args.out)
    summary = result.summary
    print(f"{summary['mpi_ranks']} MPI rank(s), {summary['threads']} thread(s) each: "
          f"{len(summary['channels'])} channels, {result.mpi_bytes / 1e6:.3g} MB "
          f"communicated; results in {args.out}")


if __name__ == "__main__":
    main()
