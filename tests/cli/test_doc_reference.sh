#!/usr/bin/env bash
# docs/scene-format.md, the reference outside programs read, against the program:
# - each command's section lists every long option its --help describes, and every
#   option of the section's table is one --help describes; --seed's states its range;
# - "Outputs": a run of a sensor with a PSF and noise writes exactly the files the table
#   names (S the sensor), and each ENVI header's `data units` is the table's unit;
# - "summary.json": every key a run writes (path with two sensors, of an Airy and a
#   Gaussian PSF and of radiometer and NETD noise; final-gather with a photon phase) is
#   named in that section, and every snake_case key the section names is one a run
#   writes; an object no sensor sees has pixels 0 and null figures;
# - "Sequences": every key of batch.json and frame.json is named in its Outputs;
# - "An example" is examples/plate-in-box/scene.json.
# (The photon-map PLY's properties were documented in another order than the file's:
# tests/unit/test_ply.c checks the file's.)
# argv: path to the thzmap binary, repository directory.
. "$(dirname "$0")/lib.sh"
doc=$REPO/docs/scene-format.md

# section TITLE: the lines of $doc after the heading line that begins with TITLE, up to
# the next heading of that level or above
section() {
    awk -v t="$1" 'BEGIN { n = index(t, " ") - 1 }
        on && /^#+ / && index($0, " ") - 1 <= n { on = 0 }
        index($0, t) == 1 { on = 1; next }
        on' "$doc"
}

for cmd in simulate render batch atmosphere materials bands classify serve; do
    "$THZMAP" $cmd --help >"$work/$cmd.help" || fail "$cmd --help: exit $?"
    section "### thzmap $cmd" >"$work/$cmd.sec"
    [ -s "$work/$cmd.sec" ] || { fail "scene-format.md has no section '### thzmap $cmd'"; continue; }
    for o in $(grep -oE -- '--[a-z][a-z0-9-]*' "$work/$cmd.help" | sort -u); do
        [ "$o" = --help ] && continue
        grep -q -- "$o\b" "$work/$cmd.sec" || fail "scene-format.md's thzmap $cmd lacks $o"
    done
    for o in $(grep -E '^\| `' "$work/$cmd.sec" | cut -d'|' -f2 |
        grep -oE -- '--[a-z][a-z0-9-]*' | sort -u); do
        grep -q -- "$o\b" "$work/$cmd.help" ||
            fail "scene-format.md's thzmap $cmd lists $o, which '$cmd --help' does not"
    done
done
# --seed's range, which the docs' tables and the error for a seed out of it state, is in
# --help too (it was not: "random seed (overrides photons.seed)")
for cmd in simulate bands classify; do
    awk '/^  --seed / { on = 1; print; next } on && /^  -/ { exit } on' "$work/$cmd.help" |
        tr -s ' \n' ' ' | grep -qF "0 to 2^63 - 1" ||
        fail "$cmd --help: --seed does not state its range, 0 to 2^63 - 1"
done

cat >"$work/scene.json" <<JSON
{"format": "thzmap-scene/1.1", "name": "doc",
 "channels": [{"frequency_thz": 0.35, "relative_width": 0.02}],
$(plate_in_room)
 "sensors": [{"name": "cam", "position_m": [0, -0.9, 0], "look_at_m": [0, 0, 0],
   "fov_deg": 40, "resolution": [8, 6], "aperture_diameter_m": 0.1,
   "noise": {"receiver_temperature_k": 1000, "integration_time_s": 0.01,
             "radiometer": "dicke"}},
  {"name": "cam2", "position_m": [0, -0.9, 0],
   "fov_deg": 40, "resolution": [4, 3], "psf": "gaussian", "psf_fwhm_deg": 5,
   "direction": [0, -1, 0],
   "noise": {"netd_k": 0.5}}],
 "render": {"paths_per_sample": 2},
 "photons": {"per_channel": 20000}}
JSON
"$THZMAP" simulate "$work/scene.json" -o "$work/path" -q --threads 1 ||
    fail "simulate (path): exit $?"
"$THZMAP" simulate "$work/scene.json" -o "$work/fg" -q --threads 1 --integrator final-gather ||
    fail "simulate (final-gather): exit $?"
# cam2 looks away from the plate: rendered alone, the plate is an object not seen
"$THZMAP" render "$work/scene.json" -o "$work/away" -q --threads 1 --sensor cam2 ||
    fail "render --sensor cam2: exit $?"

# a batch of 2 sweep values x 2 frames of cam alone (path), for batch.json and frame.json
/usr/bin/python3 - "$work" <<'PY'
import json, sys
w = sys.argv[1]
s = json.load(open(f"{w}/scene.json"))
s["sensors"] = s["sensors"][:1]
json.dump(s, open(f"{w}/one.json", "w"))
json.dump({"format": "thzmap-sequence/1", "scene": "one.json", "fps": 2, "frames": 2,
           "sweep": {"objects.plate.temperature_k": [305, 315]}}, open(f"{w}/seq.json", "w"))
PY
"$THZMAP" batch "$work/seq.json" -o "$work/batch" -q --threads 1 || fail "batch: exit $?"

