#!/usr/bin/env bash
# The sensor as built (scene-format.md "Sensors: optics and noise"), end to end:
#  - noise: a black furnace at 300 K (path: every pixel exactly B(300 K)) seen by three
#    sensors (total-power, Dicke, given NETD per channel), two channels, 128 x 128: the
#    measured Tb's standard deviation is K (T + T_rec) / sqrt(B_n tau) (or the given
#    NETD) within 3 sigma of its sampling error, the mean is unbiased within
#    3 NETD / sqrt(N), neighbouring pixels and the two channels are uncorrelated
#    (|r| < 3 / sqrt(N)) (sensor_check.py); with a 1000 K ball in view, the NETD follows
#    each pixel's Tb (not the channel's reference temperature);
#  - the noise-free cubes are byte for byte those of the same scene without the model;
#  - the measured cubes are bit-identical for --threads 1 and 2, and `render` from a
#    saved photon map gives simulate's measured cubes;
#  - PSF: a black disk at 1000 K far below the diffraction limit (0.6 mrad across,
#    lambda/D 17 mrad) in two channels: the radial profile of the measured radiance
#    matches the band-averaged Airy pattern, FWHM within 3 % of it, summed power within
#    0.5 % of the sharp image's;
#  - summary.json names the model, validate prints NETD and spot size with units, and a
#    bad noise block is refused with its JSON path (exit 2), as is, before the work, a PSF
#    too much wider than the image to fold onto it.
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
run() { # $1: what, rest: thzmap arguments
    local what=$1
    shift
    if ! "$THZMAP" "$@" --quiet > "$work/$what.log" 2>&1; then
        fail "$what: thzmap $* failed"
        cat "$work/$what.log"
    fi
}
check() { # python checks
    if ! /usr/bin/python3 "$REPO/tests/cli/sensor_check.py" "$@"; then
        fail "sensor_check.py $*"
    fi
}

# ---- noise: the furnace ----------------------------------------------------------------
furnace() { # $1: file, $2: "model" or "" (the same scene without the sensor model)
    local tp='' dk='' nd=''
    if [ "$2" = model ]; then
        tp=', "noise": {"receiver_temperature_k": 500, "integration_time_s": 0.01, "radiometer": "total-power"}'
        dk=', "noise": {"receiver_temperature_k": 800, "integration_time_s": 0.004, "radiometer": "dicke"}'
        nd=', "noise": {"netd_k": [0.5, 0.2]}, "noise_seed": 7'
    fi
    local cam='"position_m": [0, 0, 0], "direction": [0, 1, 0], "fov_deg": 30, "resolution": [128, 128]'
    cat > "$1" <<EOF
{"format": "thzmap-scene/1", "name": "furnace",
 "channels": [{"frequency_thz": 0.35, "relative_width": 0.01},
              {"frequency_thz": 0.65, "relative_width": 0.01}],
 "materials": {"black": {"reflectivity": 0}},
 "objects": [{"name": "box", "type": "solid", "material": "black", "temperature_k": 300,
              "shape": {"type": "box", "size_m": [4, 4, 4], "inward": true}}],
 "sensors": [{"name": "tp", $cam$tp}, {"name": "dicke", $cam$dk}, {"name": "netd", $cam$nd}],
 "render": {"integrator": "path", "paths_per_sample": 1}}
EOF
}
furnace "$work/furnace.json" model
furnace "$work/plain.json" ""
run noise1 simulate "$work/furnace.json" -o "$work/n1" --threads 1
run noise2 simulate "$work/furnace.json" -o "$work/n2" --threads 2
run plain simulate "$work/plain.json" -o "$work/plain" --threads 2
check noise "$work/n2" 300
for s in tp dicke netd; do
    for q in measured_radiance measured_brightness_temperature; do
        cmp -s "$work/n1/$s.$q.img" "$work/n2/$s.$q.img" ||
            fail "$s.$q differs between --threads 1 and 2"
    done
    for q in radiance brightness_temperature power normalized; do
        cmp -s "$work/n2/$s.$q.img" "$work/plain/$s.$q.img" ||
            fail "$s.$q (noise-free) changed by the sensor model"
    done
    [ -e "$work/plain/$s.measured_radiance.img" ] && fail "measured cube without a model"
    [ -e "$work/n2/$s.measured-band-01.png" ] || fail "$s.measured-band-01.png missing"
