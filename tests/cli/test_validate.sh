#!/usr/bin/env bash
# thzmap validate: the summary of the spec's example scene (channel centre and FWHM,
# triangle counts, areas, temperatures, the emitted power P_A against an independent
# computation), the mesh example, warnings on stderr, --help and usage errors.
# usage: test_validate.sh THZMAP_BINARY REPO_DIR
. "$(dirname "$0")/lib.sh"

# --- the spec's example -------------------------------------------------------------
"$THZMAP" validate "$REPO/examples/plate-in-box/scene.json" >"$work/out" 2>"$work/err"
status=$?
[[ $status -eq 0 ]] || fail "plate-in-box: exit $status: $(cat "$work/err")"
[[ -s $work/err ]] && fail "plate-in-box: unexpected warnings: $(cat "$work/err")"
expect_line "$work/out" '^scene "plate-in-box"'
expect_line "$work/out" '0\.35 THz +centre 0\.3500 THz +FWHM 3\.500 GHz'
expect_line "$work/out" '^  \[0\] room: solid, material wall, 12 triangles, area 10 m², temperature 295\.00 K'
expect_line "$work/out" '^  \[1\] target: solid, material paint, 256 triangles, area 0\.533781 m², temperature 310\.00 K'
expect_line "$work/out" '^  \[2\] cover: shell 0\.5 mm, material cloth, 128 triangles, area 0\.0634347 m², temperature 300\.00 K'
expect_line "$work/out" 'cam: 64 x 64 pixels, fov 40 deg, oversampling 2 x 2, aperture 0\.01 m²'
# the air emits at the enclosure's temperature unless told otherwise
expect_line "$work/out" '^atmosphere: constant; emitting at 295\.00 K, background 295\.00 K$'
expect_line "$work/out" '^  table: reflectivity table \(5 points'

# the air's state: 50 % relative humidity at 288 K is about 8.5 hPa of water vapour
# (half of 17.0 hPa), 216.7 e / T = 6.4 g/m³; the given background
"$THZMAP" validate "$REPO/examples/outdoor-concealed/scene.json" >"$work/outdoor" 2>"$work/err" ||
    fail "outdoor-concealed: exit $?: $(cat "$work/err")"
expect_line "$work/outdoor" '^atmosphere: itu-p676; air at 288\.00 K and 1013\.00 hPa, water vapour 8\.[45][0-9]* hPa \(6\.[34][0-9]* g/m³\); emitting at 288\.00 K, background 40\.00 K$'
cat > "$work/cold-air.json" <<'JSON'
{"format": "thzmap-scene/1", "name": "cold-air",
 "channels": [{"frequency_thz": 0.35, "relative_width": 0.05}],
 "materials": {"wall": {"reflectivity": 0.1}},
 "atmosphere": {"model": "constant", "attenuation_per_m": 0.05, "emitting": false},
 "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
              "shape": {"type": "box", "size_m": [2, 2, 2], "inward": true}}],
 "sensors": [{"name": "cam", "position_m": [0, 0, 0], "direction": [0, 1, 0], "fov_deg": 40,
              "resolution": [4, 4]}]}
JSON
"$THZMAP" validate "$work/cold-air.json" >"$work/cold" 2>/dev/null || fail "cold-air: exit $?"
expect_line "$work/cold" '^atmosphere: constant; not emitting$'
# a rotated rectangle's bottom edge lies at z = 2.4e-08 m in float vertices: shown as 0
"$THZMAP" validate "$REPO/examples/walker/scene.json" >"$work/walker" 2>"$work/err" ||
    fail "walker: exit $?: $(cat "$work/err")"
expect_line "$work/walker" 'screen: .* bounds \[-0\.6, 0, 0\] to \[0\.6, 0, 1\.8\] m$'

# P_A = sum pi eps-bar A B(T) over emitting sides, here at the channel centre (the
# band mean over a 1 % band differs by ~1e-5), computed independently in Python.
pa=$(awk '/^emitted spectral power/ {getline; print $(NF-1)}' "$work/out")
unit=$(awk '/^emitted spectral power/ {getline; print $NF}' "$work/out")
[[ $unit == "W/Hz" ]] || fail "P_A unit is '$unit', expected W/Hz"
python3 - "$pa" <<'PY' || fail "P_A of plate-in-box is wrong"
import math, sys
h, k, c = 6.62607015e-34, 1.380649e-23, 299792458.0
nu = 0.35e12
def B(T):
    return 2 * h * nu**3 / c**2 / math.expm1(h * nu / (k * T))
