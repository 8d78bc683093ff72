#!/bin/bash
# thzmap atmosphere: CSV columns and rows, the transmittance column, agreement of
# itu-p676 with an ITU-R validation value, the plot, scene channels, and exit
# status 2 with a message for bad options.
# argv: thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
# unlike lib.sh's fail: on stderr, and the test stops at the first failure
fail() { echo "FAIL: $*" >&2; exit 1; }

"$THZMAP" atmosphere --help > "$work/help" || fail "--help exit status $?"
grep -q -- "--from-thz" "$work/help" || fail "--help does not describe --from-thz"

# 0.1 to 0.2 THz in 10 GHz steps, both ends included: 11 rows
"$THZMAP" atmosphere --from-thz 0.1 --to-thz 0.2 --step-ghz 10 --distance-m 100 > "$work/a.csv" \
    || fail "lines run exit status $?"
grep -v '^#' "$work/a.csv" > "$work/a.data"
# the comment line records the path the transmittance column is of
grep -q '^# thzmap atmosphere: model lines; air .*; transmittance over a path of 100 m$' "$work/a.csv" ||
    fail "the comment line lacks --distance-m: $(head -1 "$work/a.csv")"
# ... and the air of the documented defaults: 288.15 K, 1013.25 hPa, 7.5 g/m^3 of water
# vapour, whose pressure is 7.5 x 288.15 / 216.7 = 9.973 hPa (mixing ratio 0.009842)
grep -q '^# thzmap atmosphere: model lines; air 288.15 K, 1013.25 hPa total, water vapour 9.973 hPa (7.5 g/m^3, volume mixing ratio 0.009842);' \
    "$work/a.csv" || fail "the default air is not 288.15 K, 1013.25 hPa, 7.5 g/m^3: $(head -1 "$work/a.csv")"
head -1 "$work/a.data" | grep -qx "frequency_thz,attenuation_per_m,attenuation_db_per_km,h2o_lines_db_per_km,h2o_continuum_db_per_km,o2_db_per_km,dry_continuum_db_per_km,transmittance" \
    || fail "unexpected header: $(head -1 "$work/a.data")"
[ "$(tail -n +2 "$work/a.data" | wc -l)" -eq 11 ] || fail "expected 11 rows"
tail -n +2 "$work/a.data" | awk -F, '
    NR == 1 && $1 != 0.1 { print "first frequency " $1; bad = 1 }
    NR == 11 && $1 != 0.2 { print "last frequency " $1; bad = 1 }
    { if ($2 <= 0 || $8 <= 0 || $8 >= 1) { print "bad row " $0; bad = 1 }
      # dB/km = 4342.94 * (1/m); transmittance = exp(-alpha d)
      if ((($3 / ($2 * 4342.944819)) - 1)^2 > 1e-10) { print "dB/km mismatch " $0; bad = 1 }
      if ((($8 / exp(-$2 * 100)) - 1)^2 > 1e-10) { print "transmittance mismatch " $0; bad = 1 }
      s = $4 + $5 + $6 + $7; if (((s / $3) - 1)^2 > 1e-8) { print "parts do not add up " $0; bad = 1 } }
    END { exit bad }' || fail "CSV content"

# itu-p676 at 100 GHz against the ITU-R validation value (1013.25 hPa dry air,
# 288.15 K, 7.5 g/m^3): total pressure 1013.25 + 7.5 * 288.15 / 216.7 hPa
P=$(awk 'BEGIN { printf "%.10f", 1013.25 + 7.5 * 288.15 / 216.7 }')
REF=$(awk -F, '!/^#/ && $1 == 100 { print $7 }' "$REPO/data/atmosphere/itu_r_p676_13_specific_attenuation_validation.csv")
GOT=$("$THZMAP" atmosphere --model itu-p676 --from-thz 0.1 --to-thz 0.1 --step-ghz 1 \
      --temperature-k 288.15 --pressure-hpa "$P" --water-vapour-g-m3 7.5 | grep -v '^#' | tail -1 | cut -d, -f3)
awk -v a="$GOT" -v b="$REF" 'BEGIN { exit !((a / b - 1)^2 < 1e-6) }' \
    || fail "itu-p676 at 100 GHz: $GOT dB/km, ITU-R validation $REF dB/km"

# the plot (scripts/install-deps.sh installs PLplot's pngcairo device: a missing device
# is a failure here, not a reason to skip)
if "$THZMAP" atmosphere --from-thz 0.2 --to-thz 0.5 --step-ghz 1 --plot "$work/a.png" \
       --compare-model itu-p676 > /dev/null 2> "$work/err"; then
    head -c 8 "$work/a.png" | od -An -c | grep -q "P   N   G" || fail "--plot did not write a PNG"
