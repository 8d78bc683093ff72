#!/bin/bash
# thzmap bands: on plates whose emissivity peaks at known frequencies it chooses a
# channel within one grid step of each feature (K = the number of features); with a
# feature across a water-vapour line and humid air it moves off the line, where dry
# air lets it sit on it; bands.json as the reference says (selected_thz ascending,
# score, the best set of every k <= K), the figures, determinism for a seed and any
# thread count, and exit status 2 for bad input.
# argv: thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
IN="$REPO/tests/inputs/analysis"
# unlike lib.sh's fail: on stderr, and the test stops at the first failure
fail() { echo "FAIL: $*" >&2; exit 1; }
PY=/usr/bin/python3

"$THZMAP" bands --help > "$work/help" || fail "--help exit status $?"
for o in --count --from-thz --to-thz --step-ghz --targets --netd-k --humidity-range --widths \
    --thickness-range --angle-range-deg; do
    grep -q -- "$o" "$work/help" || fail "--help does not describe $o"
done

# progress into a log (not a terminal): a line as each render ends, the nominal one
# first, then the nuisances' renders counted (it printed nothing until the end)
"$THZMAP" bands "$IN/features.json" -o "$work/log" --count 2 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 4 --threads 1 2> "$work/log.err" || fail "progress run exit status $?"
grep -E '^thzmap bands: render ' "$work/log.err" | sed -E 's/ in [0-9.]+ s$//' > "$work/renders"
# (the coarse nominal and one per target: room, A, B, C)
{ echo "thzmap bands: render 1 (nominal): 17 candidate channels"
  for i in 2 3 4 5 6; do echo "thzmap bands: render $i/6: 17 candidate channels"; done; } |
    diff - "$work/renders" ||
    fail "progress lines: $(cat "$work/log.err")"

# features at 0.40 and 0.80 THz, candidates every 50 GHz from 0.2 to 1.0 THz
"$THZMAP" bands "$IN/features.json" -o "$work/f" --count 2 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 4 -q --threads 1 || fail "features run exit status $?"
for f in bands.json bands-score.png bands-spectra.png; do
    [ -s "$work/f/$f" ] || fail "no $f"
done
[ -e "$work/f/bands-air.png" ] && fail "bands-air.png written without attenuating air"
$PY - "$work/f/bands.json" <<'PYEOF' || fail "features: $(cat "$work/f/bands.json" | head -c 600)"
import json, sys
d = json.load(open(sys.argv[1]))
sel = d["selected_thz"]
assert sel == sorted(sel), "not ascending"
assert len(sel) == 2 and d["count"] == 2
step = 0.05
for feature in (0.40, 0.80):
    assert any(abs(f - feature) <= step + 1e-9 for f in sel), f"no channel near {feature}: {sel}"
assert 0.0 <= d["score"] <= 2.0
assert len(d["per_k"]) == 2
scores = [e["score"] for e in d["per_k"]]
assert all(b >= a - 1e-3 for a, b in zip(scores, scores[1:])), scores
assert d["per_k"][1]["selected_thz"] == sel and d["per_k"][1]["score"] == d["score"]
assert d["search"] == "exhaustive"
assert len(d["candidates"]["frequency_thz"]) == 17
assert [c["name"] for c in d["classes"]] == ["room", "A", "B", "C"]
assert d["noise"]["netd_k"] == [0.5] * 17 and "no noise" in d["noise"]["source"]
PYEOF

# the same with two threads: the same file but for its timing
"$THZMAP" bands "$IN/features.json" -o "$work/f2" --count 2 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 4 -q --threads 2 || fail "second run exit status $?"
$PY - "$work/f/bands.json" "$work/f2/bands.json" <<'PYEOF' || fail "not reproducible over threads"
import json, sys
a, b = (json.load(open(p)) for p in sys.argv[1:3])
a.pop("seconds"); b.pop("seconds")
assert a == b
PYEOF

# per_k[0] (one channel) from bands.json's own class statistics: each class's variance in
# the channel its pixels' spread, its nuisances' and the NETD squared; B of every pair,
# the worst (its JM the score, its pair the worst_pair) and the mean JM; the top level is
# per_k's last entry. The top-level mean_jm taken from k = 1, or per_k's B and worst pair
# from k = K (mutants), passed every test, whose checks of these had K = 1. (abs_tol: a B of
# 1e-3 from means of 300 K written with bands.json's 10 digits.)
$PY - "$work/f/bands.json" <<'PYEOF' || fail "per_k from the class statistics"
import itertools, json, math, sys
d = json.load(open(sys.argv[1]))
e = d["per_k"][0]
c = d["candidates"]["frequency_thz"].index(e["selected_thz"][0])
var = lambda k: k["pixel_sd_k"][c] ** 2 + k["nuisance_sd_k"][c] ** 2 + k["netd_k"][c] ** 2
def bhatt(a, b):
    v1, v2 = var(a), var(b)
    v = (v1 + v2) / 2
    return (a["mean_tb_k"][c] - b["mean_tb_k"][c]) ** 2 / (8 * v) + 0.5 * math.log(v / math.sqrt(v1 * v2))
