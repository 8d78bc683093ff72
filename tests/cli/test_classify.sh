#!/bin/bash
# thzmap classify on a run of three plates of distinct materials in a room: noise-free
# (no sensor noise; the path integrator converged) the accuracy is 1; with the NETD
# raised (--netd-k) it falls monotonically; the confusion matrix sums to the pixels
# that see an object; S.class.hdr/.img hold the assigned object per pixel; a
# measured cube (S.measured_brightness_temperature) is preferred when the run has one;
# every method runs; bad input exits 2 and writes nothing.
# argv: thzmap binary, repository directory.
set -u
THZ="$1"
REPO="$2"
IN="$REPO/tests/inputs/analysis"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
PY=/usr/bin/python3

"$THZ" classify --help > "$TMP/help" || fail "--help exit status $?"
for o in --sensor --method --netd-k --train-fraction --seed; do
    grep -q -- "$o" "$TMP/help" || fail "--help does not describe $o"
done

"$THZ" simulate "$IN/distinct.json" -o "$TMP/run" -q --seed 3 || fail "simulate exit status $?"

for m in sam mahalanobis lda matched-filter ace; do
    "$THZ" classify "$TMP/run" --sensor cam -o "$TMP/c-$m" --method $m -q ||
        fail "classify --method $m exit status $?"
    for f in classification.json cam.class.hdr cam.class.img cam.class.png; do
        [ -s "$TMP/c-$m/$f" ] || fail "$m: no $f"
    done
done

# --train-fraction 1 is refused, saying the range as it is (0 < F < 1)
"$THZ" classify "$TMP/run" --sensor cam -o "$TMP/c-one" --train-fraction 1 2> "$TMP/one.err"
[ $? -eq 2 ] && grep -q "expects a fraction 0 < F < 1, got '1'" "$TMP/one.err" ||
    fail "--train-fraction 1: $(cat "$TMP/one.err")"
# every pixel training (--train-fraction near 1): said, and no 'nan' printed
"$THZ" classify "$TMP/run" --sensor cam -o "$TMP/c-all" --method lda --train-fraction 0.999 \
    2> "$TMP/all.err" || fail "classify --train-fraction 0.999 exit status $?"
grep -q "warning: no pixel was held out" "$TMP/all.err" || fail "no held-out warning: $(cat "$TMP/all.err")"
grep -qi "nan" "$TMP/all.err" && fail "classify printed nan: $(cat "$TMP/all.err")"

$PY - "$TMP/run" "$TMP/c-lda" <<'PYEOF' || fail "lda, noise-free"
import json, sys
import numpy as np
run, out = sys.argv[1:3]
d = json.load(open(f"{out}/classification.json"))
ids = np.fromfile(f"{run}/cam.object_id.img", "<f4").astype(int)
seen = int((ids >= 0).sum())
conf = np.array(d["confusion"])
assert conf.shape == (4, 4)
assert conf.sum() == seen == d["pixels"], (conf.sum(), seen, d["pixels"])
assert [c["name"] for c in d["classes"]] == ["room", "A", "B", "C"]
# rows: truth; each row sums to the object's pixels
for k, c in enumerate(d["classes"]):
    assert conf[k].sum() == (ids == c["object"]).sum() == c["pixels"]
assert d["accuracy"] == 1.0, d["accuracy"]
assert d["training_pixels"] + d["held_out_pixels"] == seen
cls = np.fromfile(f"{out}/cam.class.img", "<f4").astype(int)
assert (cls == ids).all()
hdr = open(f"{out}/cam.class.hdr").read()
assert "object names = {room, A, B, C}" in hdr, hdr
for c in d["classes"]:
    assert c["auc"] == 1.0 and len(c["roc"]["true_positive_rate"]) == 101
PYEOF

# accuracy against the added NETD: exact up to 1 K (the plates differ by more), then
# falling strictly with every doubling (the same seed: the same draws, scaled), and far
# down at 8 K
for n in 0 0.5 1 2 4 8; do
    "$THZ" classify "$TMP/run" --sensor cam -o "$TMP/n-$n" --method lda --netd-k $n -q ||
        fail "--netd-k $n exit status $?"
done
# the summary says the noise was added (classification.json's added_netd_k)
"$THZ" classify "$TMP/run" --sensor cam -o "$TMP/n-said" --method lda --netd-k 0.5 \
    2> "$TMP/said.err" || fail "--netd-k 0.5 (not quiet) exit status $?"
grep -q '^thzmap classify: .* with 0.5 K of added noise by lda: ' "$TMP/said.err" ||
    fail "the summary omits the added noise: $(head -1 "$TMP/said.err")"
grep -q "added noise" "$TMP/all.err" && fail "a run without --netd-k said noise was added"
$PY - "$TMP" <<'PYEOF' || fail "accuracy against NETD"
import json, sys
acc = [json.load(open(f"{sys.argv[1]}/n-{n}/classification.json"))["accuracy"]
       for n in ("0", "0.5", "1", "2", "4", "8")]
assert acc[:3] == [1.0, 1.0, 1.0], acc
assert 1.0 > acc[3] > acc[4] > acc[5], acc
assert acc[-1] < 0.7, acc
PYEOF

# a measured cube is preferred: a copy of the run with a noisy measured cube
cp -r "$TMP/run" "$TMP/run2"
cp "$TMP/run/cam.brightness_temperature.hdr" "$TMP/run2/cam.measured_brightness_temperature.hdr"
$PY -c "
import numpy as np
a = np.fromfile('$TMP/run/cam.brightness_temperature.img', '<f4')
r = np.random.default_rng(1)
(a + r.normal(0, 5, a.shape)).astype('<f4').tofile('$TMP/run2/cam.measured_brightness_temperature.img')"
"$THZ" classify "$TMP/run2" --sensor cam -o "$TMP/m" --method lda -q || fail "measured: exit status $?"
$PY -c "
import json; d = json.load(open('$TMP/m/classification.json'))
assert d['source'] == 'cam.measured_brightness_temperature', d['source']
assert d['accuracy'] < 0.9, d['accuracy']" || fail "the measured cube was not used"