n = 64
cyl_side = lambda r, hgt: n * 2 * r * math.sin(math.pi / n) * hgt
cap = lambda r: n * r * r * math.sin(2 * math.pi / n) / 2
R_paint = 0.05 + (0.35 - 0.2) / 1.0 * (0.12 - 0.05)
alpha = 60 + (0.35 - 0.2) / 1.0 * (900 - 60)
R_cloth, t = 0.02, 0.0005
# eps-bar of the shell = 2 int (1 - R - T(mu)) mu dmu, T = min(exp(-alpha t / mu), 1 - R)
m = 200000
ebar = sum(2 * (1 - R_cloth - min(math.exp(-alpha * t / mu), 1 - R_cloth)) * mu / m
           for mu in ((i + 0.5) / m for i in range(m)))
pa = math.pi * (10 * B(295) + (1 - R_paint) * (cyl_side(0.1, 0.75) + 2 * cap(0.1)) * B(310)
                + 2 * ebar * cyl_side(0.101, 0.1) * B(300))
got = float(sys.argv[1])
print("P_A expected %.6e W/Hz, got %.6e W/Hz" % (pa, got))
sys.exit(0 if abs(got / pa - 1) < 1e-3 else 1)
PY

# --- the mesh example -----------------------------------------------------------------
"$THZMAP" validate "$REPO/examples/meshes/scene.json" >"$work/out" 2>"$work/err"
status=$?
[[ $status -eq 0 ]] || fail "meshes example: exit $status: $(cat "$work/err")"
[[ -s $work/err ]] && fail "meshes example: unexpected warnings: $(cat "$work/err")"
expect_line "$work/out" 'pyramid: solid, material metal, 6 triangles, area 1\.009 m²'
expect_line "$work/out" '^  0\.900 THz +[0-9.]+e-[0-9]+ W/Hz'

# --- reflection lobes: each material's `reflection`, Ward's slopes as given ------------------
"$THZMAP" validate "$REPO/examples/outdoor-concealed/scene.json" >"$work/out" 2>"$work/err" ||
    fail "outdoor-concealed: exit $?: $(cat "$work/err")"
expect_line "$work/out" '^  object: .*; reflection ward \(alpha_x 0\.1, alpha_y 0\.3\)$'
expect_line "$work/out" '^  skin: .*; reflection diffuse$'
"$THZMAP" validate "$REPO/examples/mirror-plate/scene.json" >"$work/out" 2>"$work/err" ||
    fail "mirror-plate: exit $?: $(cat "$work/err")"
expect_line "$work/out" '^  metal: .*; reflection specular$'

# --- warnings ---------------------------------------------------------------------------
"$THZMAP" validate "$REPO/tests/inputs/scenes/warnings.json" >"$work/out" 2>"$work/err"
status=$?
[[ $status -eq 0 ]] || fail "warnings scene: exit $status"
[[ $(grep -c '^thzmap validate: warning: ' "$work/err") -eq 4 ]] || fail "expected 4 warnings, got: $(cat "$work/err")"
expect_line "$work/err" '^thzmap validate: warning: object "part": inconsistent winding'
expect_line "$work/err" '^thzmap validate: warning: object "plate": the explicit emissivity .* Kirchhoff'
expect_line "$work/err" '^thzmap validate: warning: material "lossy", reflectivity: the table covers'

# a mesh file with a triangle repeated (the other way round) and one of no area: each
# named, as the import counts them
mkdir -p "$work/defects"
cat > "$work/defects/tile.obj" <<'OBJ'
v 0 0 0
v 1 0 0
v 0 1 0
v 1 1 0
v 2 2 0
f 1 2 3
f 2 4 3
f 3 2 1
f 1 4 5
OBJ
cat > "$work/defects/scene.json" <<'JSON'
{"format": "thzmap-scene/1", "name": "defects",
 "channels": [{"frequency_thz": 0.35, "relative_width": 0.05}],
 "materials": {"wall": {"reflectivity": 0.1}},
 "objects": [{"name": "tile", "type": "shell", "thickness_m": 0.001, "material": "wall",
              "temperature_k": 300, "shape": {"type": "mesh", "file": "tile.obj"}}],
 "sensors": [{"name": "cam", "position_m": [0.5, 0.5, 2], "look_at_m": [0.5, 0.5, 0], "up": [0, 1, 0],
              "fov_deg": 40, "resolution": [4, 4]}]}
JSON
"$THZMAP" validate "$work/defects/scene.json" >"$work/out" 2>"$work/err" ||
    fail "defects: exit $?: $(cat "$work/err")"