done
/usr/bin/python3 - "$work/n2/summary.json" <<'EOF' || fail "summary.json: sensors[].model"
import json, sys
s = {x["name"]: x["model"] for x in json.load(open(sys.argv[1]))["sensors"]}
assert s["tp"]["noise"]["model"] == "total-power" and s["tp"]["psf"] == "none", s["tp"]
assert s["dicke"]["noise"]["model"] == "dicke", s["dicke"]
assert s["netd"]["noise"]["netd_k"] == [0.5, 0.2] and s["netd"]["noise_seed"] == 7, s["netd"]
assert s["tp"]["noise_seed"] == 1, s["tp"]
# the radiometer's NETD per channel at the reference temperature it names (the box's
# 300 K): (T + T_rec) / sqrt(B_n tau), B_n = sqrt(pi / (2 ln 2)) FWHM; a given NETD is at
# no temperature and has no receiver
import math
tp = s["tp"]["noise"]
assert tp["netd_at_temperature_k"] == [300, 300] and tp["receiver_temperature_k"] == 500, tp
for k, f in zip(tp["netd_k"], (0.35e12, 0.65e12)):
    b_n = math.sqrt(math.pi / (2 * math.log(2))) * 0.01 * f
    assert abs(k / ((300 + 500) / math.sqrt(b_n * 0.01)) - 1) < 1e-6, (k, f)
nd = s["netd"]["noise"]
assert "netd_at_temperature_k" not in nd and "receiver_temperature_k" not in nd, nd
# no aperture_diameter_m given: null, not a diameter of 0 m
assert s["tp"]["aperture_diameter_m"] is None, s["tp"]
EOF
# the measured cube's header gives every channel's NETD, not the first one's
grep -q "NETD per channel 0.5 / 0.2 K" "$work/n2/netd.measured_brightness_temperature.hdr" ||
    fail "netd.measured_brightness_temperature.hdr: $(grep description "$work/n2/netd.measured_brightness_temperature.hdr")"
# render from a saved photon map: the same measured cubes as simulate
run pm simulate "$work/furnace.json" -o "$work/pm" --integrator photon-map --photons 20000 \
    --save-photon-map --threads 2
run pmr render "$work/furnace.json" --photon-map "$work/pm/photon-map.thzpm" -o "$work/pmr" \
    --integrator photon-map --threads 1
for q in measured_radiance measured_brightness_temperature; do
    cmp -s "$work/pm/netd.$q.img" "$work/pmr/netd.$q.img" ||
        fail "netd.$q: render from the saved map differs from simulate"
done

# ---- noise where Tb varies: a 1000 K ball in the 300 K furnace --------------------------
# The radiometer's NETD follows each pixel's Tb, not the channel's reference temperature
# (the box's 300 K): (measured - true Tb) / NETD(true Tb) has mean 0 and spread 1 on the
# ball's pixels and on the box's (with T_rec = 500 K, NETD at 1000 K is 1500/800 = 1.875 x that at 300 K).
cat > "$work/hot.json" <<EOF
{"format": "thzmap-scene/1", "name": "hot",
 "channels": [{"frequency_thz": 0.35, "relative_width": 0.01}],
 "materials": {"black": {"reflectivity": 0}},
 "objects": [{"name": "box", "type": "solid", "material": "black", "temperature_k": 300,
              "shape": {"type": "box", "size_m": [4, 4, 4], "inward": true}},
             {"name": "ball", "type": "solid", "material": "black", "temperature_k": 1000,
              "shape": {"type": "sphere", "radius_m": 0.3},
              "transform": {"translate_m": [0, 1.5, 0]}}],
 "sensors": [{"name": "tp", "position_m": [0, 0, 0], "direction": [0, 1, 0], "fov_deg": 30,
              "resolution": [128, 128], "noise": {"receiver_temperature_k": 500,
              "integration_time_s": 0.01, "radiometer": "total-power"}}],
 "render": {"integrator": "path", "paths_per_sample": 1}}