else
    fail "--plot failed: $(cat "$work/err")"
fi

# a scene's channels on the plot; without --model the scene's atmosphere is used
cat > "$work/scene.json" <<'JSON'
{
  "format": "thzmap-scene/1",
  "channels": [{"name": "0.35 THz", "frequency_thz": 0.35, "relative_width": 0.05},
               {"name": "#2 (0.38)", "frequency_thz": 0.38, "relative_width": 0.02}],
  "materials": {"wall": {"reflectivity": 0.0}},
  "atmosphere": {"model": "constant", "attenuation_per_m": 0.05},
  "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
               "shape": {"type": "box", "size_m": [1, 1, 1], "inward": true}}],
  "sensors": [{"name": "cam", "position_m": [0, 0, 0], "look_at_m": [1, 0, 0],
               "fov_deg": 40, "resolution": [4, 4]}]
}
JSON
"$THZMAP" atmosphere --scene "$work/scene.json" --from-thz 0.3 --to-thz 0.4 --step-ghz 50 > "$work/s.csv" \
    || fail "--scene run exit status $?"
grep -v '^#' "$work/s.csv" | head -1 | grep -qx "frequency_thz,attenuation_per_m,attenuation_db_per_km" \
    || fail "scene atmosphere header: $(cat "$work/s.csv")"
grep -v '^#' "$work/s.csv" | tail -1 | grep -q "^0.4,5.000000e-02," || fail "scene constant alpha"
# an air option describes the air: the model is then built from the options (lines by
# default), not taken from the scene (scene-format.md: "without --model and air options")
"$THZMAP" atmosphere --scene "$work/scene.json" --from-thz 0.3 --to-thz 0.3 --step-ghz 1 \
    --temperature-k 250 > "$work/sa.csv" || fail "--scene --temperature-k: exit status $?"
grep -q '^# thzmap atmosphere: model lines; air 250.00 K, ' "$work/sa.csv" ||
    fail "--scene --temperature-k 250 used the scene's atmosphere: $(head -1 "$work/sa.csv")"
# both ends included when the step does not divide the range: 0.1 to 0.2 by 30 GHz ends at 0.2
"$THZMAP" atmosphere --model none --from-thz 0.1 --to-thz 0.2 --step-ghz 30 > "$work/odd.csv" ||
    fail "a step that does not divide the range: exit status $?"
[ "$(grep -v '^#' "$work/odd.csv" | tail -n +2 | cut -d, -f1 | tr '\n' ' ')" = "0.1 0.13 0.16 0.19 0.2 " ] ||
    fail "0.1 to 0.2 THz by 30 GHz: rows $(grep -v '^#' "$work/odd.csv" | tail -n +2 | cut -d, -f1 | tr '\n' ' ')"
if "$THZMAP" atmosphere --scene "$work/scene.json" --model lines --from-thz 0.3 --to-thz 0.4 \
       --step-ghz 1 --plot "$work/s.png" > /dev/null 2> "$work/err"; then
    [ -s "$work/s.png" ] || fail "--scene --plot wrote no PNG"
else
    fail "--scene --plot failed: $(cat "$work/err")"
fi

# a scene's humid air compared with itu-p676 (the comparison takes the scene's air)
sed 's/"model": "constant", "attenuation_per_m": 0.05/"model": "lines", "temperature_k": 250, "pressure_hpa": 900, "relative_humidity": 0.5/' \
    "$work/scene.json" > "$work/humid.json"
if "$THZMAP" atmosphere --scene "$work/humid.json" --from-thz 0.3 --to-thz 0.4 --step-ghz 1 \
       --plot "$work/h.png" --compare-model itu-p676 > "$work/h.csv" 2> "$work/err"; then
    [ -s "$work/h.png" ] || fail "--scene --compare-model wrote no PNG"
    grep -q "^# .*250.00 K, 900.00 hPa" "$work/h.csv" || fail "scene air not used: $(head -1 "$work/h.csv")"
else
    fail "--scene --compare-model failed: $(cat "$work/err")"
fi

# bad usage: exit 2 and a message naming the problem
expect_usage() {
    local pattern="$1"; shift
    "$THZMAP" atmosphere "$@" > /dev/null 2> "$work/err"
    local rc=$?
    [ $rc -eq 2 ] || fail "'$*' exit status $rc, expected 2"
    grep -q -- "$pattern" "$work/err" || fail "'$*' message lacks '$pattern': $(cat "$work/err")"
}
expect_usage "required" --from-thz 0.1
expect_usage "step-ghz" --from-thz 0.1 --to-thz 0.2 --step-ghz 0
expect_usage "must not be below" --from-thz 0.3 --to-thz 0.2 --step-ghz 1
expect_usage "unknown option '--bogus'" --bogus 1
expect_usage "unknown model 'foo'" --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --model foo
expect_usage "not per cent" --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --relative-humidity 50
# below the range too: one message with the range (it said "from 0 to 1e+06" here, then
# "must be 0 to 1" above it)
expect_usage "relative humidity must be 0 to 1 (a fraction, not per cent), got -0.1" \
    --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --relative-humidity -0.1
