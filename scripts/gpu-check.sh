#!/usr/bin/env bash
# A quick check of photonmap on a machine with an NVIDIA GPU (about two
# minutes there; under five with the per-run limit): the GL platform and its
# limits, the three paper scenes at their defaults, and each by SPPM for ten
# seconds. It builds nothing: build first with `cargo build --release`.
#
# Usage: scripts/gpu-check.sh [OUT]     (OUT default: results/gpu-check)
#
# Writes OUT/info.json, OUT/<scene>.exr and .json (the paper's method),
# OUT/<scene>.sppm.exr and .sppm.json (SPPM), each run's stderr as .log, and
# OUT/summary.txt, one line a run (also printed).
#
# Environment:
#   PHOTONMAP       the binary (default: ./target/release/photonmap of the repository)
#   PLATFORM        --platform of every run (default: egl-device; egl-surfaceless
#                   or osmesa to try it on llvmpipe)
#   EXTRA           extra render arguments, word-split (e.g. "--width 64 --height 48")
#   RUN_TIMEOUT     seconds each run may take before it is stopped (default: 45)
#   ALLOW_SOFTWARE  1: go on when the renderer is a software one (llvmpipe,
#                   softpipe, swrast); by default that is an error, as on a GPU
#                   machine it means the GPU was not used
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
out="${1:-$root/results/gpu-check}"
photonmap="${PHOTONMAP:-$root/target/release/photonmap}"
platform="${PLATFORM:-egl-device}"
run_timeout="${RUN_TIMEOUT:-45}"
read -r -a extra <<<"${EXTRA:-}"
scenes=(glass_ball ring cornell_box)

if [[ ! -x "$photonmap" ]]; then
    echo "gpu-check: no photonmap binary at $photonmap" >&2
    echo "gpu-check: build it first (cargo build --release) or set PHOTONMAP=/path/to/photonmap" >&2
    exit 1
fi
for s in "${scenes[@]}"; do
    if [[ ! -f "$root/scenes/$s.toml" ]]; then
        echo "gpu-check: missing scene $root/scenes/$s.toml" >&2
        exit 1
    fi
done
mkdir -p "$out"
summary="$out/summary.txt"
: >"$summary"

limited() {
    if command -v timeout >/dev/null; then
        timeout "$run_timeout" "$@"
    else
        "$@"
    fi
}

# One line from a run's JSON: wall seconds and, for SPPM, the iterations.
summarise() {
    local name="$1" json="$2"
    if command -v python3 >/dev/null; then
        python3 - "$name" "$json" <<'PY'
import json, sys
name, path = sys.argv[1], sys.argv[2]
d = json.load(open(path))
p = d.get("provenance", {})
line = f"{name:<22} {d.get('method', '?'):<6} {p.get('width', '?')}x{p.get('height', '?')}"
line += f"  wall {d['timings']['wall_seconds']:8.3f} s"
if d.get("method") == "sppm":
    line += f"  iterations {d.get('iterations')}  photons {d.get('photons_emitted')}"
line += f"  [{p.get('renderer', '?')}]"
print(line)
PY
    elif command -v jq >/dev/null; then
        jq -r --arg n "$name" '"\($n)  \(.method)  \(.provenance.width)x\(.provenance.height)  wall \(.timings.wall_seconds) s"
            + (if .method == "sppm" then "  iterations \(.iterations)  photons \(.photons_emitted)" else "" end)
            + "  [\(.provenance.renderer)]"' "$json"
    else
        echo "$name  (no python3 or jq to read $json)"
    fi
}

failed=()
# run NAME ARGS...: a render, its JSON to OUT/NAME.json and stderr to OUT/NAME.log.
run() {
    local name="$1"
    shift
    local json="$out/$name.json" log="$out/$name.log"
    if limited "$photonmap" render "$@" --platform "$platform" --json ${extra[@]+"${extra[@]}"} >"$json" 2>"$log"; then
        { summarise "$name" "$json" || echo "$name  done, but $json could not be read"; } | tee -a "$summary"
    else
        local rc=$?
        echo "$name  FAILED (exit $rc$([[ $rc == 124 ]] && echo ", over ${run_timeout} s")); see $log" | tee -a "$summary"
        tail -n 5 "$log" >&2 || true
        failed+=("$name")
    fi
}

echo "gpu-check: $photonmap, --platform $platform, into $out"
if ! limited "$photonmap" info --platform "$platform" --json >"$out/info.json" 2>"$out/info.log"; then
    echo "gpu-check: photonmap info --platform $platform failed:" >&2
    cat "$out/info.log" >&2
    exit 1
fi
renderer="$(python3 -c 'import json,sys; print(json.load(open(sys.argv[1]))["gl_renderer"])' "$out/info.json" 2>/dev/null ||
    sed -n 's/.*"gl_renderer": *"\([^"]*\)".*/\1/p' "$out/info.json")"
echo "info: $renderer" | tee -a "$summary"
if [[ "$renderer" =~ llvmpipe|softpipe|swrast|[Ss]oftware ]] && [[ "${ALLOW_SOFTWARE:-0}" != 1 ]]; then
    echo "gpu-check: the renderer is a software one ($renderer), not a GPU; set ALLOW_SOFTWARE=1 to go on anyway" >&2
    exit 1
fi

for s in "${scenes[@]}"; do
    run "$s" "$root/scenes/$s.toml" -o "$out/$s.exr"
done
for s in "${scenes[@]}"; do
    run "$s.sppm" "$root/scenes/$s.toml" --method sppm --time 10 -o "$out/$s.sppm.exr"
done

if ((${#failed[@]})); then
    echo "gpu-check: ${#failed[@]} run(s) failed: ${failed[*]}" >&2
    exit 1
fi
echo "gpu-check: all runs done; summary in $summary"