expect_line "$work/err" '^thzmap validate: warning: object "tile": 1 triangle\(s\) repeat another.s three corners'
expect_line "$work/err" '^thzmap validate: warning: object "tile": 1 triangle\(s\) of no area'

# --- help and usage -----------------------------------------------------------------------
"$THZMAP" validate --help >"$work/out" 2>&1 || fail "validate --help failed"
expect_line "$work/out" '^usage: thzmap validate SCENE\.json'
"$THZMAP" validate >/dev/null 2>"$work/err"
[[ $? -eq 2 ]] || fail "validate without a scene must exit 2"
"$THZMAP" validate a.json b.json >/dev/null 2>&1
[[ $? -eq 2 ]] || fail "validate with two scenes must exit 2"
"$THZMAP" validate --bogus "$REPO/examples/plate-in-box/scene.json" >/dev/null 2>&1
[[ $? -eq 2 ]] || fail "validate with an unknown option must exit 2"
"$THZMAP" validate "$work/does-not-exist.json" >/dev/null 2>"$work/err"
[[ $? -eq 2 ]] || fail "validate of a missing file must exit 2"
expect_line "$work/err" 'does-not-exist\.json: cannot open'
# a FIFO as the scene would block the open: refused at once (timeout: a hang fails)
mkfifo "$work/pipe.json"
timeout 10 "$THZMAP" validate "$work/pipe.json" 2>"$work/err"
[[ $? -eq 2 ]] || fail "validate of a FIFO must exit 2 at once"
expect_line "$work/err" 'pipe\.json: is a FIFO'
# a file with no format could be either kind: the message names both
echo '{"frames": 3}' >"$work/noformat.json"
"$THZMAP" validate "$work/noformat.json" >/dev/null 2>"$work/err"
[[ $? -eq 2 ]] || fail "validate of a file without format must exit 2"
expect_line "$work/err" 'noformat\.json: format: missing key \(expected "thzmap-scene/1" or "thzmap-scene/1\.1"; a sequence file, .*"thzmap-sequence/1"\)'

# --- a sequence file: its frames, the first frame's scene, every frame's warnings ----
"$THZMAP" validate "$REPO/examples/walker/sequence.json" >"$work/walker" 2>"$work/err"
status=$?
[[ $status -eq 0 ]] || fail "walker sequence: exit $status: $(cat "$work/err")"
[[ -s $work/err ]] && fail "walker sequence: unexpected warnings: $(cat "$work/err")"
expect_line "$work/walker" '^sequence \(.*/walker/sequence\.json\): valid$'
expect_line "$work/walker" '^frames: 25 \(1 sweep value x 25 frames, t = 0 to 3 s\)$'
expect_line "$work/walker" "^the first frame's scene \(frame-00000\):$"
expect_line "$work/walker" '^scene "walker"'
# the plate in its box with a background given (a warning while the camera is in the
# room: frame 0 of each sweep value, counting from 0), the camera leaving the room at
# t = 1 s (a warning in frames 1 and 2 of each), swept over two temperatures of the
# target; the warnings count the frames from 1 of 6
cp -r "$REPO/examples/plate-in-box" "$work/seq"
/usr/bin/python3 - "$work/seq/scene.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["atmosphere"]["background_temperature_k"] = 3
json.dump(s, open(sys.argv[1], "w"))
PY
cat > "$work/seq/sequence.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 3,
 "keyframes": [{"time_s": 0, "sensors": {"cam": {"position_m": [0, -0.45, 0.4]}}},
               {"time_s": 1, "sensors": {"cam": {"position_m": [0, -3, 0.4]}}}],
 "sweep": {"objects.target.temperature_k": [300, 320]}}
JSON
"$THZMAP" validate "$work/seq/sequence.json" >"$work/seq.out" 2>"$work/seq.err"
status=$?
[[ $status -eq 0 ]] || fail "a sequence with warnings: exit $status: $(cat "$work/seq.err")"
expect_line "$work/seq.out" '^frames: 6 \(2 sweep values x 3 frames, t = 0 to 2 s\)$'
# each warning once, with the first frame that has it, then its repeats
[[ $(grep -c 'background_temperature_k is given' "$work/seq.err") -eq 2 ]] &&
    [[ $(grep -c 'is outside the enclosure' "$work/seq.err") -eq 2 ]] ||
    fail "the warnings: not each once and once repeated: $(cat "$work/seq.err")"
