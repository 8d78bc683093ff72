#!/usr/bin/python3
"""Opens every ENVI header thzmap wrote with two independent readers, Spectral Python
and GDAL, and checks what they report against the scene and against the raw bytes.

usage: envi_readers.py OUTDIR SCENE.json   (run with Debian's /usr/bin/python3, which has
python3-spectral and python3-gdal). Exits 1 with a message on the first mismatch.
"""
import glob
import json
import os
import subprocess
import sys

import numpy as np
import spectral
from osgeo import gdal

gdal.UseExceptions()

CUBES = ["radiance", "power", "brightness_temperature", "normalized"]
TRUTH = ["temperature", "distance", "object_id"]
# scene-format.md "Outputs": the unit of each quantity, in the ASCII `data units` key
UNITS = {"radiance": "W m-2 sr-1 Hz-1", "radiance_stderr": "W m-2 sr-1 Hz-1", "power": "W",
         "brightness_temperature": "K", "normalized": "1", "temperature": "K", "distance": "m",
         "object_id": "1"}
NOTHING_HIT = -1.0  # every truth map's value, and `data ignore value`, where nothing is hit


def fail(msg):
    print(f"envi_readers: FAIL: {msg}", file=sys.stderr)
    sys.exit(1)


def check(cond, msg):
    if not cond:
        fail(msg)


def channels_of(scene):
    ch = scene["channels"]
    if isinstance(ch, dict):  # {from_thz, to_thz, count, relative_width}
        n = ch["count"]
        freqs = [ch["from_thz"] + (ch["to_thz"] - ch["from_thz"]) * i / (n - 1) for i in range(n)]
        return [(f"{f:.3f} THz", f) for f in freqs]
    return [(c.get("name", f"{c['frequency_thz']:.3f} THz"), c["frequency_thz"]) for c in ch]


