#!/usr/bin/env bash
# Where an SPPM iteration at its defaults spends its time, by stage, for
# each paper scene at its own size, once for each photon-map build. Each
# figure is the difference between a run of LONG and one of SHORT
# iterations, over LONG - SHORT (so start-up and shader compilation drop
# out), the least of REPS such differences; wall clock between glFinish
# calls. Writes a markdown table, headed by this command, to OUT.
#
# Usage: scripts/stage-times.sh OUT [SHORT LONG REPS [BUILD ...]]
# (default 8 40 3 bitonic counting). Run it on a quiet machine from the
# repository root: a build or another render at the same time slows it.
set -euo pipefail
if [ $# -lt 1 ]; then
  sed -n 2,11p "$0" >&2
  exit 2
fi
out=$1
short=${2:-8}
long=${3:-40}
reps=${4:-3}
shift $(( $# < 4 ? $# : 4 ))
builds=("$@")
[ ${#builds[@]} -gt 0 ] || builds=(bitonic counting)
bin=${PHOTONMAP:-target/release/photonmap}
[ -x "$bin" ] || { echo "no $bin: cargo build --release first" >&2; exit 1; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for scene in glass_ball cornell_box ring; do
  for build in "${builds[@]}"; do
    for rep in $(seq "$reps"); do
      for n in "$short" "$long"; do
        echo "$scene, --build $build, $n iterations (run $rep of $reps)" >&2
        "$bin" render "$scene" --method sppm --iterations "$n" --build "$build" \
          --json --quiet --exr "$work/image.exr" > "$work/${scene}_${build}_${rep}_${n}.json"
      done
    done
  done
done
python3 - "$work" "$out" "$short" "$long" "$reps" "${builds[@]}" <<'PYEOF'
import json, sys
work, out, short, long, reps = sys.argv[1:6]
builds = sys.argv[6:]
short, long, reps = int(short), int(long), int(reps)
scenes = ["glass_ball", "cornell_box", "ring"]
def stages(path):
    t = json.load(open(path))["timings"]
    return {s["name"]: s["wall_seconds"] for s in t["stages"]}, t["wall_seconds"]
per = {}
names = []
for scene in scenes:
    for build in builds:
        best = None
        for rep in range(1, reps + 1):
            (a, wa), (b, wb) = (stages(f"{work}/{scene}_{build}_{rep}_{n}.json") for n in (short, long))
            diff = {k: (b[k] - a.get(k, 0.0)) / (long - short) * 1e3 for k in b}
            total = sum(diff.values())
            for k in b:
                if k not in names:
                    names.append(k)
            if best is None or total < best[1]:
                best = (diff, total)
        per[(scene, build)] = best
cols = [(s, b) for s in scenes for b in builds]
lines = [f"`scripts/stage-times.sh {out} {short} {long} {reps} {' '.join(builds)}`", "",
         f"Milliseconds an SPPM iteration at the defaults, by stage: runs of {long} and {short} "
         f"iterations differenced, the least of {reps} (wall clock between glFinish calls).", "",
         "| stage | " + " | ".join(f"{s} ({b})" for s, b in cols) + " |",
         "|---|" + "---|" * len(cols)]
for name in names:
    lines.append(f"| {name} | " + " | ".join(f"{per[c][0].get(name, 0.0):.1f}" for c in cols) + " |")
lines.append("| **total** | " + " | ".join(f"**{per[c][1]:.1f}**" for c in cols) + " |")
open(out, "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PYEOF
