#!/usr/bin/python3
"""Reads photon-map.ply as a generic PLY client would (header, then the binary body by
the declared properties) and checks it against photon-map.thzpm of the same run: the
same photons (position, channel, signed power, object) as multisets when the file is
not capped, and per point a unit direction whose colour is round(255 * 0.5 * (1 - d)).

usage: photon_ply.py OUTDIR N_CHANNELS N_OBJECTS [--negative]: --negative requires some
photons of negative power (a deviation map's). Exits 1 with a message on a mismatch.
"""
import struct
import subprocess
import sys

TYPES = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I",
         "float": "f", "double": "d"}


def fail(msg):
    print(f"photon_ply: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def read_ply(path):
    data = open(path, "rb").read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    lines = data[:end].decode("ascii").splitlines()
    if lines[0] != "ply" or lines[1] != "format binary_little_endian 1.0":
        fail(f"{path}: not a binary little-endian PLY")
    count, props = None, []
    for line in lines[2:]:
        w = line.split()
        if w[0] == "element":
            if w[1] != "vertex" or count is not None:
                fail(f"{path}: unexpected element line {line!r}")
            count = int(w[2])
        elif w[0] == "property":
            if w[1] == "list":
                fail(f"{path}: unexpected list property")
            props.append((w[2], TYPES[w[1]]))
    fmt = "<" + "".join(t for _, t in props)
    size = struct.calcsize(fmt)
    if len(data) != end + count * size:
        fail(f"{path}: {len(data) - end} body bytes for {count} points of {size} bytes")
    names = [n for n, _ in props]
    return [dict(zip(names, v)) for v in struct.iter_unpack(fmt, data[end:])]


def read_thzpm(path):
    """The records of each channel, from the zstd frames after the 24-byte prefix."""
    data = open(path, "rb").read()
    if struct.unpack_from("<I", data, 8)[0] != 4:
        fail(f"{path}: not a version-4 photon map")
    raw = data[24:]
    out = subprocess.run(["zstd", "-dc"], input=raw, capture_output=True, check=True).stdout
    n_channels = struct.unpack_from("<Q", out, 8 * 3)[0]  # after the 3 scene hashes
    header = 8 * (7 + 21 * n_channels)
    counts = [struct.unpack_from("<Q", out, 8 * (7 + 21 * c + 2))[0] for c in range(n_channels)]
    records, at = [], header
    for c, n in enumerate(counts):
        # version 4's 28-byte records: the tag holds object << 5 | side << 4 | bits
        for r in struct.iter_unpack("<3f f f I I", out[at:at + 28 * n]):
            records.append((c, r[0], r[1], r[2], r[3], r[6] >> 5))
        at += 28 * n
    if at != len(out):
        fail(f"{path}: {len(out) - at} bytes after the records")
    return records


def main():
    outdir, n_channels, n_objects = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    points = read_ply(f"{outdir}/photon-map.ply")
    records = read_thzpm(f"{outdir}/photon-map.thzpm")
    if set(p["channel"] for p in points) != set(range(n_channels)):
        fail(f"the points' channels {sorted(set(p['channel'] for p in points))}")
    if len(points) != len(records):
        fail(f"{len(points)} points, {len(records)} photons in the map (expected all)")
    got = sorted((p["channel"], p["x"], p["y"], p["z"], p["power_w_per_hz"], p["object"])
                 for p in points)
    if got != sorted(records):
        fail("the points are not the photon map's photons (position, channel, power, object)")
    negative = 0
    for p in points:
        d = (p["dx"], p["dy"], p["dz"])
        if abs(sum(x * x for x in d) - 1) > 1e-5:
            fail(f"direction {d} is not a unit vector")
        rgb = tuple(min(255, max(0, int(255 * 0.5 * (1 - x) + 0.5))) for x in d)
        if rgb != (p["red"], p["green"], p["blue"]):
            fail(f"colour {(p['red'], p['green'], p['blue'])} != {rgb} for direction {d}")
        if not (0 <= p["channel"] < n_channels and 0 <= p["object"] < n_objects):
            fail(f"channel {p['channel']} or object {p['object']} out of range")
        negative += p["power_w_per_hz"] < 0
    if "--negative" in sys.argv and negative == 0:
        fail("no photon of negative power, expected a deviation map's")
    print(f"photon_ply: {len(points)} points match the photon map's photons "
          f"({negative} with negative power); colours follow the directions")


if __name__ == "__main__":
    main()