pairs = sorted((bhatt(a, b), a["name"], b["name"]) for a, b in itertools.combinations(d["classes"], 2))
jm = [2 * (1 - math.exp(-b)) for b, _, _ in pairs]
print("k = 1:", pairs[0], e, file=sys.stderr)
assert math.isclose(pairs[0][0], e["bhattacharyya"], rel_tol=1e-6, abs_tol=1e-7)
assert math.isclose(jm[0], e["score"], rel_tol=1e-6, abs_tol=1e-7)
assert sorted(e["worst_pair"]) == sorted(pairs[0][1:])
assert math.isclose(sum(jm) / len(jm), e["mean_jm"], rel_tol=1e-6, abs_tol=1e-7)
last = d["per_k"][-1]
for key in ("selected_thz", "selected_relative_width", "score", "bhattacharyya", "mean_jm",
            "worst_pair"):
    assert d[key] == last[key], key
# the k = 1 and k = 2 entries differ where the tests above could not tell them apart
assert e["mean_jm"] != last["mean_jm"] and e["bhattacharyya"] != last["bhattacharyya"]
PYEOF

# --targets: the plates and the rest as one background class
"$THZMAP" bands "$IN/features.json" -o "$work/t" --count 2 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 4 -q --targets A,B || fail "--targets run exit status $?"
$PY -c "import json,sys; d=json.load(open('$work/t/bands.json')); \
names=[c['name'] for c in d['classes']]; assert names==['A','B','background'], names" \
    || fail "--targets classes"
# the scene has no air: its temperature is not among the nuisances (two background
# objects varied together once made it look so)
$PY -c "import json; n=json.load(open('$work/t/bands.json'))['nuisances']; \
assert not n['air_temperature_varied'], n" || fail "air temperature 'varied' in a scene without air"
# the nuisances not given take their documented defaults: +-2 K for the targets and for the
# rest, the humidity +-0.2 of itself, the thickness and the angle not varied
$PY -c "import json; n=json.load(open('$work/t/bands.json'))['nuisances']; \
assert (n['target_temperature_range_k'], n['ambient_temperature_range_k'], n['humidity_range'], \
n['thickness_range'], n['angle_range_deg']) == (2, 2, 0.2, 0, 0), n" || fail "default nuisances"

# a feature across the 556.9 GHz water line: dry air lets the choice sit on the line,
# humid air moves it off (within the feature, 0.52-0.60 THz)
for air in dry humid; do
    "$THZMAP" bands "$IN/water-line-$air.json" -o "$work/w-$air" --count 2 --from-thz 0.5 \
        --to-thz 0.72 --step-ghz 20 --paths 4 -q || fail "water line ($air) exit status $?"
done
[ -s "$work/w-humid/bands-air.png" ] || fail "no bands-air.png with humid air"
$PY - "$work/w-dry/bands.json" "$work/w-humid/bands.json" <<'PYEOF' || fail "water line"
import json, sys
dry, humid = (json.load(open(p))["selected_thz"] for p in sys.argv[1:3])
line = 0.55693
for sel, name in ((dry, "dry"), (humid, "humid")):
    assert any(abs(f - 0.68) <= 0.02 + 1e-9 for f in sel), f"{name}: no channel near 0.68: {sel}"
    feature = [f for f in sel if 0.50 <= f <= 0.62]
    assert len(feature) == 1, f"{name}: no channel in the 0.52-0.60 THz feature: {sel}"
humid_f = [f for f in humid if 0.50 <= f <= 0.62][0]
assert abs(humid_f - line) > 0.01, f"humid air: {humid_f} THz still on the line"
# on the line's candidate the dry spectrum of B is as high as anywhere on its feature
# (so the move is the air's doing), the humid one far lower
d = json.load(open(sys.argv[1])); h = json.load(open(sys.argv[2]))
freqs = d["candidates"]["frequency_thz"]
i_line = min(range(len(freqs)), key=lambda i: abs(freqs[i] - line))
plateau = [i for i, f in enumerate(freqs) if 0.52 <= f <= 0.60]
tb_dry = next(c for c in d["classes"] if c["name"] == "B")["mean_tb_k"]
tb_humid = next(c for c in h["classes"] if c["name"] == "B")["mean_tb_k"]
assert tb_dry[i_line] > max(tb_dry[i] for i in plateau) - 0.3, tb_dry
assert tb_humid[i_line] < tb_humid[freqs.index(humid_f)] - 2.0, tb_humid
# the air's temperature is given here: it is among the nuisances varied
assert h["nuisances"]["air_temperature_varied"], h["nuisances"]
# ... and so is its humidity (bands.json's humidity_varied never set, a mutant, passed
# every test)
assert h["nuisances"]["humidity_varied"], h["nuisances"]
PYEOF

