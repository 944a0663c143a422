#!/usr/bin/env bash
# Which of Bitterli's pbrt-v4 scenes photonmap reads strictly (no
# --lenient): `convert-scene` on every <scene>/pbrt/scene-v4.pbrt, and the
# first thing refused where one is. Writes a Markdown table headed by its
# command.
#
#   scripts/bitterli-strict.sh BITTERLI OUT.md
#
# BITTERLI: a checkout of Bitterli's scenes in pbrt-v4 form (gonsolo/bitterli),
# its large meshes included where they are in the checkout; a scene whose
# mesh is missing reads "files incomplete".
set -euo pipefail
BIT=$(realpath "$1"); OUT=$2
PM=$(realpath "${PHOTONMAP:-target/release/photonmap}")
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
{
    echo "\`scripts/bitterli-strict.sh BITTERLI OUT.md\`: \`photonmap convert-scene scene-v4.pbrt OUT.toml\` in each \`<scene>/pbrt/\` of Bitterli's scenes (gonsolo/bitterli)."
    echo
    echo "| scene | read strictly | first refusal |"
    echo "|---|---|---|"
    read_ok=0; complete=0
    for f in "$BIT"/*/pbrt/scene-v4.pbrt; do
        scene=$(basename "$(dirname "$(dirname "$f")")")
        said=$(cd "$(dirname "$f")" && "$PM" convert-scene scene-v4.pbrt "$WORK/$scene.toml" 2>&1 | grep -v '^\[' | tail -1 || true)
        if [ -z "$said" ] || [ -f "$WORK/$scene.toml" ]; then
            echo "| $scene | yes | |"; read_ok=$((read_ok + 1)); complete=$((complete + 1))
        elif echo "$said" | grep -q "No such file"; then
            echo "| $scene | files incomplete | |"
        else
            complete=$((complete + 1))
            echo "| $scene | no | $(echo "$said" | sed 's/^error: //; s/|/\\|/g') |"
        fi
    done
    echo
    echo "$read_ok of the $complete scenes whose files are complete are read strictly."
} > "$OUT"
