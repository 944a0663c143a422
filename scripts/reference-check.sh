#!/usr/bin/env bash
# How far an SPPM reference is from an independent one: photonmap compare
# on a mask, the independent reference's own noise taken out.
#
#   scripts/reference-check.sh SPPM.exr MITSUBA_DIR MASK.png OUT.md
#
# SPPM.exr: a `photonmap reference` image (its JSON beside it gives its own
# remaining noise); MITSUBA_DIR: a `bench mitsuba --mitsuba-reference` folder
# (reference.exr, and mitsuba.json with its noise, truth_noise); MASK.png:
# the pixels compared. Writes OUT.md: the command, then a table. With d the
# relative RMSE between the two references and n the independent one's
# noise, both over the mask, the SPPM reference's own error (its noise and
# bias together) is sqrt(d^2 - n^2) when the two are independent, and at
# most d + n whatever they share.
set -euo pipefail
SPPM=$1; MI=$2; MASK=$3; OUT=$4
PM=${PHOTONMAP:-target/release/photonmap}
json=$("$PM" compare "$SPPM" "$MI/reference.exr" --mask "$MASK" --json)
python3 - "$SPPM" "$MI" "$MASK" "$OUT" "$json" <<'PY'
import json, math, os, sys
sppm, mi, mask, out, compared = sys.argv[1:6]
c = json.loads(compared)
m = json.load(open(os.path.join(mi, "mitsuba.json")))
s = json.load(open(sppm[:-len(".exr")] + ".json"))
d, n = c["rel_rmse"], m["truth_noise"]
own = math.sqrt(max(d * d - n * n, 0.0))
cmd = " ".join(["scripts/reference-check.sh"] + sys.argv[1:5])
with open(out, "w") as f:
    f.write(f"`{cmd}`\n\n")
    f.write(f"{c['pixels_compared']} pixels of {mask}; the SPPM reference: `{s['command']}`.\n\n")
    f.write("| SPPM reference against Mitsuba's | rel RMSE d | energy | Mitsuba reference's noise n "
            "| SPPM reference's own noise (its halves, all pixels) | its error, sqrt(d^2 - n^2) | its error at most, d + n |\n")
    f.write("|---|---|---|---|---|---|---|\n")
    f.write(f"| {os.path.basename(sppm)} | {d:.4f} | {c['energy']:.4f} | {n:.4f} "
            f"| {s['residual_noise_rmse']:.4f} | {own:.4f} | {d + n:.4f} |\n")
print(open(out).read())
PY