# the sensor's noise: a given netd_k per channel, interpolated to the candidates; a
# radiometer, whose NETD falls as 1/sqrt(bandwidth), i.e. 1/sqrt(frequency) at a fixed
# relative width; --netd-k overrides both
$PY - "$IN/features.json" "$work" <<'PYEOF' || fail "noisy scenes"
import json, sys
d = json.load(open(sys.argv[1]))
d["channels"] = [{"frequency_thz": 0.2, "relative_width": 0.01},
                 {"frequency_thz": 1.0, "relative_width": 0.01}]
d["sensors"][0]["noise"] = {"netd_k": [0.2, 1.0]}
json.dump(d, open(sys.argv[2] + "/netd.json", "w"))
d["sensors"][0]["noise"] = {"receiver_temperature_k": 2000, "integration_time_s": 0.001,
                            "radiometer": "total-power"}
json.dump(d, open(sys.argv[2] + "/radiometer.json", "w"))
PYEOF
for s in netd radiometer; do
    "$THZMAP" bands "$work/$s.json" -o "$work/n-$s" --count 1 --from-thz 0.2 --to-thz 1.0 \
        --step-ghz 200 --paths 2 -q || fail "$s scene exit status $?"
done
"$THZMAP" bands "$work/netd.json" -o "$work/n-given" --count 1 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 200 --paths 2 -q --netd-k 0.7 || fail "--netd-k on a noisy scene: exit status $?"
$PY - "$work" <<'PYEOF' || fail "the sensor's NETD"
import json, math, sys
n = {k: json.load(open(f"{sys.argv[1]}/n-{k}/bands.json"))["noise"]
     for k in ("netd", "radiometer", "given")}
assert "interpolated" in n["netd"]["source"], n["netd"]
assert all(abs(a - b) < 1e-12 for a, b in zip(n["netd"]["netd_k"], [0.2, 0.4, 0.6, 0.8, 1.0])), n["netd"]
r = n["radiometer"]["netd_k"]
assert "radiometer" in n["radiometer"]["source"] and all(x > 0 for x in r), n["radiometer"]
# T_rec dominates: NETD ~ (T + T_rec) / sqrt(B_n tau), B_n proportional to the frequency
assert abs(r[0] / r[4] / math.sqrt(5.0) - 1.0) < 0.02, r
assert n["given"]["netd_k"] == [0.7] * 5 and n["given"]["source"] == "--netd-k", n["given"]
# the radiometer's NETD in each class's covariance is at the class's own Tb:
# NETD ~ Tb + T_rec (T_rec = 2000 K), so the plates at 310 K read more noise than the room
cl = json.load(open(f"{sys.argv[1]}/n-radiometer/bands.json"))["classes"]
room, plate = cl[0], cl[1]
for c in range(5):
    ratio = plate["netd_k"][c] / room["netd_k"][c]
    expect = (plate["mean_tb_k"][c] + 2000) / (room["mean_tb_k"][c] + 2000)
    assert abs(ratio / expect - 1) < 1e-9 and abs(ratio - 1) > 1e-3, (c, ratio, expect)
given = json.load(open(f"{sys.argv[1]}/n-given/bands.json"))["classes"]
assert all(k["netd_k"] == [0.7] * 5 for k in given), given
PYEOF

# widths searched: every centre with a narrow (1 %) and a broad (30 %) width at one
# NETD; the 80 GHz-wide features are diluted in a 120-240 GHz-wide channel, so the
# narrow width is chosen at each feature and no centre is chosen twice
"$THZMAP" bands "$IN/features.json" -o "$work/wd" --count 2 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 4 -q --widths 0.3,0.01 || fail "--widths run exit status $?"
$PY - "$work/wd/bands.json" <<'PYEOF' || fail "widths: $(head -c 600 "$work/wd/bands.json")"
import json, sys
d = json.load(open(sys.argv[1]))
sel, wid = d["selected_thz"], d["selected_relative_width"]
assert sel == sorted(sel) and len(set(sel)) == 2, sel
for feature in (0.40, 0.80):
    assert any(abs(f - feature) <= 0.05 + 1e-9 for f in sel), f"no channel near {feature}: {sel}"
