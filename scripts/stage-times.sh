#!/usr/bin/env bash
# Where an SPPM iteration at its defaults spends its time, by stage, for
# each scene at its own size, once for each photon-map build and each
# binary. Each figure is the difference between LONG and SHORT iterations'
# times, over LONG - SHORT (so start-up and shader compilation drop out),
# each time the stage's least over REPS runs of that length; wall clock
# between glFinish calls. Writes a markdown table, headed by this command, to OUT.
#
# Usage: [BINARIES="LABEL=PATH ..."] [SCENES="glass_ball ..."] \
#        scripts/stage-times.sh OUT [SHORT LONG REPS [BUILD ...]]
# (defaults: 8 40 3 counting; BINARIES: this tree's target/release/photonmap;
# SCENES: the three paper scenes, names or scene files). BINARIES compares
# builds of two commits, one column each. Run it on a quiet machine from
# the repository root: a build or another render at the same time slows it.
set -euo pipefail
if [ $# -lt 1 ]; then
  sed -n 2,14p "$0" >&2
  exit 2
fi
out=$1
short=${2:-8}
long=${3:-40}
reps=${4:-3}
shift $(( $# < 4 ? $# : 4 ))
builds=("$@")
[ ${#builds[@]} -gt 0 ] || builds=(counting)
read -r -a binaries <<< "${BINARIES:-this=${PHOTONMAP:-target/release/photonmap}}"
read -r -a scenes <<< "${SCENES:-glass_ball cornell_box ring}"
for b in "${binaries[@]}"; do
  [ -x "${b#*=}" ] || { echo "no ${b#*=}: cargo build --release first" >&2; exit 1; }
done
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
columns=()
for scene in "${scenes[@]}"; do
  tag=$(basename "$scene" .toml)
  for bin in "${binaries[@]}"; do
    for build in "${builds[@]}"; do
      col="$tag|${bin%%=*}|$build"
      columns+=("$col")
      for rep in $(seq "$reps"); do
        for n in "$short" "$long"; do
          echo "$tag, ${bin%%=*}, --build $build, $n iterations (run $rep of $reps)" >&2
          "${bin#*=}" render "$scene" --method sppm --iterations "$n" --build "$build" \
            --json --quiet --exr "$work/image.exr" > "$work/$(echo "$col" | tr '|' '_')_${rep}_${n}.json"
        done
      done
    done
  done
done
python3 - "$work" "$out" "$short" "$long" "$reps" "$out $short $long $reps ${builds[*]}" \
  "${#binaries[@]}" "${#builds[@]}" "${BINARIES:-}" "${SCENES:-}" "${columns[@]}" <<'PYEOF'
import json, sys
work, out, short, long, reps, args, nbin, nbuild, binaries, scenes = sys.argv[1:11]
columns = sys.argv[11:]
short, long, reps = int(short), int(long), int(reps)
def stages(path):
    t = json.load(open(path))["timings"]
    return {s["name"]: s["wall_seconds"] for s in t["stages"]}
per, names = {}, []
for col in columns:
    # Each stage's least over the runs of each length, then their
    # difference: the least of the differences would pick the pair whose
    # short run the machine slowed, and can read below zero.
    least = {}
    for n in (short, long):
        for rep in range(1, reps + 1):
            for k, v in stages(f"{work}/{col.replace('|', '_')}_{rep}_{n}.json").items():
                least[(n, k)] = min(least.get((n, k), v), v)
                if k not in names:
                    names.append(k)
    diff = {k: (least.get((long, k), 0.0) - least.get((short, k), 0.0)) / (long - short) * 1e3
            for k in names if (long, k) in least}
    per[col] = (diff, sum(diff.values()))
def heading(col):
    scene, binary, build = col.split("|")
    parts = [binary] if int(nbin) > 1 else []
    parts += [build] if int(nbuild) > 1 else []
    return f"{scene} ({', '.join(parts)})" if parts else scene
env = (f'BINARIES="{binaries}" ' if binaries else "") + (f'SCENES="{scenes}" ' if scenes else "")
lines = [f"`{env}scripts/stage-times.sh {args}`", "",
         f"Milliseconds an SPPM iteration at the defaults, by stage: runs of {long} and {short} "
         f"iterations differenced, each the least of {reps} (wall clock between glFinish calls).", "",
         "| stage | " + " | ".join(heading(c) for c in columns) + " |",
         "|---|" + "---|" * len(columns)]
for name in names:
    lines.append(f"| {name} | " + " | ".join(f"{per[c][0].get(name, 0.0):.1f}" for c in columns) + " |")
lines.append("| **total** | " + " | ".join(f"**{per[c][1]:.1f}**" for c in columns) + " |")
open(out, "w").write("\n".join(lines) + "\n")
print("\n".join(lines))
PYEOF
