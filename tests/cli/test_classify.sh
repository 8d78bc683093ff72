#!/bin/bash
# thzmap classify on a run of three plates of distinct materials in a room: noise-free
# (no sensor noise; the path integrator converged) the accuracy is 1; with the NETD
# raised (--netd-k) it falls monotonically; the confusion matrix sums to the pixels
# that see an object; S.class.hdr/.img hold the assigned object per pixel; a
# measured cube (S.measured_brightness_temperature) is preferred when the run has one;
# every method runs; bad input exits 2 and writes nothing.
# argv: thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
IN="$REPO/tests/inputs/analysis"
# unlike lib.sh's fail: on stderr, and the test stops at the first failure
fail() { echo "FAIL: $*" >&2; exit 1; }
PY=/usr/bin/python3

"$THZMAP" classify --help > "$work/help" || fail "--help exit status $?"
for o in --sensor --method --netd-k --train-fraction --seed; do
    grep -q -- "$o" "$work/help" || fail "--help does not describe $o"
done

"$THZMAP" simulate "$IN/distinct.json" -o "$work/run" -q --seed 3 || fail "simulate exit status $?"

for m in sam mahalanobis lda matched-filter ace; do
    "$THZMAP" classify "$work/run" --sensor cam -o "$work/c-$m" --method $m -q ||
        fail "classify --method $m exit status $?"
    for f in classification.json cam.class.hdr cam.class.img cam.class.png; do
        [ -s "$work/c-$m/$f" ] || fail "$m: no $f"
    done
done

# --train-fraction 1 is refused, saying the range as it is (0 < F < 1)
"$THZMAP" classify "$work/run" --sensor cam -o "$work/c-one" --train-fraction 1 2> "$work/one.err"
[ $? -eq 2 ] && grep -q "expects a fraction 0 < F < 1, got '1'" "$work/one.err" ||
    fail "--train-fraction 1: $(cat "$work/one.err")"
# every pixel training (--train-fraction near 1): said, and no 'nan' printed
"$THZMAP" classify "$work/run" --sensor cam -o "$work/c-all" --method lda --train-fraction 0.999 \
    2> "$work/all.err" || fail "classify --train-fraction 0.999 exit status $?"
grep -q "warning: no pixel was held out" "$work/all.err" || fail "no held-out warning: $(cat "$work/all.err")"
grep -qi "nan" "$work/all.err" && fail "classify printed nan: $(cat "$work/all.err")"
# ... and classification.json counts them so: every pixel seen training, none held out
# (training_pixels written from the held-out count, a mutant, passed every test: at a
# fraction of 1/2 the two counts are equal)
$PY -c "import json, sys; d = json.load(open(sys.argv[1]))
assert (d['training_pixels'], d['held_out_pixels']) == (d['pixels'], 0), d" \
    "$work/c-all/classification.json" || fail "training pixels at --train-fraction 0.999"

$PY - "$work/run" "$work/c-lda" <<'PYEOF' || fail "lda, noise-free"
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
# the documented defaults (no --seed, no --train-fraction given): seed 1, half of each
# object's pixels training (rounded per object)
assert d["seed"] == 1 and d["train_fraction"] == 0.5, (d["seed"], d["train_fraction"])
assert abs(d["training_pixels"] - seen / 2) <= len(d["classes"]), (d["training_pixels"], seen)
cls = np.fromfile(f"{out}/cam.class.img", "<f4").astype(int)
assert (cls == ids).all()
hdr = open(f"{out}/cam.class.hdr").read()
assert "object names = {room, A, B, C}" in hdr, hdr
# -1 is "nothing hit" and what an ENVI reader is to leave out (0 there, a mutant that
# passed every test, hid the room's pixels, object 0, as no data)
assert "data ignore value = -1\n" in hdr and "data units = 1\n" in hdr, hdr
for c in d["classes"]:
    assert c["auc"] == 1.0 and len(c["roc"]["true_positive_rate"]) == 101
PYEOF