assert wid == [0.01, 0.01], wid
c = d["candidates"]
assert c["relative_widths"] == [0.01, 0.3] and c["relative_width"] is None, c
assert len(c["frequency_thz"]) == 34 and c["candidate_relative_width"][:2] == [0.01, 0.3], c
for e in d["per_k"]:
    assert len(e["selected_relative_width"]) == e["k"] and len(set(e["selected_thz"])) == e["k"], e
# the widths are rendered: plate A's Tb at its 0.40 THz feature is higher in the narrow
# channel than in the broad one, which averages the feature with its flanks
i = c["frequency_thz"].index(0.4)
a = next(k for k in d["classes"] if k["name"] == "A")["mean_tb_k"]
assert a[i] > a[i + 1] + 1.0, (a[i], a[i + 1])
PYEOF

# nuisances of the cover's thickness and of the viewing angle: plate A (310 K) behind a
# 0.5 mm shell at 280 K (alpha t = 1), whose pixels the truth names "cover"; varying the thickness by
# +-50 % spreads that class and hardly B's (which nothing covers); turning the sensor by
# 10 degrees spreads the classes too
$PY - "$IN/features.json" "$work" <<'PYEOF' || fail "covered scene"
import json, sys
d = json.load(open(sys.argv[1]))
d["materials"]["cloth"] = {"reflectivity": 0.05, "attenuation_per_m": 2000}
d["objects"].append({"name": "cover", "type": "shell", "thickness_m": 0.0005,
                     "material": "cloth", "temperature_k": 280,
                     "shape": {"type": "rectangle", "size_m": [0.34, 0.64]},
                     "transform": {"rotate_deg": [90, 0, 0], "translate_m": [-0.35, 0.45, 0]}})
json.dump(d, open(sys.argv[2] + "/covered.json", "w"))
PYEOF
# plate A hidden whole by the cover: a target the sensor sees no pixel of is refused,
# and the message says what to name instead (it said only 'sees no pixel of')
"$THZMAP" bands "$work/covered.json" -o "$work/hidden" --count 1 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 400 --paths 1 -q --targets A,B 2> "$work/hidden.err"
[ $? -eq 2 ] || fail "a hidden target: exit status not 2"
grep -q "targets: the sensor sees no pixel of 'A' (.*a target behind a cover is the cover's pixels; name the cover" \
    "$work/hidden.err" || fail "a hidden target: $(cat "$work/hidden.err")"
[ -e "$work/hidden" ] && fail "a hidden target: OUTDIR written"
NUIS="--count 1 --from-thz 0.2 --to-thz 1.0 --step-ghz 200 --paths 2 -q --targets cover,B,C
      --temperature-range-k 0 --ambient-range-k 0 --humidity-range 0"
# shellcheck disable=SC2086
"$THZMAP" bands "$work/covered.json" -o "$work/c0" $NUIS || fail "covered scene exit status $?"
# shellcheck disable=SC2086
"$THZMAP" bands "$work/covered.json" -o "$work/ct" $NUIS --thickness-range 0.5 \
    || fail "--thickness-range exit status $?"
# shellcheck disable=SC2086
"$THZMAP" bands "$work/covered.json" -o "$work/ca" $NUIS --angle-range-deg 10 \
    || fail "--angle-range-deg exit status $?"
# the same camera given by a direction instead of look_at_m: turned about its position
$PY - "$work/covered.json" "$work/covered-dir.json" <<'PYEOF'
import json, math, sys
d = json.load(open(sys.argv[1]))
for sn in d["sensors"]:
    at = sn.pop("look_at_m")
    v = [a - p for a, p in zip(at, sn["position_m"])]
    n = math.sqrt(sum(x * x for x in v))
    sn["direction"] = [x / n for x in v]
json.dump(d, open(sys.argv[2], "w"))
PYEOF
# shellcheck disable=SC2086
"$THZMAP" bands "$work/covered-dir.json" -o "$work/cd" $NUIS --angle-range-deg 10 \
    || fail "--angle-range-deg with a sensor direction: exit status $?"