EOF
run hot simulate "$work/hot.json" -o "$work/hot" --threads 2
/usr/bin/python3 - "$REPO/tests/cli" "$work/hot" <<'EOF' || fail "noise where Tb varies"
import math, sys
sys.path.insert(0, sys.argv[1])
from sensor_check import cube
truth = cube(sys.argv[2], "tp", "brightness_temperature")[0]
meas = cube(sys.argv[2], "tp", "measured_brightness_temperature")[0]
b_n = 2.0 * math.sqrt(math.pi) * 0.01 * 0.35e12 / (2.0 * math.sqrt(2.0 * math.log(2.0)))
z = (meas - truth) / ((truth + 500.0) / math.sqrt(b_n * 0.01))
ok = True
for name, sel in (("ball", truth > 650.0), ("box", truth < 650.0)):
    n = int(sel.sum())
    std, mean = float(z[sel].std(ddof=1)), float(z[sel].mean())
    tol = 3.0 / math.sqrt(2.0 * n)
    good = n > 3000 and abs(std - 1.0) < tol and abs(mean) < 3.0 / math.sqrt(n)
    print(("ok:   " if good else "FAIL: ") + f"{name}: {n} pixels, (measured - true Tb) / "
          f"NETD(Tb): std {std:.4f} (1 +- {tol:.4f}), mean {mean:+.4f}")
    ok = ok and good
sys.exit(0 if ok else 1)
EOF

# ---- PSF: a hot disk far below the diffraction limit -----------------------------------
pitch=0.0015 # rad per pixel at the centre, 129 columns
fov=$(/usr/bin/python3 -c "import math; print(2 * math.degrees(math.atan(math.tan($pitch / 2) * 129)))")
cat > "$work/disk.json" <<EOF
{"format": "thzmap-scene/1", "name": "disk",
 "channels": [{"frequency_thz": 0.35, "relative_width": 0.01},
              {"frequency_thz": 0.5, "relative_width": 0.05}],
 "materials": {"black": {"reflectivity": 0}},
 "objects": [{"name": "disk", "type": "solid", "material": "black", "temperature_k": 1000,
              "shape": {"type": "disk", "radius_m": 0.0003}}],
 "sensors": [{"name": "cam", "position_m": [0, 0, 1], "direction": [0, 0, -1], "up": [0, 1, 0],
              "fov_deg": $fov, "resolution": [129, 129], "oversampling": 4,
              "aperture_diameter_m": 0.05}],
 "render": {"integrator": "path", "paths_per_sample": 1}}
EOF
run disk1 simulate "$work/disk.json" -o "$work/d1" --threads 1
run disk2 simulate "$work/disk.json" -o "$work/d2" --threads 2
check psf "$work/d2" 0.05 "$pitch"
cmp -s "$work/d1/cam.measured_radiance.img" "$work/d2/cam.measured_radiance.img" ||
    fail "PSF: measured radiance differs between --threads 1 and 2"

# ---- validate and bad input ------------------------------------------------------------
"$THZMAP" validate "$work/disk.json" > "$work/v.log" 2>&1 || fail "validate disk.json"
grep -q "spot 1.22 lambda/D 20.9 mrad = 2.09 cm at 1 m" "$work/v.log" ||
    { fail "validate: no spot size of 20.9 mrad (2.09 cm at 1 m)"; cat "$work/v.log"; }
"$THZMAP" validate "$work/furnace.json" > "$work/vf.log" 2>&1 || fail "validate furnace.json"
grep -q "NETD 0.1102 K at Tb 300 K" "$work/vf.log" ||
    { fail "validate: total-power NETD of 0.1102 K at 300 K missing"; cat "$work/vf.log"; }
sed 's/"netd_k": \[0.5, 0.2\]/"netd_k": [0.5]/' "$work/furnace.json" > "$work/bad.json"
"$THZMAP" validate "$work/bad.json" > "$work/bad.log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "a netd_k list of the wrong length: exit $rc, expected 2"
grep -q 'sensors\[2\].noise.netd_k' "$work/bad.log" ||
    { fail "the error does not name sensors[2].noise.netd_k"; cat "$work/bad.log"; }
