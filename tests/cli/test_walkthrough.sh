#!/usr/bin/env bash
# The newcomer walkthrough (docs/walkthrough.md) runs as written: its fenced blocks
# marked `file=NAME` are saved under NAME and those marked `run` are run by bash, in
# order, in an empty directory, with `thzmap` (the binary under test) and Debian's
# `python3` first on PATH; each block marked `text` (an output the page shows) must be
# lines the steps printed, as they printed them. Then the results are checked
# independently of the page's own script: every room pixel reads the room's 295 K and
# every person pixel the grey-plate value (1 - R) B(310 K) + R B(295 K), within 5 of the
# pixel's reported standard errors plus 0.02 K (the band-mean term of a 1 % channel, a
# few mK, and float32 rounding); and the page's script and its numpy-only reader must print the same numbers.
#   usage: test_walkthrough.sh THZMAP REPO
set -euo pipefail
thzmap=$(realpath "$1")
repo=$2
doc="$repo/docs/walkthrough.md"
py=/usr/bin/python3 # Debian's: python3-numpy and python3-spectral live there

"$py" -c 'import numpy, spectral' ||
    { echo "FAIL: $py lacks numpy or spectral (scripts/install-deps.sh)"; exit 1; }
[ -f "$doc" ] || { echo "FAIL: $doc is missing"; exit 1; }

tmp=$(mktemp -d "${TMPDIR:-/tmp}/thz-walkthrough-XXXXXX")
trap 'rm -rf "$tmp"' EXIT
mkdir "$tmp/bin" "$tmp/work"
ln -s "$thzmap" "$tmp/bin/thzmap"
ln -s "$py" "$tmp/bin/python3"

# Split the page into blocks: files to write and commands to run (in page order).
"$py" - "$doc" "$tmp" <<'PY'
import re
import sys

doc, tmp = sys.argv[1], sys.argv[2]
text = open(doc).read()
blocks = re.findall(r"^```([^\n]*)\n(.*?)^```", text, re.M | re.S)
n_files = n_runs = n_texts = 0
with open(f"{tmp}/steps.sh", "w") as steps:
    for info, body in blocks:
        words = info.split()
        files = [w[5:] for w in words if w.startswith("file=")]
        if files:
            open(f"{tmp}/work/{files[0]}", "w").write(body)
            n_files += 1
        elif "run" in words[1:]:
            n_runs += 1
            steps.write(f"echo '>>> step {n_runs}'\n{body}")
        elif words[:1] == ["text"]:  # what the page says a step prints
            n_texts += 1
            open(f"{tmp}/shown-{n_texts}.txt", "w").write(body)
if n_files < 3 or n_runs < 4:
    sys.exit(f"FAIL: {doc}: expected at least 3 file blocks and 4 run blocks, "
             f"found {n_files} and {n_runs} (are the fences still marked?)")
PY

cd "$tmp/work"
set +e
PATH="$tmp/bin:$PATH" bash -euo pipefail "$tmp/steps.sh" >"$tmp/stdout" 2>"$tmp/stderr"
rc=$?
set -e
if [ $rc -ne 0 ]; then
    echo "FAIL: the walkthrough's commands exited $rc"
    echo "--- stdout"; cat "$tmp/stdout"; echo "--- stderr"; cat "$tmp/stderr"
    exit 1
fi
cat "$tmp/stdout"

fail() { echo "FAIL: $*"; exit 1; }
# Each output the page shows (```text) is what a step printed, line for line: the run is
# deterministic (seed, paths per sample), so a changed message or figure is a stale page.
for shown in "$tmp"/shown-*.txt; do
    [ -e "$shown" ] || fail "the page shows no output (\`\`\`text) to compare"
    "$py" - "$shown" "$tmp/stdout" <<'PY' || exit 1
import sys
shown = open(sys.argv[1]).read().splitlines()
out = open(sys.argv[2]).read().splitlines()
if not any(out[i:i + len(shown)] == shown for i in range(len(out))):
    sys.exit("FAIL: the page shows\n" + "\n".join(shown) + "\nbut no step printed it; they printed\n"
             + "\n".join(out))
PY
done
grep -q 'scene "first-room" (room.json): valid' "$tmp/stdout" || fail "validate did not say the scene is valid"
grep -q 'typo.json: objects\[0\].temperature_c: unknown key' "$tmp/stderr" ||
    fail "the typo's message does not name objects[0].temperature_c"