# S.class.png is a figure: the class map in the classes' `color` (classification.json),
# nothing hit in black, and a legend beside it, a box of each class's colour, in the
# order of `classes`, then a black one for nothing hit (it had no legend: a user could
# not tell the colours apart). Read back: the figure's size, the legend's boxes (one
# column, right of the map), and per class its share of the map's coloured area against
# its share of S.class.img's pixels. Here the room's pixels made "nothing hit", so that
# the classes (A, B, C: objects 1, 2, 3) are not numbered as their objects: the palette
# indexed by the object instead of the class (a mutant) drew every class in the next
# class's colour.
cp -r "$work/run" "$work/run-noroom"
$PY - "$work/run-noroom/cam.object_id.img" <<'PYEOF'
import sys
import numpy as np
t = np.fromfile(sys.argv[1], "<f4")
t[t == 0] = -1
t.tofile(sys.argv[1])
PYEOF
"$THZMAP" classify "$work/run-noroom" --sensor cam -o "$work/c-noroom" --method lda -q ||
    fail "classify without the room: exit status $?"
for out in c-lda c-noroom; do
    $PY - "$work/$out" <<'PYEOF' || fail "$out: the class figure and its legend"
import json, sys
import numpy as np
from PIL import Image
from scipy import ndimage
out = sys.argv[1]
d = json.load(open(f"{out}/classification.json"))
cls = np.fromfile(f"{out}/cam.class.img", "<f4").astype(int)
png = np.asarray(Image.open(f"{out}/cam.class.png").convert("RGB")).astype(int)
h, w, _ = png.shape
# a figure 960 pixels wide (scene-format.md), not the map's 24 x 16 pixels
assert w == 960 and 240 <= h <= 1400, (w, h)
colours = [tuple(c["color"]) for c in d["classes"]] + ([(0, 0, 0)] if (cls == -1).any() else [])
assert len(set(colours)) == len(colours), colours
# each colour's regions; a legend box is one of at least 8 x 8 pixels, the rightmost
boxes, area = [], []
for c in colours:
    mask = (png == c).all(axis=2)
    lab, n = ndimage.label(mask)
    regions = [s for s in ndimage.find_objects(lab)
               if s[0].stop - s[0].start >= 8 and s[1].stop - s[1].start >= 8]
    assert regions, f"no region of colour {c}"
    box = max(regions, key=lambda s: s[1].start)
    boxes.append(box)
    area.append(int(mask.sum()) - (box[0].stop - box[0].start) * (box[1].stop - box[1].start))
# one column of boxes, in the order of the classes, right of everything else drawn in them
lefts = {b[1].start for b in boxes}
assert max(lefts) - min(lefts) <= 1, boxes
tops = [b[0].start for b in boxes]
assert tops == sorted(tops) and len(set(tops)) == len(tops), tops
for c, b in zip(colours, boxes):
    mask = (png == c).all(axis=2)
    mask[b] = False
    xs = np.nonzero(mask.any(axis=0))[0]
    if c != (0, 0, 0):  # black is also the text's and the axes'
        assert len(xs) and xs.max() < b[1].start, (c, b)
# the map: each class's share of the coloured area as its share of the class map's pixels
k = len(d["classes"])
share = np.array(area[:k], float) / sum(area[:k])
want = np.array([(cls == c["object"]).sum() for c in d["classes"]], float)
want /= want.sum()
assert np.abs(share - want).max() < 0.02, (share, want)
PYEOF
done

# accuracy against the added NETD: exact up to 1 K (the plates differ by more), then
# falling strictly with every doubling (the same seed: the same draws, scaled), and far
# down at 8 K
for n in 0 0.5 1 2 4 8; do
    "$THZMAP" classify "$work/run" --sensor cam -o "$work/n-$n" --method lda --netd-k $n -q ||
        fail "--netd-k $n exit status $?"
done
# the summary says the noise was added (classification.json's added_netd_k)
"$THZMAP" classify "$work/run" --sensor cam -o "$work/n-said" --method lda --netd-k 0.5 \
    2> "$work/said.err" || fail "--netd-k 0.5 (not quiet) exit status $?"
grep -q '^thzmap classify: .* with 0.5 K of added noise by lda: ' "$work/said.err" ||
    fail "the summary omits the added noise: $(head -1 "$work/said.err")"
grep -q "added noise" "$work/all.err" && fail "a run without --netd-k said noise was added"
$PY - "$work" <<'PYEOF' || fail "accuracy against NETD"
import json, sys
acc = [json.load(open(f"{sys.argv[1]}/n-{n}/classification.json"))["accuracy"]
       for n in ("0", "0.5", "1", "2", "4", "8")]