# noise beyond the 32-bit outputs' range: refused (exit 2, nothing written), not inf written
sed 's/"netd_k": \[0.5, 0.2\]/"netd_k": [0.5, 1e300]/' "$work/furnace.json" > "$work/huge.json"
"$THZMAP" simulate "$work/huge.json" -o "$work/huge" --quiet > "$work/huge.log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "netd_k 1e300 K: exit $rc, expected 2"
grep -q "$work/huge.json: sensors\[2\].noise (sensor 'netd'), channel 2: the noise takes the measured image beyond" "$work/huge.log" ||
    { fail "netd_k 1e300 K: no message naming the file, sensor and channel"; cat "$work/huge.log"; }
[ ! -e "$work/huge" ] || fail "netd_k 1e300 K: OUTDIR written"
# a PSF too much wider than the image to fold onto it: refused before the work (no
# estimate, no render), exit 2, the JSON path of the key that sets the PSF's width (it
# said "sensors[0].psf: sensor 'cam': ..."), the most it may reach, nothing written; the
# Airy pattern of a 10 um aperture: its aperture_diameter_m
python3 - "$work/furnace.json" "$work/wide.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["sensors"][0].update({"psf": "gaussian", "psf_fwhm_deg": 120, "fov_deg": 0.01})
json.dump(s, open(sys.argv[2], "w"))
PY
"$THZMAP" simulate "$work/wide.json" -o "$work/wide" > "$work/wide.log" 2>&1
rc=$?
[ $rc -eq 2 ] || fail "a 120 deg PSF on a 0.01 deg field: exit $rc, expected 2"
grep -q "^thzmap: $work/wide.json: sensors\[0\].psf_fwhm_deg: the PSF reaches [0-9]* pixels from the centre at 0.35 THz, against an image of 128 x 128 pixels: expected at most 4095 pixels" "$work/wide.log" ||
    { fail "a 120 deg PSF on a 0.01 deg field: no message naming sensors[0].psf_fwhm_deg"; cat "$work/wide.log"; }
grep -q "estimate:" "$work/wide.log" && fail "a 120 deg PSF on a 0.01 deg field: refused only after the estimate"
[ ! -e "$work/wide" ] || fail "a 120 deg PSF on a 0.01 deg field: OUTDIR written"
# validate says the same (it said "valid", exit 0, of the scene simulate refuses)
"$THZMAP" validate "$work/wide.json" > "$work/wide-v.log" 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q "^thzmap: $work/wide.json: sensors\[0\].psf_fwhm_deg: the PSF reaches [0-9]* pixels from the centre at 0.35 THz, against an image of 128 x 128 pixels: expected at most 4095 pixels" "$work/wide-v.log" ||
    { fail "validate of a 120 deg PSF on a 0.01 deg field: exit $rc, not simulate's refusal"; cat "$work/wide-v.log"; }
grep -q "valid" "$work/wide-v.log" && fail "validate of a 120 deg PSF on a 0.01 deg field: says valid"
python3 - "$work/wide.json" "$work/airy.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
del s["sensors"][0]["psf_fwhm_deg"]
s["sensors"][0].update({"psf": "airy", "aperture_diameter_m": 1e-5, "aperture_m2": 7e-11})
json.dump(s, open(sys.argv[2], "w"))
PY
"$THZMAP" simulate "$work/airy.json" -o "$work/airy" > "$work/airy.log" 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q "^thzmap: $work/airy.json: sensors\[0\].aperture_diameter_m: the PSF reaches" "$work/airy.log" ||
    { fail "the Airy PSF of a 10 um aperture: exit $rc, no message naming aperture_diameter_m"; cat "$work/airy.log"; }
[ ! -e "$work/airy" ] || fail "the Airy PSF of a 10 um aperture: OUTDIR written"
"$THZMAP" validate "$work/airy.json" > "$work/airy-v.log" 2>&1
rc=$?
[ $rc -eq 2 ] && grep -q "^thzmap: $work/airy.json: sensors\[0\].aperture_diameter_m: the PSF reaches" "$work/airy-v.log" ||
    { fail "validate of the Airy PSF of a 10 um aperture: exit $rc, not simulate's refusal"; cat "$work/airy-v.log"; }

finish "PASS"