section "## Outputs" >"$work/outputs.sec"
awk '/^\*\*Outputs\*\* in OUTDIR/ { on = 1 } /^\*\*Resuming\.\*\*/ { on = 0 } on' "$doc" \
    >"$work/batch.sec"
section "### summary.json" >"$work/summary.sec"
REPO=$REPO /usr/bin/python3 - "$work" <<'PY' || fail "the program and scene-format.md differ (above)"
import json, os, re, sys

work = sys.argv[1]
ok = True


def bad(msg):
    global ok
    ok = False
    print("FAIL:", msg)


# The outputs table: | `S.x.hdr/.img` | bands | unit (`data units`) | content |
rows = [l for l in open(os.path.join(work, "outputs.sec")) if re.match(r"\| `S[.]", l)]
if len(rows) < 10:
    bad(f"only {len(rows)} rows in the outputs table")
ascii_unit = {"W·m⁻²·sr⁻¹·Hz⁻¹": "W m-2 sr-1 Hz-1", "W": "W", "K": "K", "1": "1", "m": "m"}
documented = set()
for row in rows:
    cells = [c.strip() for c in row.strip().strip("|").split("|")]
    name = re.match(r"`S(\.[^`]*)`", cells[0]).group(1).replace("NN", "01")
    unit = re.sub(r"\s*\(.*\)$", "", cells[2])
    if name.endswith(".hdr/.img"):
        stem = "cam" + name[: -len(".hdr/.img")]
        documented |= {stem + ".hdr", stem + ".img"}
        hdr = os.path.join(work, "path", stem + ".hdr")
        if os.path.exists(hdr):
            m = re.search(r"^data units = (.*)$", open(hdr).read(), re.M)
            want = ascii_unit.get(unit)
            if not m or m.group(1) != want:
                bad(f"{stem}.hdr: data units {m and m.group(1)!r}, the table says {unit!r}")
    else:
        documented.add("cam" + name)
written = {f for f in os.listdir(os.path.join(work, "path")) if f.startswith("cam.")}
for f in sorted(written - documented):
    bad(f"the run wrote {f}, which the outputs table does not name")
for f in sorted(documented - written):
    bad(f"the outputs table names {f}, which a run of a sensor with a PSF and noise did not write")

# summary.json: every key written is named in the section, and every snake_case key
# named there is written by one of the runs.
text = open(os.path.join(work, "summary.sec")).read()
named = set(re.findall(r"[`{,]\s*([a-z][a-z0-9_]*)", text)) | set(
    re.findall(r"\.([a-z][a-z0-9_]*)", text))
keys = set()


def walk(v):
    if isinstance(v, dict):
        for k, x in v.items():
            keys.add(k)
            walk(x)
    elif isinstance(v, list):
        for x in v:
            walk(x)


for run in ("path", "fg", "away"):
    walk(json.load(open(os.path.join(work, run, "summary.json"))))
for k in sorted(keys - named):
    bad(f"summary.json has the key {k}, which scene-format.md's summary.json section does not name")
for k in sorted(k for k in named - keys if "_" in k and re.search(r"`" + k + r"`", text)):
    bad(f"scene-format.md's summary.json section names `{k}`, which no run wrote")
# batch.json and frame.json: every key is named in the sequences' Outputs paragraph (the
# frame's scene and the sweep values' dotted keys aside)
text = open(os.path.join(work, "batch.sec")).read()
named = set(re.findall(r'`"?([a-z][a-z0-9_]*)(?:`|": )', text))
for name in ("batch.json", "sweep-01/frame-00001/frame.json"):
    path = os.path.join(work, "batch", name)
    if not os.path.exists(path):
        bad(f"the batch wrote no {name}")
        continue
    keys = set()
    top = json.load(open(path))
    if name.endswith("frame.json"):
        top["scene"] = None  # the frame's scene, as a scene file holds it
    for sw in top.get("sweeps", []):
        sw.pop("values", None)
    top.pop("sweep_values", None)
    walk(top)
    for k in sorted(keys - named):
        bad(f"{name} has the key {k}, which scene-format.md's sequence Outputs do not name")

# "An example" is examples/plate-in-box/scene.json, as JSON
doc = open(os.path.join(os.environ["REPO"], "docs", "scene-format.md")).read()
block = re.search(r"## An example\n.*?```json\n(.*?)```", doc, re.S)
shipped = json.load(open(os.path.join(os.environ["REPO"], "examples/plate-in-box/scene.json")))
if not block or json.loads(block.group(1)) != shipped:
    bad("scene-format.md's example is not examples/plate-in-box/scene.json")

# "pixels 0 and both figures null where the object is not seen"
s = json.load(open(os.path.join(work, "away", "summary.json")))
if s["command"] != "render":
    bad(f"render's summary.json says command {s['command']!r}")
plate = [o for o in s["channels"][0]["objects"] if o["name"] == "plate"]
if plate != [{"name": "plate", "pixels": 0, "median_stderr_k": None, "p95_stderr_k": None,
              "starved_pixels": 0}]:
    bad(f"an object not seen: {plate}, expected pixels 0 and null figures")
sys.exit(0 if ok else 1)
PY

finish "doc reference: all checks passed"