assert acc[:3] == [1.0, 1.0, 1.0], acc
assert 1.0 > acc[3] > acc[4] > acc[5], acc
assert acc[-1] < 0.7, acc
# each class's auc is the area under its own ROC: the 101-point curve's trapezoids, within
# the points' spacing (the held-out pixels / 100 each), at 8 K where the classes' AUCs differ
# (every class given class 0's auc or ROC, mutants, passed every test: at 0 K all are 1)
d = json.load(open(f"{sys.argv[1]}/n-8/classification.json"))
auc = [c["auc"] for c in d["classes"]]
assert max(auc) - min(auc) > 0.1, auc
for c in d["classes"]:
    f, t = c["roc"]["false_positive_rate"], c["roc"]["true_positive_rate"]
    area = sum((f[i + 1] - f[i]) * (t[i + 1] + t[i]) / 2 for i in range(len(f) - 1))
    assert abs(area - c["auc"]) < 0.01, (c["name"], area, c["auc"])
PYEOF

# a measured cube is preferred: a copy of the run with a noisy measured cube
cp -r "$work/run" "$work/run2"
cp "$work/run/cam.brightness_temperature.hdr" "$work/run2/cam.measured_brightness_temperature.hdr"
$PY -c "
import numpy as np
a = np.fromfile('$work/run/cam.brightness_temperature.img', '<f4')
r = np.random.default_rng(1)
(a + r.normal(0, 5, a.shape)).astype('<f4').tofile('$work/run2/cam.measured_brightness_temperature.img')"
"$THZMAP" classify "$work/run2" --sensor cam -o "$work/m" --method lda -q || fail "measured: exit status $?"
$PY -c "
import json; d = json.load(open('$work/m/classification.json'))
assert d['source'] == 'cam.measured_brightness_temperature', d['source']
assert d['accuracy'] < 0.9, d['accuracy']" || fail "the measured cube was not used"

# a measured header that is there but is no file to read (a directory, too large) is an
# error, not a quiet fallback to the noise-free cube (the classification would be of
# the sensor without its noise)
cp -r "$work/run2" "$work/run2d"
rm "$work/run2d/cam.measured_brightness_temperature.hdr"
mkdir "$work/run2d/cam.measured_brightness_temperature.hdr"
"$THZMAP" classify "$work/run2d" --sensor cam -o "$work/md" --method lda -q 2> "$work/err"
rc=$?
[ $rc -eq 2 ] || fail "a measured header that is a directory: exit status $rc, expected 2"
grep -q 'cam\.measured_brightness_temperature\.hdr: .*directory' "$work/err" ||
    fail "a measured header that is a directory: $(cat "$work/err")"
[ ! -e "$work/md" ] || fail "a measured header that is a directory: OUTDIR written"

# a run whose sensor has noise writes the measured cube; classify takes it
$PY -c "
import json; d = json.load(open('$IN/distinct.json'))
d['sensors'][0]['noise'] = {'netd_k': 3.0}
json.dump(d, open('$work/noisy.json', 'w'))"
"$THZMAP" simulate "$work/noisy.json" -o "$work/run3" -q --seed 3 || fail "noisy simulate exit status $?"
[ -s "$work/run3/cam.measured_brightness_temperature.img" ] || fail "no measured cube written"
"$THZMAP" classify "$work/run3" --sensor cam -o "$work/m3" --method lda -q || fail "noisy: exit status $?"
$PY -c "
import json; d = json.load(open('$work/m3/classification.json'))
assert d['source'] == 'cam.measured_brightness_temperature', d['source']
assert d['accuracy'] < 1.0, d['accuracy']" || fail "the sensor's measured cube was not used"

# bad input
expect2() {
    local what=$1; shift
    "$THZMAP" classify "$@" > /dev/null 2> "$work/err"
    local rc=$?
    [ $rc -eq 2 ] || fail "$what: exit status $rc, expected 2"
    [ -s "$work/err" ] || fail "$what: no message"
}
expect2 "no sensor" "$work/run" -o "$work/x"
expect2 "unknown sensor" "$work/run" --sensor nope -o "$work/x"
# said as a sensor the run lacks, naming the ones it has (was: nope.brightness_temperature.hdr
# cannot be opened); a directory without any sensor's cube says so
grep -q "^thzmap: $work/run: the run there has no sensor \"nope\"; its sensor: \"cam\"$" "$work/err" ||
    fail "unknown sensor: $(cat "$work/err")"
mkdir "$work/no-sensors"
expect2 "a directory of no run" "$work/no-sensors" --sensor cam -o "$work/x"
grep -q "no-sensors: the run there has no sensor \"cam\", nor any other" "$work/err" ||
    fail "a directory of no run: $(cat "$work/err")"