$PY - "$work" <<'PYEOF' || fail "thickness and angle nuisances"
import json, sys
r = {k: json.load(open(f"{sys.argv[1]}/{k}/bands.json")) for k in ("c0", "ct", "ca", "cd")}
sd = {k: {c["name"]: c["nuisance_sd_k"] for c in d["classes"]} for k, d in r.items()}
assert r["c0"]["renders"] == 1 and all(x == 0 for v in sd["c0"].values() for x in v), sd["c0"]
n = r["ct"]["nuisances"]
# the nominal render, and a coarse nominal and the variant (1 sample per pixel, a
# quarter of the paths)
assert r["ct"]["renders"] == 3 and n["thickness_varied"] and n["thickness_range"] == 0.5, n
assert all(c > 0.3 and c > 10 * b for c, b in zip(sd["ct"]["cover"], sd["ct"]["B"])), sd["ct"]
n = r["ca"]["nuisances"]
assert n["render_paths_per_sample"] == 1 and n["render_oversampling"] == 1, n
assert r["ca"]["renders"] == 3 and n["angle_varied"] and not n["thickness_varied"], n
assert max(max(v) for v in sd["ca"].values()) > 0.05, sd["ca"]
assert r["cd"]["nuisances"]["angle_varied"], r["cd"]["nuisances"]
assert max(max(v) for v in sd["cd"].values()) > 0.05, sd["cd"]
# no air in this scene: the humidity is not among the nuisances varied
assert not any(d["nuisances"]["humidity_varied"] for d in r.values()), r["ct"]["nuisances"]
PYEOF
# a pan of 90 degrees leaves the targets out of view: "a class the turned sensor no longer
# sees gets no angle spread" (analysis.md); the room it then sees does. A lost class's mean
# taken as 0 K instead of the nominal one (a mutant) passed every test: a spread of
# 280 / sqrt(3) K, the class unseparable from anything.
# shellcheck disable=SC2086
"$THZMAP" bands "$work/covered-dir.json" -o "$work/c90" $NUIS --angle-range-deg 90 \
    || fail "--angle-range-deg 90: exit status $?"
$PY - "$work/c90/bands.json" <<'PYEOF' || fail "a class out of the turned view: $(head -c 600 "$work/c90/bands.json")"
import json, sys
sd = {c["name"]: c["nuisance_sd_k"] for c in json.load(open(sys.argv[1]))["classes"]}
assert all(x == 0.0 for name in ("cover", "B", "C") for x in sd[name]), sd
assert min(sd["background"]) > 0.5, sd
PYEOF

# nuisances by hand: black objects seen directly (no air, no reflection: path's estimate
# is the band mean of B(T) exactly, no Monte Carlo noise), so raising the target A by
# --temperature-range-k 3 raises its Tb by 3 K and the ambient (the room) by 2 K the
# background's by 2 K; a uniform variation within +-range has the spread range / sqrt(3):
# nuisance_sd_k 1.7321 K for A, 1.1547 K for the background, in every candidate (range /
# 3 instead passed every test)
cat > "$work/plate.json" <<'EOF'
{"format": "thzmap-scene/1", "name": "plate",
 "channels": [{"frequency_thz": 0.5, "relative_width": 0.01}],
 "materials": {"black": {"reflectivity": 0}},
 "objects": [{"name": "room", "type": "solid", "material": "black", "temperature_k": 290,
              "shape": {"type": "box", "size_m": [4, 4, 4], "inward": true}},
             {"name": "A", "type": "solid", "material": "black", "temperature_k": 300,
              "shape": {"type": "box", "size_m": [0.6, 0.1, 0.6]},
              "transform": {"translate_m": [0, 1, 0]}}],
 "sensors": [{"name": "cam", "position_m": [0, 0, 0], "direction": [0, 1, 0], "up": [0, 0, 1],
              "fov_deg": 40, "resolution": [16, 16]}],
 "render": {"integrator": "path", "paths_per_sample": 1}}
EOF
"$THZMAP" bands "$work/plate.json" -o "$work/plate" --count 1 --from-thz 0.3 --to-thz 0.7 \
    --step-ghz 200 --paths 1 -q --targets A --temperature-range-k 3 --ambient-range-k 2 \
    --humidity-range 0 --netd-k 0.1 --threads 1 || fail "plate run exit status $?"
$PY - "$work/plate/bands.json" <<'PYEOF' || fail "nuisance spreads: $(head -c 600 "$work/plate/bands.json")"
import json, math, sys
sd = {c["name"]: c["nuisance_sd_k"] for c in json.load(open(sys.argv[1]))["classes"]}
for name, rng in (("A", 3.0), ("background", 2.0)):
    assert len(sd[name]) == 3 and all(abs(x / (rng / math.sqrt(3.0)) - 1.0) < 1e-3
                                      for x in sd[name]), (name, sd[name])
PYEOF