grep -q '^exit status 2$' "$tmp/stdout" || fail "validate of the typo did not exit 2"
for q in brightness_temperature radiance radiance_stderr power normalized temperature \
    distance object_id; do
    for ext in hdr img; do
        [ -s "out/cam.$q.$ext" ] || fail "out/cam.$q.$ext is missing"
    done
done
for f in cam.visual.png cam.band-01.png cam.band-02.png cam.spectra.png summary.json; do
    [ -s "out/$f" ] || fail "out/$f is missing"
done

# Independent check of the images, and of what the page's scripts printed.
"$py" - "$tmp/stdout" <<'PY'
import re
import sys

import numpy as np

h, kb, c = 6.62607015e-34, 1.380649e-23, 299792458.0
planck = lambda f, t: 2 * h * f**3 / c**2 / np.expm1(h * f / (kb * t))
tb_of = lambda f, l: h * f / kb / np.log1p(2 * h * f**3 / (c**2 * l))
def dbdt(f, t):
    x = h * f / (kb * t)
    return planck(f, t) * x * np.exp(x) / np.expm1(x) / t

def read(stem):
    hdr = dict(l.split("=", 1) for l in open(stem + ".hdr") if "=" in l)
    hdr = {k.strip(): v.strip() for k, v in hdr.items()}
    shape = [int(hdr[k]) for k in ("bands", "lines", "samples")]
    assert hdr["data type"] == "4" and hdr["byte order"] == "0" and hdr["interleave"] == "bsq"
    return np.fromfile(stem + ".img", "<f4").reshape(shape).astype(float), hdr

tb, hdr = read("out/cam.brightness_temperature")
se, _ = read("out/cam.radiance_stderr")
ids, ids_hdr = read("out/cam.object_id")
ids = ids[0].astype(int)
assert hdr["data units"] == "K", hdr["data units"]
assert ids_hdr["object names"] == "{room, person}", ids_hdr["object names"]
freqs = np.array([0.4e12, 0.85e12])
r_person = np.interp(freqs * 1e-12, [0.25, 1.0], [0.4, 0.1])  # the page's skin table
n_room, n_person = (ids == 0).sum(), (ids == 1).sum()
assert n_room > 1000 and n_person > 100, (n_room, n_person)
assert (ids >= 0).all(), "a pixel of a closed room sees nothing"
means = []
for ch, f in enumerate(freqs):
    for k, expect_l in ((0, planck(f, 295.0)),
                        (1, (1 - r_person[ch]) * planck(f, 310.0) + r_person[ch] * planck(f, 295.0))):
        m = ids == k
        err_k = se[ch][m] / dbdt(f, tb[ch][m])
        dev = np.abs(tb[ch][m] - tb_of(f, expect_l))
        tol = 5 * err_k + 0.02
        worst = np.max(dev - tol)
        print(f"channel {ch}: object {k}: {m.sum()} pixels, expected {tb_of(f, expect_l):.3f} K, "
              f"largest deviation {dev.max():.4f} K, largest pixel error {err_k.max():.4f} K")
        if worst > 0:
            sys.exit(f"FAIL: channel {ch}, object {k}: a pixel is {dev.max():.4f} K off the "
                     f"closed form (tolerance 5 x its error + 0.02 K)")
        means.append((k, tb[ch][m].mean()))

# The page's script: per object "Tb = X K ± E K  expected Y K", within 5 E + 0.02 K,
# and its Tb the mean computed here.
out = open(sys.argv[1]).read()
rows = re.findall(r"^\s+(\w+)\s+(\d+) pixels\s+Tb =\s*([\d.]+) K ± ([\d.]+) K\s+expected\s+([\d.]+) K",
                  out, re.M)
if len(rows) != 4:
    sys.exit(f"FAIL: read_results.py printed {len(rows)} object lines, expected 4")
for (name, n, tbv, err, exp), (k, mean) in zip(rows, means):
    tbv, err, exp = float(tbv), float(err), float(exp)
    if name != ("room", "person")[k] or abs(tbv - mean) > 0.0015 or abs(tbv - exp) > 5 * err + 0.02:
        sys.exit(f"FAIL: read_results.py: {name}: Tb {tbv} ± {err} K, expected {exp} K "
                 f"(mean here {mean:.4f} K)")
plain = [float(v) for v in re.findall(r"^band \d: room mean Tb = ([\d.]+) K$", out, re.M)]
room_means = [mean for k, mean in means if k == 0]
if len(plain) != 2 or any(abs(a - b) > 0.0015 for a, b in zip(plain, room_means)):
    sys.exit(f"FAIL: read_plain.py printed {plain}, expected {room_means}")
print("walkthrough: OK")
PY
