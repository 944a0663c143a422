#!/usr/bin/env bash
# What each of VCM's techniques carries: renders SCENE with --method vcm at
# its defaults for SECONDS at WIDTH x HEIGHT, writes the image and each
# technique's image (--vcm-techniques) as PNG into OUT, and OUT/shares.md:
# each technique's share of the image's light (`photonmap compare`'s energy
# of the technique against the image), headed by this command.
#
# Usage: scripts/vcm-techniques.sh SCENE SECONDS WIDTH HEIGHT OUT
set -euo pipefail
if [ $# -ne 5 ]; then
  sed -n 2,8p "$0" >&2
  exit 2
fi
scene=$1 seconds=$2 width=$3 height=$4 out=$5
bin=${PHOTONMAP:-target/release/photonmap}
[ -x "$bin" ] || { echo "no $bin: cargo build --release first" >&2; exit 1; }
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$bin" render "$scene" --method vcm --time "$seconds" --width "$width" --height "$height" \
  -o "$work/image.exr" --vcm-techniques "$work" --quiet
"$bin" convert "$work/image.exr" "$out/image.png" >/dev/null
{
  echo "\`$0 $*\`"
  echo
  echo "Each technique's share of the image's light (its mean over the image's), at the defaults; llvmpipe."
  echo
  echo "| technique | share |"
  echo "|---|---|"
  for t in lights_hit next_event_estimation connections merging light_tracing; do
    "$bin" convert "$work/$t.exr" "$out/$t.png" >/dev/null
    share=$("$bin" compare "$work/$t.exr" "$work/image.exr" --json |
      python3 -c 'import json, sys; c = json.load(sys.stdin); print("%.3f" % c.get("metrics", c)["energy"])')
    echo "| ${t//_/ } | $share |"
  done
} > "$out/shares.md"
echo "wrote $out" >&2
