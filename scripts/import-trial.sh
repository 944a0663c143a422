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
# mitsuba/scene_v3.xml; PY: a Python with `mitsuba` and numpy; WORK: where
# the EXRs go; OUT: the table and PNGs (default
# results/llvmpipe/import_trial). MI_VARIANT: Mitsuba's variant (default
# llvm_ad_rgb, which needs DRJIT_LIBLLVM_PATH naming libLLVM 16 or newer
# where the system's is older). STAGES=compare skips the renders; STAGES=mask,
# cbox6, cbox64 or bitterli renders only those.
set -euo pipefail
MI=$(realpath "$1"); BIT=$(realpath "$2"); PY=$3; WORK=$(realpath -m "$4")
OUT=$(realpath -m "${5:-results/llvmpipe/import_trial}")
PM=$(realpath "${PHOTONMAP:-target/release/photonmap}")
HERE=$(realpath "$(dirname "$0")")
ITER=${ITER:-256}; BIT_ITER=${BIT_ITER:-$ITER}; MI_SPP=${MI_SPP:-1024}; RES=256
VARIANT=${MI_VARIANT:-llvm_ad_rgb}
mkdir -p "$WORK" "$OUT"

render() { # NAME DIR SCENE ITERATIONS [FLAGS ...]
    local name=$1 dir=$2 scene=$3 iter=$4; shift 4
    for s in 1 2; do
        (cd "$dir" && nice -n 19 "$PM" render "$scene" --method sppm --iterations "$iter" \
            --width $RES --height $RES --seed $s "$@" --quiet --exr "$WORK/${name}_seed$s.exr")
    done
}
# Mitsuba renders the file with every film's filter a box of one pixel, as
# photonmap's; --black-emitters also makes the emitting shapes' BSDF black.
mitsuba() { # NAME DEPTH [--black-emitters]
    for s in 1 2; do
        (cd "$MI" && nice -n 19 "$PY" "$HERE/mitsuba-render.py" "$VARIANT" cbox.xml "$MI_SPP" $s \
            "$WORK/$1_seed$s.exr" ${3:-} res=$RES max_depth=$2)
    done
}
STAGES=${STAGES:-all}
stage() { [ "$STAGES" = all ] || [ "$STAGES" = "$1" ]; }
# The interior: pixels whose 4 x 4 sub-pixel rays all first hit one diffuse,
# non-emitting plane (no edges, light, spheres); the edges: those whose rays
# all hit diffuse, non-emitting surfaces, but not one plane.
if stage mask; then
    (cd "$MI" && nice -n 19 "$PY" "$HERE/mitsuba-render.py" "$VARIANT" cbox.xml --mask "$WORK/interior.png" \
        --edges "$WORK/edges.png" res=$RES) |
        tee "$WORK/interior.txt"
fi
# Mitsuba's max_depth D is D - 1 bounces; the importer writes D - 1 into
# the scene, and SPPM's photons take theirs from --photon-bounces.
for d in 6 64; do
    if stage "cbox$d"; then
        mitsuba mitsuba_d$d $d
        mitsuba mitsuba_black_d$d $d --black-emitters
        render sppm_d$d "$MI" cbox.xml "$ITER" -D max_depth=$d --photon-bounces $((d - 1))
    fi
done
if stage bitterli; then
    render pbrt "$BIT" scene-v4.pbrt "$BIT_ITER"
    render xml "$BIT" mitsuba/scene_v3.xml "$BIT_ITER"
fi

# rel RMSE and energy of A against B, by photonmap compare [over the mask].
cmp() { "$PM" compare "$WORK/$1.exr" "$WORK/$2.exr" --json ${3:+--mask "$3"} 2>/dev/null |
    python3 -c 'import json,sys; j=json.load(sys.stdin); print(j["rel_rmse"], j["energy"])'; }