# Two channels of the same plates: each class has one nuisance (A its own temperature,
# the background the room's), which moves its Tb the same way in both channels, so its
# covariance is its nuisance_sd_k's outer product (correlation 1) plus the NETD^2 (its
# pixels do not spread): the worst pair's B from bands.json's class statistics with that
# covariance. A nuisance added to the diagonal alone (a mutant) passed every test (the
# one-channel checks cannot see a correlation): B 11.56 for 5.80, as if each channel
# brought independent evidence when one temperature change moves both.
"$THZMAP" bands "$work/plate.json" -o "$work/plate2" --count 2 --from-thz 0.3 --to-thz 0.7 \
    --step-ghz 200 --paths 1 -q --targets A --temperature-range-k 3 --ambient-range-k 2 \
    --humidity-range 0 --netd-k 0.1 --threads 1 || fail "plate run, two channels: exit status $?"
$PY - "$work/plate2/bands.json" <<'PYEOF' || fail "nuisance correlation: $(head -c 600 "$work/plate2/bands.json")"
import json, math, sys
import numpy as np
d = json.load(open(sys.argv[1]))
f = d["candidates"]["frequency_thz"]
idx = [f.index(x) for x in d["selected_thz"]]
a, bg = d["classes"]
assert (a["name"], bg["name"]) == ("A", "background") and len(idx) == 2, d["classes"]
def cov(c):
    g = lambda key: np.array([c[key][i] for i in idx])
    assert all(g("pixel_sd_k") == 0.0), c
    return np.outer(g("nuisance_sd_k"), g("nuisance_sd_k")) + np.diag(g("netd_k") ** 2)
ca, cb = cov(a), cov(bg)
s = (ca + cb) / 2
dm = np.array([a["mean_tb_k"][i] - bg["mean_tb_k"][i] for i in idx])
b = dm @ np.linalg.solve(s, dm) / 8 + 0.5 * math.log(
    np.linalg.det(s) / math.sqrt(np.linalg.det(ca) * np.linalg.det(cb)))
print("B", b, d["bhattacharyya"], file=sys.stderr)
sys.exit(0 if math.isclose(b, d["bhattacharyya"], rel_tol=1e-6) else 1)
PYEOF

# bad input: exit status 2 and a message naming the problem
expect2() {
    local what=$1; shift
    "$THZMAP" bands "$@" > /dev/null 2> "$work/err"
    local rc=$?
    [ $rc -eq 2 ] || fail "$what: exit status $rc, expected 2"
    [ -s "$work/err" ] || fail "$what: no message"
}
expect2 "no --count" "$IN/features.json" -o "$work/x"
expect2 "--count 0" "$IN/features.json" -o "$work/x" --count 0
expect2 "no -o" "$IN/features.json" --count 1
expect2 "to below from" "$IN/features.json" -o "$work/x" --count 1 --from-thz 1 --to-thz 0.5
# a first channel with a measured response (no relative_width): the candidates take its
# FWHM / centre (0.05 THz / 0.5 THz), not the 0 that blamed the scene's channels[0].relative_width
$PY - "$IN/features.json" "$work/response.json" <<'PYEOF'
import json, sys
d = json.load(open(sys.argv[1]))
d["channels"] = [{"frequency_thz": 0.5, "response": [[0.45, 0], [0.5, 1], [0.55, 0]]}]
json.dump(d, open(sys.argv[2], "w"))
PYEOF
"$THZMAP" bands "$work/response.json" -o "$work/resp" --count 1 --from-thz 0.4 --to-thz 0.8 \
    --step-ghz 400 --paths 2 -q 2> "$work/resp.err" || fail "response channel: $(cat "$work/resp.err")"
$PY -c 'import json, sys; c = json.load(open(sys.argv[1]))["candidates"]
assert abs(c["relative_width"] - 0.1) < 1e-9, c' "$work/resp/bands.json" ||
    fail "response channel: not its FWHM / centre"

# two targets of one material: their means differ by the renders' Monte Carlo noise
# alone, which the worst pair's B does not exceed: a warning on standard error (also
# with -q) and in bands.json; two different plates: none
$PY - "$IN/flat-and-dip.json" "$work/identical.json" <<'PYEOF'
import json, sys
d = json.load(open(sys.argv[1]))
for o in d["objects"]:
    if o["name"] == "Y":
        o["material"] = "x"
json.dump(d, open(sys.argv[2], "w"))
PYEOF
for s in identical flat; do
    scene="$work/identical.json"; [ $s = flat ] && scene="$IN/flat-and-dip.json"
    "$THZMAP" bands "$scene" -o "$work/$s" --count 2 --from-thz 0.2 --to-thz 1.0 --step-ghz 50 \
        --paths 4 --targets X,Y -q 2> "$work/$s.err" || fail "$s targets: exit status $?"
