#!/usr/bin/env bash
# SPPM's (or with METHOD=vcm, VCM's) defaults against their alternatives at
# equal wall time, on each
# scene's reference: each configuration renders for SECONDS at the
# reference's size, then `photonmap compare` measures relative RMSE and
# energy on the mask's pixels. Writes OUT/table.md (one row per
# configuration, one column per scene, headed by this command) and
# OUT/runs.jsonl (every run's figures), OUT/stages.md (where the defaults'
# iterations spend their time) and OUT/split.md (the defaults' error split
# into noise and bias by a second seed).
#
# Usage: [SPPM_CONFIGS=leak-grid | METHOD=vcm] scripts/sppm-defaults.sh SECONDS OUT SCENE:REFERENCE.exr[:MASK.png] ...
# (SCENE: a paper scene's name, or a scene file's path)
# Run it from the repository root on a quiet machine (a build or another
# render at the same time changes the iterations each run gets).
set -euo pipefail
if [ $# -lt 3 ]; then
  sed -n 2,12p "$0" >&2
  exit 2
fi
seconds=$1
out=$2
shift 2
bin=${PHOTONMAP:-target/release/photonmap}
[ -x "$bin" ] || { echo "no $bin: cargo build --release first" >&2; exit 1; }
mkdir -p "$out"
runs="$out/runs.jsonl"
if [ -z "${SPPM_TABLES_ONLY:-}" ]; then
  : > "$runs"
  : > "$out/split.jsonl"
fi

# label|arguments (the defaults first; their second seed splits the error).
# SPPM_CONFIGS=leak-grid compares the gather's leak test and the grid instead.
method=${METHOD:-sppm}
case $method in sppm|vcm) ;; *) echo "METHOD: sppm or vcm" >&2; exit 2 ;; esac
configs_of=${SPPM_CONFIGS:-defaults}
[ "$method" = vcm ] && configs_of=vcm
case $configs_of in
  defaults)
    configs=(
      "defaults|"
      "defaults, second seed|--seed 2"
      "no kNN bound on the start (--start-photons 0)|--start-photons 0"
      "kNN bound 8 (--start-photons 8)|--start-photons 8"
      "kNN bound 32 (--start-photons 32)|--start-photons 32"
      "alpha 0.6|--alpha 0.6"
      "alpha 0.8|--alpha 0.8"
      "32768 photons an iteration|--photons-per-iteration 32768"
      "2 shadow rays an iteration|--sppm-shadow-rays 2"
    ) ;;
  leak-grid)
    configs=(
      "defaults|"
      "defaults, second seed|--seed 2"
      "visibility leak test|--leak-test visibility"
      "disc leak test|--leak-test disc"
      "uniform grid|--grid uniform"
    ) ;;
  vcm)
    configs=(
      "defaults|"
      "defaults, second seed|--seed 2"
      "camera paths continue as light paths (--camera-continuation 1)|--camera-continuation 1"
      "--camera-continuation 0.3|--camera-continuation 0.3"
      "--camera-continuation 0.03|--camera-continuation 0.03"
      "first radius 2 pixel footprints|--merge-start-pixels 2"
      "first radius 4 pixel footprints|--merge-start-pixels 4"
      "merge alpha 0.6|--merge-alpha 0.6"
      "32768 light paths an iteration|--light-paths 32768"
      "2 connections a camera vertex|--connections 2"
    ) ;;
  *) echo "SPPM_CONFIGS: defaults or leak-grid" >&2; exit 2 ;;
esac