row() { # LABEL A B [MASK]: crossed seeds against each side's seed-to-seed noise
    local x1 x2 e e2 na nb ea eb
    # Seeds crossed (1 against 2, 2 against 1): photonmap's renders of one
    # seed share their random numbers, so they are not independent.
    read -r x1 e < <(cmp "$2_seed1" "$3_seed2" "${4:-}"); read -r x2 e2 < <(cmp "$2_seed2" "$3_seed1" "${4:-}")
    read -r na ea < <(cmp "$2_seed2" "$2_seed1" "${4:-}"); read -r nb eb < <(cmp "$3_seed2" "$3_seed1" "${4:-}")
    python3 - "$1" "$x1" "$x2" "$e" "$e2" "$na" "$nb" "$ea" "$eb" <<'PY'
import math, sys
label, x1, x2, e, e2, na, nb, ea, eb = sys.argv[1], *map(float, sys.argv[2:])
d = math.sqrt((x1 * x1 + x2 * x2) / 2)         # one run of A against one of B
sa, sb = na / math.sqrt(2), nb / math.sqrt(2)  # one run's own noise
expect = math.hypot(sa, sb)                    # what d would be with no bias
# energy: the crossed pairs' mean ratio; its noise, one run's spread of each
# side (seed against seed over sqrt 2) combined and over sqrt 2 for the two pairs
en = math.hypot(ea - 1, eb - 1) / 2
print(f"| {label} | {d:.4f} | {sa:.4f} | {sb:.4f} | {expect:.4f} | {d / expect:.2f} "
      f"| {(e + e2) / 2:.4f} ± {en:.4f} |")
PY
}
MASK=$WORK/interior.png
{
    echo "\`ITER=$ITER BIT_ITER=$BIT_ITER MI_SPP=$MI_SPP MI_VARIANT=$VARIANT scripts/import-trial.sh MITSUBA_SCENES BITTERLI_CORNELL PY WORK\`: per seed S in 1, 2 and D in 6, 64: \`photonmap render cbox.xml --method sppm --iterations $ITER --width $RES --height $RES --seed S -D max_depth=D --photon-bounces D-1 --exr sppm_dD_seedS.exr\`, \`python scripts/mitsuba-render.py $VARIANT cbox.xml $MI_SPP S mitsuba_dD_seedS.exr res=$RES max_depth=D\` (a box filter), the same with \`--black-emitters\` to mitsuba_black_dD_seedS.exr; \`python scripts/mitsuba-render.py $VARIANT cbox.xml --mask interior.png res=$RES\`; \`photonmap render scene-v4.pbrt --method sppm --iterations $BIT_ITER --width $RES --height $RES --seed S --exr pbrt_seedS.exr\` (likewise \`mitsuba/scene_v3.xml\` to xml_seedS); then \`photonmap compare A B --json [--mask interior.png]\` for every pair"
    echo
    echo "$RES x $RES, Mitsuba 3 with a box filter of one pixel (as photonmap's); all pixels, or the interior ($(grep -o '[0-9]* white' "$WORK/interior.txt" | sed -n 1p | cut -d' ' -f1) of the $((RES * RES)) pixels whose 4 x 4 sub-pixel rays all first hit one diffuse plane: no edges, light or spheres), or the walls' edges (the $(grep -o '[0-9]* white' "$WORK/interior.txt" | sed -n 2p | cut -d' ' -f1) whose rays all hit diffuse, non-emitting surfaces, but not one plane). One run of A against an independent one of B (rms over A's seed 1 against B's seed 2 and A's 2 against B's 1), each side's own noise (seed 2 against seed 1, over sqrt 2), the difference that noise alone gives (their root sum of squares), and the ratio; energy: A's mean over B's (the two crossed pairs' mean), ± the spread that the two sides' seed-to-seed energy differences give it."
    echo
    echo "| A against B | rel RMSE | noise A | noise B | noise alone | ratio | energy |"
    echo "|---|---|---|---|---|---|---|"
    for d in 6 64; do
        w="Mitsuba's cbox.xml, max_depth $d"
        [ $d = 6 ] && w="$w (the file's)"
        p="photonmap SPPM ($ITER it.)"; m="Mitsuba 3 path ($MI_SPP spp)"
        row "$w, all pixels: $p against $m" sppm_d$d mitsuba_d$d
        row "$w, all pixels: $p against $m, the light's BSDF black" sppm_d$d mitsuba_black_d$d
        row "$w, interior: $p against $m" sppm_d$d mitsuba_d$d "$MASK"
        row "$w, interior: $p against $m, the light's BSDF black" sppm_d$d mitsuba_black_d$d "$MASK"
        row "$w, interior: Mitsuba 3, the light's BSDF black against the file's" mitsuba_black_d$d mitsuba_d$d "$MASK"
    done
    p="photonmap SPPM ($ITER it.)"; m="Mitsuba 3 path ($MI_SPP spp), the light's BSDF black"
    row "Mitsuba's cbox.xml, max_depth 64, the walls' edges: $p against $m" sppm_d64 mitsuba_black_d64 "$WORK/edges.png"
    row "Bitterli's Cornell box, all pixels, photonmap SPPM ($BIT_ITER it.): pbrt-v4 against Mitsuba 3 XML" pbrt xml
    read -r same esame < <(cmp pbrt_seed1 xml_seed1)
    echo
    echo "The same seed (1) of both, sharing their random numbers: rel RMSE $(printf %.4f "$same"), energy $(printf %.4f "$esame")."
} > "$OUT/table.md"
for f in sppm_d64 mitsuba_d64 pbrt xml; do "$PM" convert "$WORK/${f}_seed1.exr" "$OUT/$f.png" >/dev/null; done
cp "$MASK" "$OUT/interior.png"
cat "$OUT/table.md"