expect_usage "--model none has no air" --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --model none \
    --relative-humidity 0.5
expect_usage "--relative-humidity expects a number, got 'nan'" --from-thz 0.1 --to-thz 0.2 \
    --step-ghz 1 --relative-humidity nan
expect_usage "only one of" --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --relative-humidity 0.5 --h2o-vmr 0.01
expect_usage "range of atmosphere model 'itu-p676'" --from-thz 0.9 --to-thz 1.2 --step-ghz 1 --model itu-p676
expect_usage "no-such.par" --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --h2o-lines "$work/no-such.par"
expect_usage "temperature" --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --temperature-k 20
expect_usage "--temperature-k expects a number from 100 to 400" --from-thz 0.1 --to-thz 0.2 \
    --step-ghz 1 --temperature-k 500
expect_usage "--from-thz expects a number above 0" --from-thz 0x1p-3 --to-thz 0.2 --step-ghz 1
expect_usage "--step-ghz expects a number above 0" --from-thz 0.1 --to-thz 0.2 --step-ghz ' 1'
expect_usage "--pressure-hpa expects a number above 0 and at most 2000, got '0'" --from-thz 0.1 --to-thz 0.2 \
    --step-ghz 1 --pressure-hpa 0
expect_usage "--pressure-hpa expects a number above 0 and at most 2000" --from-thz 0.1 --to-thz 0.2 \
    --step-ghz 1 --pressure-hpa 5000
# ... and the ends of the documented ranges are taken (scene-format.md: above 0 and at
# most 2000 hPa; 100-400 K; frequencies up to 1000 THz)
for air in "--pressure-hpa 2000" "--temperature-k 100" "--temperature-k 400"; do
    # shellcheck disable=SC2086 # (the option and its value)
    "$THZMAP" atmosphere --model itu-p676 --from-thz 0.1 --to-thz 0.1 --step-ghz 1 $air \
        > /dev/null 2> "$work/err" || fail "$air, the end of its range: exit $?: $(cat "$work/err")"
done
"$THZMAP" atmosphere --model none --from-thz 999 --to-thz 1000 --step-ghz 1e6 > "$work/ends.csv" \
    2> "$work/err" || fail "--to-thz 1000 --step-ghz 1e6, the ends of their ranges: exit $?: $(cat "$work/err")"
expect_usage "apply to a lines model" --from-thz 0.1 --to-thz 0.2 --step-ghz 1 --model itu-p676 \
    --no-continuum
expect_usage "the scene's atmosphere is used" --scene "$work/humid.json" --from-thz 0.3 \
    --to-thz 0.4 --step-ghz 1 --h2o-lines "$work/no-such.par"
# --plot writes PNG files only: a slip that names the scene is refused, the scene kept
cp "$work/humid.json" "$work/keep.json"
"$THZMAP" atmosphere --from-thz 0.3 --to-thz 0.4 --step-ghz 10 --scene "$work/keep.json" \
    --plot "$work/keep.json" > "$work/out" 2> "$work/err"
rc=$?
[ $rc -eq 2 ] && grep -q "plot expects a file name ending in .png, got '$work/keep.json'" "$work/err" ||
    fail "--plot of the scene's name: exit $rc: $(cat "$work/err")"
cmp -s "$work/humid.json" "$work/keep.json" || fail "--plot of the scene's name changed the scene"
# an unwritable --plot path: PLplot would prompt on stdin and exit; thzmap refuses it
# first (exit 2, naming the path) and never reads stdin
timeout 60 "$THZMAP" atmosphere --from-thz 0.1 --to-thz 0.2 --step-ghz 1 \
    --plot "$work/no-such-dir/a.png" < /dev/null > "$work/out" 2> "$work/err"
rc=$?
[ $rc -eq 2 ] || fail "unwritable --plot: exit status $rc, expected 2 ($(cat "$work/err"))"
grep -q "no-such-dir/a.png: cannot create" "$work/err" || fail "unwritable --plot message: $(cat "$work/err")"
[ ! -s "$work/out" ] || fail "unwritable --plot: CSV printed before the failure"

# A line catalogue with an absurd (finite) value: the attenuation is NaN; refused with
# exit 2 and nothing printed or plotted, here and in a scene (it printed -nan rows and a
# scene's images were NaN, exit 0).
awk -F, 'BEGIN { OFS = "," } NR == 3 { $6 = "1e300" } NR <= 3' \
    "$REPO/tests/inputs/atm_h2o_subset.csv" > "$work/huge.csv"