# a run directory that is not there: said so (was: its cube file cannot be opened)
expect2 "no directory" "$work/not-there" --sensor cam -o "$work/x"
grep -q "^thzmap: $work/not-there: no run directory there (No such file or directory)$" "$work/err" ||
    fail "no directory: $(cat "$work/err")"
# sensors too many for one message: whole names, then how many more
for k in $(seq 100 159); do : > "$work/no-sensors/sensor_with_a_long_name_$k.brightness_temperature.hdr"; done
expect2 "sixty sensors" "$work/no-sensors" --sensor cam -o "$work/x"
grep -q 'its sensors: "sensor_with_a_long_name_100", .*"sensor_with_a_long_name_1[0-9][0-9]" and [1-9][0-9]* more$' \
    "$work/err" || fail "sixty sensors: $(cat "$work/err")"
expect2 "unknown method" "$work/run" --sensor cam -o "$work/x" --method svm
expect2 "seed beyond 2^63 - 1 (classification.json could not record it)" "$work/run" \
    --sensor cam -o "$work/x" --seed 9223372036854775808
expect2 "no run" "$work/none" --sensor cam -o "$work/x"
# one channel: sam's angle is 0 to every class (every pixel went to the first class, 37.5 %
# on plate-in-box, silently); refused, naming the methods that work; mahalanobis runs
$PY - "$IN/distinct.json" "$work/one-channel.json" <<'PYEOF'
import json, sys
d = json.load(open(sys.argv[1]))
d["channels"] = [{"frequency_thz": 0.6, "relative_width": 0.01}]
json.dump(d, open(sys.argv[2], "w"))
PYEOF
"$THZMAP" simulate "$work/one-channel.json" -o "$work/run1" -q --seed 3 || fail "one channel: simulate exit status $?"
expect2 "sam on one channel" "$work/run1" --sensor cam -o "$work/x"
grep -q "cam.brightness_temperature has 1 channel: sam .* needs 2 channels or more; use another method: mahalanobis, lda or matched-filter" \
    "$work/err" || fail "sam on one channel: $(cat "$work/err")"
[ -e "$work/x" ] && fail "sam on one channel left $work/x"
# ace likewise: its squared cosine is 1 for every pixel in one channel (a separable scene
# classified 42 % right, every class scored +-1)
expect2 "ace on one channel" "$work/run1" --sensor cam -o "$work/x" --method ace
grep -q "cam.brightness_temperature has 1 channel: ace compares spectral shapes .* needs 2 channels or more; use another method: mahalanobis, lda or matched-filter" \
    "$work/err" || fail "ace on one channel: $(cat "$work/err")"
[ -e "$work/x" ] && fail "ace on one channel left $work/x"
"$THZMAP" classify "$work/run1" --sensor cam -o "$work/c-one-mf" --method matched-filter -q ||
    fail "matched-filter on one channel: exit status $?"
"$THZMAP" classify "$work/run1" --sensor cam -o "$work/c-one-mahalanobis" --method mahalanobis -q ||
    fail "mahalanobis on one channel: exit status $?"
printf 'ENVI\nsamples = 24\nlines = 16\nbands = 5\ndata type = 4\n' > "$work/run2/cam.measured_brightness_temperature.hdr"
head -c 100 "$work/run/cam.brightness_temperature.img" > "$work/run2/cam.measured_brightness_temperature.img"
expect2 "truncated cube" "$work/run2" --sensor cam -o "$work/x"
grep -q "bytes" "$work/err" || fail "truncated cube: $(cat "$work/err")"
# a truth of one object only: nothing to tell apart (it reported 100 %), said of the truth
# file with its run directory; a cube value that is not finite, by band, row and column
cp -r "$work/run" "$work/one"
$PY - "$work/one" <<'PYEOF' || fail "test set-up: one-object truth"
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
expect2 "one object" "$work/one" --sensor cam -o "$work/x"
grep -q "one/cam.object_id: the truth map shows one object only" "$work/err" ||
    fail "one object: $(cat "$work/err")"
cp "$work/run/cam.object_id.img" "$work/one/cam.object_id.img"
mv "$work/one/cam.brightness_temperature.nan" "$work/one/cam.brightness_temperature.img"
expect2 "a NaN in the cube" "$work/one" --sensor cam -o "$work/x"
grep -q "one/cam.brightness_temperature: band 2, row 3, column 6 holds a value that is not finite" \
    "$work/err" || fail "NaN pixel: $(cat "$work/err")"
[ -e "$work/x" ] && fail "a failed run left $work/x"
echo ok