# a run whose sensor has noise writes the measured cube; classify takes it
$PY -c "
import json; d = json.load(open('$IN/distinct.json'))
d['sensors'][0]['noise'] = {'netd_k': 3.0}
json.dump(d, open('$TMP/noisy.json', 'w'))"
"$THZ" simulate "$TMP/noisy.json" -o "$TMP/run3" -q --seed 3 || fail "noisy simulate exit status $?"
[ -s "$TMP/run3/cam.measured_brightness_temperature.img" ] || fail "no measured cube written"
"$THZ" classify "$TMP/run3" --sensor cam -o "$TMP/m3" --method lda -q || fail "noisy: exit status $?"
$PY -c "
import json; d = json.load(open('$TMP/m3/classification.json'))
assert d['source'] == 'cam.measured_brightness_temperature', d['source']
assert d['accuracy'] < 1.0, d['accuracy']" || fail "the sensor's measured cube was not used"

# bad input
expect2() {
    local what=$1; shift
    "$THZ" classify "$@" > /dev/null 2> "$TMP/err"
    local rc=$?
    [ $rc -eq 2 ] || fail "$what: exit status $rc, expected 2"
    [ -s "$TMP/err" ] || fail "$what: no message"
}
expect2 "no sensor" "$TMP/run" -o "$TMP/x"
expect2 "unknown sensor" "$TMP/run" --sensor nope -o "$TMP/x"
grep -q "nope.brightness_temperature" "$TMP/err" || fail "missing cube not named: $(cat "$TMP/err")"
expect2 "unknown method" "$TMP/run" --sensor cam -o "$TMP/x" --method svm
expect2 "seed beyond 2^63 - 1 (classification.json could not record it)" "$TMP/run" \
    --sensor cam -o "$TMP/x" --seed 9223372036854775808
expect2 "no run" "$TMP/none" --sensor cam -o "$TMP/x"
# one channel: sam's angle is 0 to every class (every pixel went to the first class, 37.5 %
# on plate-in-box, silently); refused, naming the methods that work; mahalanobis runs
$PY - "$IN/distinct.json" "$TMP/one-channel.json" <<'PYEOF'
import json, sys
d = json.load(open(sys.argv[1]))
d["channels"] = [{"frequency_thz": 0.6, "relative_width": 0.01}]
json.dump(d, open(sys.argv[2], "w"))
PYEOF
"$THZ" simulate "$TMP/one-channel.json" -o "$TMP/run1" -q --seed 3 || fail "one channel: simulate exit status $?"
expect2 "sam on one channel" "$TMP/run1" --sensor cam -o "$TMP/x"
grep -q "cam.brightness_temperature has 1 channel: sam .* needs 2 channels or more; use another method: mahalanobis, lda, matched-filter or ace" \
    "$TMP/err" || fail "sam on one channel: $(cat "$TMP/err")"
[ -e "$TMP/x" ] && fail "sam on one channel left $TMP/x"
"$THZ" classify "$TMP/run1" --sensor cam -o "$TMP/c-one-mahalanobis" --method mahalanobis -q ||
    fail "mahalanobis on one channel: exit status $?"
printf 'ENVI\nsamples = 24\nlines = 16\nbands = 5\ndata type = 4\n' > "$TMP/run2/cam.measured_brightness_temperature.hdr"
head -c 100 "$TMP/run/cam.brightness_temperature.img" > "$TMP/run2/cam.measured_brightness_temperature.img"
expect2 "truncated cube" "$TMP/run2" --sensor cam -o "$TMP/x"
grep -q "bytes" "$TMP/err" || fail "truncated cube: $(cat "$TMP/err")"
# a truth of one object only: nothing to tell apart (it reported 100 %), said of the truth
# file with its run directory; a cube value that is not finite, by band, row and column
cp -r "$TMP/run" "$TMP/one"
$PY - "$TMP/one" <<'PYEOF' || fail "test set-up: one-object truth"
import sys
import numpy as np
d = sys.argv[1]
t = np.fromfile(d + "/cam.object_id.img", dtype="<f4")
t[t >= 0] = t[t >= 0].min()
t.tofile(d + "/cam.object_id.img")
c = np.fromfile(d + "/cam.brightness_temperature.img", dtype="<f4")
c[1 * t.size + 2 * 24 + 5] = np.nan  # band 2, row 3, column 6 (24 columns)
c.tofile(d + "/cam.brightness_temperature.nan")
PYEOF
expect2 "one object" "$TMP/one" --sensor cam -o "$TMP/x"
grep -q "one/cam.object_id: the truth map shows one object only" "$TMP/err" ||
    fail "one object: $(cat "$TMP/err")"
cp "$TMP/run/cam.object_id.img" "$TMP/one/cam.object_id.img"
mv "$TMP/one/cam.brightness_temperature.nan" "$TMP/one/cam.brightness_temperature.img"
expect2 "a NaN in the cube" "$TMP/one" --sensor cam -o "$TMP/x"
grep -q "one/cam.brightness_temperature: band 2, row 3, column 6 holds a value that is not finite" \
    "$TMP/err" || fail "NaN pixel: $(cat "$TMP/err")"
[ -e "$TMP/x" ] && fail "a failed run left $TMP/x"
echo ok