echo precious > "$work/huge.png" # a figure there before stays (the failure deleted it)
"$THZMAP" atmosphere --from-thz 0.3 --to-thz 0.31 --step-ghz 5 --h2o-lines "$work/huge.csv" \
    --o2-lines "$REPO/tests/inputs/atm_o2_subset.csv" --plot "$work/huge.png" \
    > "$work/out" 2> "$work/err"
rc=$?
[ $rc -eq 2 ] || fail "n_air 1e300: exit status $rc, expected 2"
grep -q "the attenuation at 0.3 THz is not a finite number" "$work/err" ||
    fail "n_air 1e300: message: $(cat "$work/err")"
[ ! -s "$work/out" ] && [ "$(cat "$work/huge.png")" = precious ] ||
    fail "n_air 1e300: output written, or the figure there before changed"
[ -z "$(ls "$work" | grep partial)" ] || fail "n_air 1e300: a partial figure left: $(ls "$work")"
"$THZMAP" atmosphere --from-thz 0.3 --to-thz 0.31 --step-ghz 5 --model itu-p676 \
    --compare-model lines --h2o-lines "$work/huge.csv" \
    --o2-lines "$REPO/tests/inputs/atm_o2_subset.csv" --plot "$work/cmp.png" > "$work/out" 2> "$work/err"
rc=$?
[ $rc -eq 2 ] && grep -q "attenuation of --compare-model at 0.3 THz is not a finite number" "$work/err" ||
    fail "n_air 1e300 in --compare-model: exit $rc: $(cat "$work/err")"
[ ! -s "$work/out" ] && [ ! -e "$work/cmp.png" ] || fail "n_air 1e300 in --compare-model: output written"
# an isotopologue the partition sums lack: the message names the catalogue and the table
awk -F, 'BEGIN { OFS = "," } NR == 3 { $8 = "99" } { print }' \
    "$REPO/tests/inputs/atm_h2o_subset.csv" > "$work/iso99.csv"
"$THZMAP" atmosphere --from-thz 0.3 --to-thz 0.31 --step-ghz 5 --h2o-lines "$work/iso99.csv" \
    --o2-lines "$REPO/tests/inputs/atm_o2_subset.csv" > "$work/out" 2> "$work/err"
rc=$?
[ $rc -eq 2 ] && grep -q "iso99.csv: H2O lines: no partition sum for isotopologue 99 at .* K in .*partition_sums" "$work/err" ||
    fail "isotopologue 99: exit $rc: $(cat "$work/err")"
cp "$REPO/tests/inputs/atm_o2_subset.csv" "$work/"
cat > "$work/huge.json" <<'JSON'
{"format": "thzmap-scene/1.1", "channels": [{"frequency_thz": 0.35, "relative_width": 0.01}],
 "materials": {"wall": {"reflectivity": 0.1}},
 "objects": [{"name": "room", "type": "solid", "material": "wall", "temperature_k": 295,
              "shape": {"type": "box", "size_m": [3, 3, 3], "inward": true}}],
 "sensors": [{"name": "cam", "position_m": [0, -1.4, 0], "look_at_m": [0, 0, 0],
              "fov_deg": 40, "resolution": [4, 4]}],
 "atmosphere": {"model": "lines", "temperature_k": 295, "pressure_hpa": 1000,
                "relative_humidity": 0.5, "h2o_lines_file": "huge.csv",
                "o2_lines_file": "atm_o2_subset.csv"}}
JSON
"$THZMAP" validate "$work/huge.json" > "$work/out" 2> "$work/err"
rc=$?
[ $rc -eq 2 ] && grep -q "attenuation at .* THz is not a finite number" "$work/err" ||
    fail "a scene with n_air 1e300: exit status $rc: $(cat "$work/err")"
# a catalogue's own error names the scene key that gave the file (it said "atmosphere:")
awk -F, 'BEGIN { OFS = "," } NR == 3 { $2 = "-1" } NR <= 3' \
    "$REPO/tests/inputs/atm_h2o_subset.csv" > "$work/neg.csv"
sed 's/"h2o_lines_file": "huge.csv"/"h2o_lines_file": "neg.csv"/' "$work/huge.json" > "$work/neg.json"
"$THZMAP" validate "$work/neg.json" > "$work/out" 2> "$work/err"
rc=$?
[ $rc -eq 2 ] && grep -q "neg.json: atmosphere.h2o_lines_file: .*neg.csv:3: the line's intensity must be >= 0" "$work/err" ||
    fail "a scene's bad catalogue: exit status $rc: $(cat "$work/err")"
echo "ok"