done
grep -q "^thzmap bands: warning: 'X' and 'Y' cannot be told apart: their Bhattacharyya distance" \
    "$work/identical.err" || fail "identical targets, no warning: $(cat "$work/identical.err")"
[ -s "$work/flat.err" ] && fail "different targets warned: $(cat "$work/flat.err")"
$PY - "$work/identical/bands.json" "$work/flat/bands.json" <<'PYEOF' || fail "warnings in bands.json"
import json, sys
same, diff = (json.load(open(p)) for p in sys.argv[1:3])
assert same["bhattacharyya"] <= same["monte_carlo_bhattacharyya"], same
assert len(same["warnings"]) == 1 and "cannot be told apart" in same["warnings"][0], same
assert diff["warnings"] == [] and diff["bhattacharyya"] > 10 * diff["monte_carlo_bhattacharyya"]
PYEOF

# one path of one sample per pixel estimates no standard error: the pixels' variance stands
# in for the Monte Carlo one (analysis.md, a bound), and the spreads hold the render's
# noise, so that on one channel monte_carlo_bhattacharyya = r (1 + 3 sqrt 2) / 8
# + 1/2 ln(S / sqrt(S_X S_Y)), r = (sd_X^2 / n_X + sd_Y^2 / n_Y) / S with S_X, S_Y the
# classes' variances and S their mean, from bands.json's class statistics. A render taken
# as having standard errors whatever they were (a mutant) passed every test: the means'
# noise then 0, and B_MC 0, for every --paths 1 run.
"$THZMAP" bands "$work/identical.json" -o "$work/id1" --count 1 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 1 --targets X,Y -q || fail "one path: exit status $?"
$PY - "$work/id1/bands.json" <<'PYEOF' || fail "B_MC with one path: $(head -c 600 "$work/id1/bands.json")"
import json, math, sys
d = json.load(open(sys.argv[1]))
c = d["candidates"]["frequency_thz"].index(d["selected_thz"][0])
cl = {k["name"]: k for k in d["classes"]}
x, y = (cl[n] for n in d["worst_pair"])
var = lambda k: k["pixel_sd_k"][c] ** 2 + k["nuisance_sd_k"][c] ** 2 + k["netd_k"][c] ** 2
r = (x["pixel_sd_k"][c] ** 2 / x["pixels"] + y["pixel_sd_k"][c] ** 2 / y["pixels"]) / (
    (var(x) + var(y)) / 2)
want = r * (1 + 3 * math.sqrt(2)) / 8 + 0.5 * math.log(
    (var(x) + var(y)) / 2 / math.sqrt(var(x) * var(y)))
assert want > 1e-3 and math.isclose(d["monte_carlo_bhattacharyya"], want, rel_tol=1e-6), want
PYEOF

# ... and on two channels the search picks a pair where one class's spread holds a few
# pixels that met something hot: B 0.856, all from the spreads, against 0.019 from the
# means alone, and no warning before
"$THZMAP" bands "$work/identical.json" -o "$work/id1k2" --count 2 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 1 --targets X,Y -q 2> "$work/id1k2.err" || fail "one path, two channels"
grep -q "^thzmap bands: warning: 'X' and 'Y' cannot be told apart: .* and of their spreads" \
    "$work/id1k2.err" || fail "one path, two channels: no warning: $(cat "$work/id1k2.err")"

expect2 "unknown target" "$IN/features.json" -o "$work/x" --count 1 --targets A,nope
grep -q "nope" "$work/err" || fail "unknown target not named: $(cat "$work/err")"
expect2 "no sensor noise" "$IN/features.json" -o "$work/x" --count 1 --netd-k 0
grep -q -- "--netd-k expects a number above 0" "$work/err" || fail "NETD 0 not named: $(cat "$work/err")"
expect2 "missing scene" "$work/none.json" -o "$work/x" --count 1
expect2 "count above candidates" "$IN/features.json" -o "$work/x" --count 3 --from-thz 0.5 \
    --to-thz 0.52 --step-ghz 20
expect2 "width above 0.5" "$IN/features.json" -o "$work/x" --count 1 --widths 0.01,0.6
expect2 "an empty width" "$IN/features.json" -o "$work/x" --count 1 --widths 0.01,,0.2
expect2 "an empty target" "$IN/features.json" -o "$work/x" --count 1 --targets A,,B
expect2 "width above 0.5, said once" "$IN/features.json" -o "$work/x" --count 1 --widths 0.01,0.6
[ "$(grep -c expects "$work/err")" = 1 ] || fail "a bad width said other than once: $(cat "$work/err")"
expect2 "width twice" "$IN/features.json" -o "$work/x" --count 1 --widths 0.01,0.01
grep -q "twice" "$work/err" || fail "a repeated width not named: $(cat "$work/err")"
expect2 "angle above 90" "$IN/features.json" -o "$work/x" --count 1 --angle-range-deg 91
grep -q -- "--angle-range-deg.*91" "$work/err" || fail "the bad angle not named: $(cat "$work/err")"
expect2 "a width and widths" "$IN/features.json" -o "$work/x" --count 1 --relative-width 0.02 \
    --widths 0.01,0.05