# SPPM_TABLES_ONLY=1: rebuild the tables from OUT's runs.jsonl and
# split.jsonl without rendering (the same arguments otherwise).
for spec in "$@"; do
  [ -n "${SPPM_TABLES_ONLY:-}" ] && break
  IFS=: read -r file reference mask <<< "$spec"
  case $file in */*) ;; *) file="scenes/$file.toml" ;; esac
  scene=$(basename "$file" .toml)
  size=$(python3 -c "
import struct, sys
f = open(sys.argv[1], 'rb'); f.read(8)
# the EXR header's dataWindow attribute: xmin ymin xmax ymax
data = f.read(4096); i = data.index(b'dataWindow\0box2i\0')
x0, y0, x1, y1 = struct.unpack('<4i', data[i + 21:i + 37])
print(x1 - x0 + 1, y1 - y0 + 1)" "$reference")
  read -r width height <<< "$size"
  for config in "${configs[@]}"; do
    label=${config%%|*}
    args=${config#*|}
    tag=$(echo "$label" | tr -c 'a-zA-Z0-9\n' '_')
    image="$out/${scene}_${tag}.exr"
    echo "$scene: $label" >&2
    # shellcheck disable=SC2086
    "$bin" render "$file" --method "$method" --time "$seconds" \
      --width "$width" --height "$height" $args -o "$image" --json --quiet > "$out/render.json"
    "$bin" compare "$image" "$reference" ${mask:+--mask "$mask"} --json > "$out/compare.json"
    python3 - "$scene" "$label" "$args" "$out/render.json" "$out/compare.json" >> "$runs" <<'EOF'
import json, sys
scene, label, args, render, compare = sys.argv[1:6]
r, c = json.load(open(render)), json.load(open(compare))
m = c.get("metrics", c)
stages = {s["name"]: s["wall_seconds"] for s in r["timings"]["stages"]}
print(json.dumps({"scene": scene, "config": label, "args": args,
                  "iterations": r["iterations"], "rel_rmse": m["rel_rmse"], "rmse": m["rmse"],
                  "energy": m["energy"], "stages": stages}))
EOF
    rm -f "$out/render.json" "$out/compare.json"
  done
  # The two seeds' difference is noise alone: their RMSE over sqrt(2) is one
  # run's noise, and what the error has beyond it is bias.
  "$bin" compare "$out/${scene}_defaults.exr" "$out/${scene}_defaults__second_seed.exr" \
    ${mask:+--mask "$mask"} --json > "$out/compare.json"
  python3 -c '
import json, sys
c = json.load(open(sys.argv[2]))
m = c.get("metrics", c)
print(json.dumps({"scene": sys.argv[1], "rmse_between_seeds": m["rmse"]}))' \
    "$scene" "$out/compare.json" >> "$out/split.jsonl"
  rm -f "$out/${scene}"_*.exr "$out/compare.json"
done

prefix=""
[ -n "${SPPM_CONFIGS:-}" ] && prefix="SPPM_CONFIGS=$SPPM_CONFIGS "
[ "$method" = vcm ] && prefix="METHOD=vcm "
python3 - "$runs" "$out" "$seconds" "$prefix$0 $seconds $out $*" <<'EOF'
import json, sys
runs, out, seconds, command = sys.argv[1:5]
rows = [json.loads(l) for l in open(runs)]
scenes = list(dict.fromkeys(r["scene"] for r in rows))
configs = list(dict.fromkeys(r["config"] for r in rows))
at = {(r["scene"], r["config"]): r for r in rows}


def table(caption, first, keys, cell):
    """The command, `caption`, then a row a key and a column a scene."""
    t = [f"`{command}`\n", caption,
         f"| {first} | " + " | ".join(scenes) + " |",
         "|---|" + "---|" * len(scenes)]
    for k in keys:
        t.append(f"| {k} | " + " | ".join(cell(s, k) for s in scenes) + " |")
    return t


def rmse_cell(s, c):
    r = at.get((s, c))
    return "-" if r is None else f"{r['rel_rmse']:.4f} ({r['energy']:.4f}; {r['iterations']})"


def stage_cell(s, n):
    r = at[(s, "defaults")]
    return f"{1000 * r['stages'].get(n, 0.0) / r['iterations']:.1f}"


t = table(f"Relative RMSE (energy; iterations) after {seconds} s at the reference's size, "
          "on its mask's pixels, one seed each; llvmpipe.\n", "configuration", configs, rmse_cell)
open(f"{out}/table.md", "w").write("\n".join(t) + "\n")
names = list(dict.fromkeys(n for r in rows for n in r["stages"]))
st = table("Milliseconds an iteration by stage, at the defaults (wall clock between glFinish calls).\n",
           "stage", names, stage_cell)
totals = [f"{1000 * sum(at[(s, 'defaults')]['stages'].values()) / at[(s, 'defaults')]['iterations']:.1f}"
          for s in scenes]
st.append("| **total** | " + " | ".join(f"**{x}**" for x in totals) + " |")
open(f"{out}/stages.md", "w").write("\n".join(st) + "\n")
# Bias and noise of one run at the defaults, relative to the reference's mean.
sp = [f"`{command}`\n",
      "One run at the defaults: relative RMSE (the two seeds' mean square), its noise "
      "(the RMSE between the seeds over sqrt 2) and its bias (the rest, which "
      "holds the reference's own noise too).\n",
      "| scene | relative RMSE | noise | bias |", "|---|---|---|---|"]
for l in open(f"{out}/split.jsonl"):
    d = json.loads(l)
    a, b = at[(d["scene"], "defaults")], at[(d["scene"], "defaults, second seed")]
    mse = (a["rel_rmse"] ** 2 + b["rel_rmse"] ** 2) / 2
    reference_mean = a["rmse"] / a["rel_rmse"]  # compare's rmse is absolute
    noise = d["rmse_between_seeds"] / 2 ** 0.5 / reference_mean
    # Where the noise estimate reaches the whole error, the bias is not
    # resolved: say so rather than print 0.
    bias = f"{(mse - noise ** 2) ** 0.5:.4f}" if mse > noise ** 2 else "below the noise"
    sp.append(f"| {d['scene']} | {mse ** 0.5:.4f} | {noise:.4f} | {bias} |")
open(f"{out}/split.md", "w").write("\n".join(sp) + "\n")
EOF
echo "wrote $out/table.md, $out/stages.md, $runs" >&2
