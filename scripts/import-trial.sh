#!/usr/bin/env bash
# The import trial (docs/src/evaluation/import-trial.md): public scenes,
# fetched outside the repository, rendered by photonmap's SPPM through the
# importers and compared with Mitsuba 3 (Mitsuba's Cornell box) and across
# formats (Bitterli's Cornell box in pbrt-v4 and in Mitsuba 3 XML). Two
# independent seeds of every render give each side's own noise.
#
#   scripts/import-trial.sh MITSUBA_SCENES BITTERLI_CORNELL PY WORK [OUT]
#
# MITSUBA_SCENES: mitsuba-tutorials' scenes/ (cbox.xml, meshes/);
# BITTERLI_CORNELL: a cornell-box/ folder with scene-v4.pbrt and
# mitsuba/scene_v3.xml; PY: a Python with `mitsuba`; WORK: where the EXRs go;
# OUT: the table and PNGs (default results/llvmpipe/import_trial).
# STAGES=compare skips the renders; STAGES=cbox6, cbox64 or bitterli renders
# only those.
set -euo pipefail
MI=$(realpath "$1"); BIT=$(realpath "$2"); PY=$3; WORK=$(realpath -m "$4")
OUT=$(realpath -m "${5:-results/llvmpipe/import_trial}")
PM=$(realpath "${PHOTONMAP:-target/release/photonmap}")
HERE=$(realpath "$(dirname "$0")")
ITER=${ITER:-256}; BIT_ITER=${BIT_ITER:-$ITER}; MI_SPP_6=${MI_SPP_6:-512}; MI_SPP_64=${MI_SPP_64:-256}; RES=256
mkdir -p "$WORK" "$OUT"

render() { # NAME DIR SCENE ITERATIONS [-D ...]
    local name=$1 dir=$2 scene=$3 iter=$4; shift 4
    for s in 1 2; do
        (cd "$dir" && nice -n 10 "$PM" render "$scene" --method sppm --iterations "$iter" \
            --width $RES --height $RES --seed $s "$@" --quiet --exr "$WORK/${name}_seed$s.exr")
    done
}
mitsuba() { # DEPTH SPP
    for s in 1 2; do
        (cd "$MI" && nice -n 10 "$PY" "$HERE/mitsuba-render.py" scalar_rgb cbox.xml "$2" $s \
            "$WORK/mitsuba_d$1_seed$s.exr" res=$RES max_depth=$1)
    done
}
# Mitsuba's cbox.xml at its own max_depth (6) and at 64, where neither
# renderer's truncation matters.
STAGES=${STAGES:-all}
for d in 6 64; do
    if [ "$STAGES" = all ] || [ "$STAGES" = "cbox$d" ]; then
        spp=MI_SPP_$d; mitsuba $d "${!spp}"
        render sppm_d$d "$MI" cbox.xml "$ITER" -D max_depth=$d
    fi
done
if [ "$STAGES" = all ] || [ "$STAGES" = bitterli ]; then
    render pbrt "$BIT" scene-v4.pbrt "$BIT_ITER"
    render xml "$BIT" mitsuba/scene_v3.xml "$BIT_ITER"
fi

# rel RMSE and energy of A against B, by photonmap compare.
cmp() { "$PM" compare "$WORK/$1.exr" "$WORK/$2.exr" --json 2>/dev/null |
    python3 -c 'import json,sys; j=json.load(sys.stdin); print(j["rel_rmse"], j["energy"])'; }
row() { # LABEL A B: crossed seeds against each side's seed-to-seed noise
    local x1 x2 e na nb ea eb
    # Seeds crossed (1 against 2, 2 against 1): photonmap's renders of one
    # seed share their random numbers, so they are not independent.
    read -r x1 e < <(cmp "$2_seed1" "$3_seed2"); read -r x2 _ < <(cmp "$2_seed2" "$3_seed1")
    read -r na ea < <(cmp "$2_seed2" "$2_seed1"); read -r nb eb < <(cmp "$3_seed2" "$3_seed1")
    python3 - "$1" "$x1" "$x2" "$e" "$na" "$nb" "$ea" "$eb" <<'PY'
import math, sys
label, x1, x2, e, na, nb, ea, eb = sys.argv[1], *map(float, sys.argv[2:])
d = math.sqrt((x1 * x1 + x2 * x2) / 2)         # one run of A against one of B
sa, sb = na / math.sqrt(2), nb / math.sqrt(2)  # one run's own noise
expect = math.hypot(sa, sb)                    # what d would be with no bias
print(f"| {label} | {d:.4f} | {sa:.4f} | {sb:.4f} | {expect:.4f} | {d / expect:.2f} "
      f"| {e:.4f} | {abs(ea - 1) / math.sqrt(2):.4f}, {abs(eb - 1) / math.sqrt(2):.4f} |")
PY
}
{
    echo "\`ITER=$ITER BIT_ITER=$BIT_ITER MI_SPP_6=$MI_SPP_6 MI_SPP_64=$MI_SPP_64 scripts/import-trial.sh MITSUBA_SCENES BITTERLI_CORNELL PY WORK\`: per seed S in 1, 2 and D in 6, 64: \`photonmap render cbox.xml --method sppm --iterations $ITER --width $RES --height $RES --seed S -D max_depth=D --exr sppm_dD_seedS.exr\`, \`python scripts/mitsuba-render.py scalar_rgb cbox.xml MI_SPP_D S mitsuba_dD_seedS.exr res=$RES max_depth=D\`; \`photonmap render scene-v4.pbrt --method sppm --iterations $BIT_ITER --width $RES --height $RES --seed S --exr pbrt_seedS.exr\` (likewise \`mitsuba/scene_v3.xml\` to xml_seedS); then \`photonmap compare A B --json\` for every pair"
    echo
    echo "$RES x $RES, all pixels; one run of A against an independent one of B (rms over A's seed 1 against B's seed 2 and A's 2 against B's 1), each side's own noise (seed 2 against seed 1, over sqrt 2), the difference that noise alone gives (their root sum of squares), and the ratio; energy: A's mean over B's (A's seed 1, B's seed 2), with each side's seed-to-seed energy spread."
    echo
    echo "| A against B | rel RMSE | noise A | noise B | noise alone | ratio | energy | energy noise A, B |"
    echo "|---|---|---|---|---|---|---|---|"
    row "Mitsuba's cbox.xml, max_depth 6 (the file's): photonmap SPPM ($ITER it.) against Mitsuba 3 path ($MI_SPP_6 spp)" sppm_d6 mitsuba_d6
    row "Mitsuba's cbox.xml, max_depth 64: photonmap SPPM ($ITER it.) against Mitsuba 3 path ($MI_SPP_64 spp)" sppm_d64 mitsuba_d64
    row "Bitterli's Cornell box, photonmap SPPM ($BIT_ITER it.): pbrt-v4 against Mitsuba 3 XML" pbrt xml
    read -r same esame < <(cmp pbrt_seed1 xml_seed1)
    echo
    echo "The same seed (1) of both, sharing their random numbers: rel RMSE $(printf %.4f "$same"), energy $(printf %.4f "$esame")."
} > "$OUT/table.md"
for f in sppm_d64 mitsuba_d64 pbrt xml; do "$PM" convert "$WORK/${f}_seed1.exr" "$OUT/$f.png" >/dev/null; done
cat "$OUT/table.md"