grep -q -- "--relative-width 0.02 and --widths" "$work/err" ||
  fail "--relative-width with --widths not refused by name: $(cat "$work/err")"
expect2 "count above the candidates" "$IN/features.json" -o "$work/x" --count 5 \
    --from-thz 0.5 --to-thz 0.53
grep -q -- "--count 5: only 4 candidate centres from 0.5 to 0.53 THz every 10 GHz" "$work/err" ||
    fail "--count above the candidates not refused by name: $(cat "$work/err")"
# One channel: the worst pair's B and the mean JM from bands.json's own class statistics,
# each class's variance its pixels' spread, its nuisances' and the NETD squared (a NETD
# of 0.5 K added unsquared, a helper's mutant, passed every test: the runs above have none)
"$THZMAP" bands "$IN/features.json" -o "$work/one" --count 1 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 100 --netd-k 0.5 -q 2> /dev/null || fail "one channel: exit status $?"
$PY - "$work/one/bands.json" <<'PYEOF' || fail "one channel's B from the class statistics"
import itertools, json, math, sys
d = json.load(open(sys.argv[1]))
c = d["candidates"]["frequency_thz"].index(d["selected_thz"][0])
def var(k):
    return k["pixel_sd_k"][c] ** 2 + k["nuisance_sd_k"][c] ** 2 + k["netd_k"][c] ** 2
def bhatt(a, b):
    v1, v2 = var(a), var(b)
    v = (v1 + v2) / 2
    return (a["mean_tb_k"][c] - b["mean_tb_k"][c]) ** 2 / (8 * v) + 0.5 * math.log(v / math.sqrt(v1 * v2))
assert all(k["netd_k"][c] == 0.5 for k in d["classes"]), d["classes"]
pairs = sorted((bhatt(a, b), a["name"], b["name"]) for a, b in itertools.combinations(d["classes"], 2))
jm = [2 * (1 - math.exp(-b)) for b, _, _ in pairs]
ok = (math.isclose(pairs[0][0], d["bhattacharyya"], rel_tol=1e-6) and
      sorted(d["worst_pair"]) == sorted(pairs[0][1:]) and
      math.isclose(sum(jm) / len(jm), d["mean_jm"], rel_tol=1e-6) and
      math.isclose(jm[0], d["score"], rel_tol=1e-6))
print("B", pairs[0], d["bhattacharyya"], "mean JM", sum(jm) / len(jm), d["mean_jm"], file=sys.stderr)
sys.exit(0 if ok else 1)
PYEOF
touch "$work/file"
expect2 "OUTDIR a file" "$IN/features.json" -o "$work/file" --count 1
grep -q -- "exists and is not a directory" "$work/err" || fail "-o FILE: $(cat "$work/err")"
expect2 "thickness range 1" "$IN/features.json" -o "$work/x" --count 1 --thickness-range 1
[ -e "$work/x" ] && fail "a failed run left $work/x"

# an OUTDIR another run is writing into is refused before the renders, not after every
# one of them (the work lost); here a long simulate holds OUTDIR's lock
"$THZMAP" simulate "$REPO/examples/plate-in-box/scene.json" -o "$work/busy" --photons 50000000 \
    --integrator photon-map 2> "$work/busy.err" &
busy=$!
for _ in $(seq 600); do # the estimate's line: OUTDIR (and its lock) opened
    grep -q "estimate:" "$work/busy.err" 2>/dev/null && break
    sleep 0.1
done
"$THZMAP" bands "$IN/features.json" -o "$work/busy" --count 1 --from-thz 0.2 --to-thz 1.0 \
    --step-ghz 50 --paths 4 2> "$work/err"
st=$?
kill -TERM $busy
wait $busy 2>/dev/null
[ "$st" = 1 ] || fail "a busy OUTDIR: exit status $st, expected 1: $(cat "$work/err")"
grep -q "another thzmap run" "$work/err" || fail "a busy OUTDIR: $(cat "$work/err")"
grep -q "render 1" "$work/err" && fail "a busy OUTDIR refused only after the renders"
echo ok