def main():
    outdir, scene_path = sys.argv[1], sys.argv[2]
    scene = json.load(open(scene_path))
    channels = channels_of(scene)
    names = [n for n, _ in channels]
    ghz = [f * 1000.0 for _, f in channels]
    n_objects = len(scene["objects"])

    check(not glob.glob(os.path.join(outdir, ".thzmap-staging-*")), "staging directory left")
    summary = json.load(open(os.path.join(outdir, "summary.json")))
    check([c["name"] for c in summary["channels"]] == names, "summary.json channel names")

    for sensor in scene["sensors"]:
        s = sensor["name"]
        cols, rows = sensor["resolution"]
        for png in ["visual", "spectra"] + [f"band-{i + 1:02d}" for i in range(len(channels))]:
            path = os.path.join(outdir, f"{s}.{png}.png")
            check(open(path, "rb").read(8) == b"\x89PNG\r\n\x1a\n", f"{path} is not a PNG")
        quantities = CUBES + TRUTH
        truth = {}
        if os.path.exists(os.path.join(outdir, f"{s}.radiance_stderr.hdr")):
            quantities.append("radiance_stderr")
        for q in quantities:
            hdr = os.path.join(outdir, f"{s}.{q}.hdr")
            img = os.path.join(outdir, f"{s}.{q}.img")
            per_channel = q not in TRUTH
            bands = len(channels) if per_channel else 1
            dtype = np.dtype("<f4")  # every image, object_id too (scene-format.md "Outputs")
            raw = np.fromfile(img, dtype=dtype)
            check(raw.size == cols * rows * bands, f"{img}: {raw.size} values")
            raw = raw.reshape(bands, rows, cols)  # BSQ

            # Spectral Python
            im = spectral.open_image(hdr)
            check(im.shape == (rows, cols, bands), f"{hdr}: spectral shape {im.shape}")
            check(np.dtype(im.dtype) == dtype, f"{hdr}: spectral dtype {im.dtype}")
            data = im.open_memmap(interleave="bip")  # rows x columns x bands, as stored
            check(np.array_equal(np.asarray(data), raw.transpose(1, 2, 0)),
                  f"{hdr}: spectral data differ from the raw bytes")
            check(im.metadata.get("data units") == UNITS[q],
                  f"{hdr}: data units {im.metadata.get('data units')!r} != {UNITS[q]!r}")
            if per_channel:
                check(im.metadata.get("band names") == names,
                      f"{hdr}: band names {im.metadata.get('band names')} != {names}")
                check(im.bands.band_unit == "GHz", f"{hdr}: wavelength units {im.bands.band_unit}")
                check(np.allclose(im.bands.centers, ghz, rtol=1e-9),
                      f"{hdr}: wavelengths {im.bands.centers} != {ghz} GHz")

            # GDAL, through the Python binding and through gdalinfo
            ds = gdal.Open(img)
            check((ds.RasterXSize, ds.RasterYSize, ds.RasterCount) == (cols, rows, bands),
                  f"{img}: GDAL size")
            check(ds.GetDriver().ShortName == "ENVI", f"{img}: GDAL driver")
            for b in range(bands):
                band = ds.GetRasterBand(b + 1)
                check(np.array_equal(band.ReadAsArray(), raw[b]), f"{img}: GDAL band {b + 1}")
                if per_channel:
                    md = band.GetMetadata()
                    check(band.GetDescription().startswith(names[b]),
                          f"{img}: GDAL band {b + 1} description {band.GetDescription()!r}")
                    check(md.get("wavelength_units") == "GHz", f"{img}: GDAL wavelength units")
                    check(abs(float(md["wavelength"]) - ghz[b]) <= 1e-9 * ghz[b],
                          f"{img}: GDAL wavelength {md.get('wavelength')} != {ghz[b]}")
            ds = None
            # GDAL keeps every header key in its ENVI metadata domain; `data units` is the
            # ENVI key for the unit of the values (GDAL 3.6 maps no key to a band's unit type)
            info = json.loads(subprocess.run(["gdalinfo", "-json", "-mdd", "ENVI", img],
                                             check=True, capture_output=True, text=True).stdout)
            check(info["size"] == [cols, rows] and len(info["bands"]) == bands,
                  f"{img}: gdalinfo size")
            units = info.get("metadata", {}).get("ENVI", {}).get("data_units")
            check(units == UNITS[q], f"{img}: gdalinfo data_units {units!r} != {UNITS[q]!r}")
            nodata = [b.get("noDataValue") for b in info["bands"]]
            if per_channel:
                check(nodata == [None] * bands, f"{img}: gdalinfo no-data {nodata} on a cube")
            else:
                check(nodata == [NOTHING_HIT], f"{img}: gdalinfo no-data {nodata}")
                check(float(im.metadata.get("data ignore value", "nan")) == NOTHING_HIT,
                      f"{hdr}: spectral data ignore value")
                truth[q] = raw[0]

            if q == "object_id":
                check(raw.min() >= -1 and raw.max() < n_objects, f"{img}: ids out of range")
                check(np.array_equal(raw, np.round(raw)), f"{img}: ids are not whole numbers")
                objects = [o["name"] for o in scene["objects"]]
                check(im.metadata.get("object names") == objects,
                      f"{hdr}: object names {im.metadata.get('object names')} != {objects}")
                ds = gdal.Open(img)  # kept while its band is used: GDAL frees bands with it
                nodata = ds.GetRasterBand(1).GetNoDataValue()
                ds = None
                check(nodata == NOTHING_HIT, f"{img}: GDAL no-data value {nodata}")
                ids = raw[0].astype(np.int32)
            if q == "brightness_temperature":
                tb = raw
        hit = ids >= 0
        check(hit.any() == (s != "sky"), f"{s}: the sensor sees {hit.sum()} object pixels")
        for q in ["temperature", "distance"]:
            check(np.all(truth[q][hit] > 0), f"{s}.{q}: not positive where an object is seen")
            check(np.all(truth[q][~hit] == NOTHING_HIT), f"{s}.{q}: not -1 where nothing is hit")
        if s == "sky":
            continue
        check(np.all(np.isfinite(tb)) and np.all(tb[:, hit] > 0), f"{s}: brightness temperature")
    print(f"envi_readers: every header opens in Spectral Python {spectral.__version__} and "
          f"GDAL {gdal.__version__}; band names, GHz wavelengths, data units and the truth "
          f"maps' ignore value match the scene")


if __name__ == "__main__":
    main()