expect_line "$work/seq.err" '^thzmap validate: warning: sweep-00/frame-00000: atmosphere\.background_temperature_k is given'
expect_line "$work/seq.err" '^thzmap validate: warning: the same in 1 later frame: atmosphere\.background_temperature_k'
expect_line "$work/seq.err" '^thzmap validate: warning: sweep-00/frame-00001: sensor "cam" at \[0, -3, 0\.4\] m is outside'
expect_line "$work/seq.err" '^thzmap validate: warning: the same in 3 later frames: sensor "cam" .* is outside'
# a warning whose numbers change from frame to frame (the camera moving outside the room)
# is printed in full once, the later frames' alike ones counted; within a frame, two
# sensors' warnings are both printed, and their names, cam1 and cam2, differ by more than
# numbers (a name's digits are no number): each is counted apart
/usr/bin/python3 - "$work/seq/scene.json" "$work/seq/two.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
s["sensors"] = [dict(s["sensors"][0], name=name) for name in ("cam1", "cam2")]
json.dump(s, open(sys.argv[2], "w"))
PY
cat > "$work/seq/moving.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "two.json", "fps": 1, "frames": 4,
 "keyframes": [{"time_s": 0, "sensors": {"cam1": {"position_m": [0, -3, 0.4]},
                                         "cam2": {"position_m": [0, -7, 0.4]}}},
               {"time_s": 3, "sensors": {"cam1": {"position_m": [0, -6, 0.4]},
                                         "cam2": {"position_m": [0, -10, 0.4]}}}]}
JSON
"$THZMAP" validate "$work/seq/moving.json" >/dev/null 2>"$work/seq.err" ||
    fail "a moving camera's sequence: exit $?: $(cat "$work/seq.err")"
expect_line "$work/seq.err" '^thzmap validate: warning: frame-00000: sensor "cam1" at \[0, -3, 0\.4\] m is outside'
expect_line "$work/seq.err" '^thzmap validate: warning: frame-00000: sensor "cam2" at \[0, -7, 0\.4\] m is outside'
expect_line "$work/seq.err" '^thzmap validate: warning: the same but for its numbers in 3 later frames: sensor "cam1" at \[0, -3, 0\.4\] m is outside'
expect_line "$work/seq.err" '^thzmap validate: warning: the same but for its numbers in 3 later frames: sensor "cam2" at \[0, -7, 0\.4\] m is outside'
[[ $(grep -c 'is outside' "$work/seq.err") -eq 4 ]] ||
    fail "a moving camera's warnings: not two, then two counts: $(cat "$work/seq.err")"
# an index in a JSON path is no number either: sensors[1]'s warning, alike sensors[0]'s of
# an earlier frame but for the index, is its own (it was counted with sensors[0]'s, "the
# same but for its numbers in 1 later frame", and never printed). Both apertures of
# 0.05 m² with their 0.1 m diameter warn; cam2's is swept from 0.005 m² (no warning) to it
/usr/bin/python3 - "$work/seq/two.json" "$work/seq/index.json" <<'PY'
import json, sys
s = json.load(open(sys.argv[1]))
for sn in s["sensors"]:
    sn.update(aperture_diameter_m=0.1, aperture_m2=0.05)
json.dump(s, open(sys.argv[2], "w"))
PY
cat > "$work/seq/index-seq.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "index.json",
 "sweep": {"sensors.cam2.aperture_m2": [0.005, 0.05]}}
JSON
"$THZMAP" validate "$work/seq/index-seq.json" >/dev/null 2>"$work/seq.err" ||
    fail "a sweep of cam2's aperture: exit $?: $(cat "$work/seq.err")"
expect_line "$work/seq.err" '^thzmap validate: warning: sweep-00/frame-00000: .*sensors\[0\]\.aperture_m2: 0\.05 m\^2 is more than'
expect_line "$work/seq.err" '^thzmap validate: warning: sweep-01/frame-00000: .*sensors\[1\]\.aperture_m2: 0\.05 m\^2 is more than'
expect_line "$work/seq.err" '^thzmap validate: warning: the same in 1 later frame: .*sensors\[0\]\.aperture_m2'
[[ $(grep -c 'aperture_m2' "$work/seq.err") -eq 3 ]] ||
    fail "a sweep of cam2's aperture: not cam1's, cam2's and cam1's repeat: $(cat "$work/seq.err")"

# a frame whose scene is bad by a keyframe's value: exit 2, naming the keyframe's value
# in the sequence file, then the scene's JSON path and the frame's directory (as batch
# does)
cat > "$work/seq/bad.json" <<'JSON'
{"format": "thzmap-sequence/1", "scene": "scene.json", "fps": 1, "frames": 3,
 "keyframes": [{"time_s": 0, "objects": {"target": {"temperature_k": 300}}},
               {"time_s": 2, "objects": {"target": {"temperature_k": -300}}}]}
JSON
"$THZMAP" validate "$work/seq/bad.json" >/dev/null 2>"$work/err"
[[ $? -eq 2 ]] || fail "a sequence with a bad frame must exit 2: $(cat "$work/err")"
expect_line "$work/err" 'bad\.json: keyframes\[1\]\.objects\.target\.temperature_k: .* \(the scene scene\.json.s objects\[1\]\.temperature_k, frame-00002, t = 2 s\)'

# a Gaussian PSF's width at the objects' distance is 2 d tan(FWHM / 2) (60 deg at 1 m: 1.15 m;
# distance x angle said 1.05 m), and none from 90 deg on (170 deg said 6.37 m at 2.147 m)
psf_scene() { # $1: psf_fwhm_deg
    cat > "$work/psf$1.json" <<JSON
{"format": "thzmap-scene/1", "channels": [{"frequency_thz": 0.35, "relative_width": 0.02}],
 "materials": {"wall": {"reflectivity": 0.1}},
 "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
              "shape": {"type": "box", "size_m": [4, 4, 4], "inward": true}},
             {"name": "target", "type": "solid", "material": "wall", "temperature_k": 300,
              "shape": {"type": "box", "size_m": [0.2, 0.2, 0.2]},
              "transform": {"translate_m": [0, 1, 0]}}],
 "sensors": [{"name": "cam", "position_m": [0, 0, 0], "direction": [0, 1, 0], "fov_deg": 40,
              "resolution": [4, 4], "psf": "gaussian", "psf_fwhm_deg": $1}]}
JSON
    "$THZMAP" validate "$work/psf$1.json" >"$work/psf$1.out" 2>"$work/err" ||
        fail "psf_fwhm_deg $1: exit $?: $(cat "$work/err")"
}
psf_scene 60
expect_line "$work/psf60.out" 'PSF FWHM 1047 mrad = 1\.15 m at 1 m, 1\.15 m at 1 m \(nearest and farthest object centre\)$'
for deg in 90 170; do
    psf_scene $deg
    expect_line "$work/psf$deg.out" 'PSF FWHM [0-9]+ mrad$'
done

# an Airy spot and a radiometer's NETD, by hand: at 0.35 THz (lambda 0.8565 mm) with D 0.5 m,
# 1.22 lambda / D = 2.090 mrad, 2 d tan(spot / 2) = 2.09 mm at the near box (1 m) and
# 1.254 cm at the far one (6 m; the room around the sensor is left out); B_n of a Gaussian
# of FWHM 7 GHz is sqrt(pi / (2 ln 2)) FWHM = 10.54 GHz, and the total-power NETD at the
# largest emitter's 295 K is (295 + 700) K / sqrt(B_n 0.01 s) = 0.09693 K. The total area
# is the room's 2400 m^2, 0.24 and 0.96 m^2.
cat > "$work/airy.json" <<'JSON'
{"format": "thzmap-scene/1", "channels": [{"frequency_thz": 0.35, "relative_width": 0.02}],
 "materials": {"wall": {"reflectivity": 0.1}},
 "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
              "shape": {"type": "box", "size_m": [20, 20, 20], "inward": true}},
             {"name": "near", "type": "solid", "material": "wall", "temperature_k": 300,
              "shape": {"type": "box", "size_m": [0.2, 0.2, 0.2]},
              "transform": {"translate_m": [0, 1, 0]}},
             {"name": "far", "type": "solid", "material": "wall", "temperature_k": 300,
              "shape": {"type": "box", "size_m": [0.4, 0.4, 0.4]},
              "transform": {"translate_m": [0, 6, 0]}}],
 "sensors": [{"name": "cam", "position_m": [0, 0, 0], "direction": [0, 1, 0], "fov_deg": 40,
              "resolution": [4, 4], "aperture_diameter_m": 0.5,
              "noise": {"receiver_temperature_k": 700, "integration_time_s": 0.01,
                        "radiometer": "total-power"}}]}
JSON
"$THZMAP" validate "$work/airy.json" >"$work/airy.out" 2>"$work/err" ||
    fail "an Airy PSF and a radiometer: exit $?: $(cat "$work/err")"
expect_line "$work/airy.out" ' NETD 0\.09693 K at Tb 295 K \(B_n 10\.54 GHz\); spot 1\.22 lambda/D 2\.09 mrad = 2\.09 mm at 1 m, 1\.25 cm at 6 m \(nearest and farthest object centre\)$'
expect_line "$work/airy.out" '^  total: 36 triangles, area 2401\.2 m²$'

finish "validate: all checks passed"
