#!/usr/bin/env bash
# The measured figures the book includes that no other committed command
# writes: each block runs one command (or a few) and writes its output under
# results/llvmpipe/<topic>/, with the command beside it in that folder's
# command.txt (one line per file: the file, then the command that wrote it).
# The comment above each block names the page that includes its files.
#
# Usage: scripts/book-figures.sh [PART ...]
#   deterministic  counts and errors that do not depend on the clock (what
#                  they print is the same on every run on the same driver);
#                  their files are committed
#   timings        wall-clock figures and equal-time comparisons: run them on
#                  a quiet machine (nothing else building or rendering), or
#                  the seconds say nothing
#   tests          every test binary's printed figures (--nocapture, one test
#                  at a time), and the whole suite's run time
#   fuzz           the long seeded run of the loaders' mutation tests
#   all            all of the above
# (default: timings). Build first: cargo build --release. Run from anywhere;
# it works in the repository root. About an hour for `all` on two cores:
# deterministic 3 min, timings 40 min, tests 20 min, fuzz 10 min or more.
#
# Environment: PHOTONMAP, the binary (default target/release/photonmap).
set -euo pipefail

root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
bin="${PHOTONMAP:-target/release/photonmap}"
res=results/llvmpipe
if [[ ! -x "$bin" ]]; then
    echo "book-figures: no $bin: run cargo build --release first (or set PHOTONMAP)" >&2
    exit 1
fi
scratch="$(mktemp -d)"
trap 'rm -rf "$scratch"' EXIT

# words ARGS...: ARGS as a shell would need them typed (quoted where they
# hold anything but plain characters).
words() {
    local a out=()
    for a in "$@"; do
        if [[ "$a" =~ ^[A-Za-z0-9_./:=,+@%-]+$ ]]; then
            out+=("$a")
        else
            out+=("'${a//\'/\'\\\'\'}'")
        fi
    done
    echo "${out[*]}"
}

# note FILE COMMAND: FILE's line in its folder's command.txt becomes COMMAND.
note() {
    local file="$1" command="$2" dir base list
    dir="$(dirname "$file")"
    base="$(basename "$file")"
    list="$dir/command.txt"
    mkdir -p "$dir"
    if [[ -f "$list" ]]; then
        awk -v line="$base: " 'index($0, line) != 1' "$list" >"$list.new"
        mv "$list.new" "$list"
    fi
    echo "$base: $command" >>"$list"
    sort -o "$list" "$list"
}

# run_to FILE ARGS...: `photonmap ARGS`, its stdout into FILE.
run_to() {
    local file="$1"
    shift
    mkdir -p "$(dirname "$file")"
    echo "book-figures: photonmap $*" >&2
    "$bin" "$@" >"$file"
    note "$file" "photonmap $(words "$@")"
}

# photons_to FILE ARGS...: `photonmap photons ARGS`, its counts only (the
# stage table of times and the GPU time of earlier attempts left out).
photons_to() {
    local file="$1"
    shift
    mkdir -p "$(dirname "$file")"
    echo "book-figures: photonmap photons $*" >&2
    "$bin" photons "$@" | sed '/^stage /,$d' | grep -v 'more GPU time' >"$file"
    note "$file" "photonmap photons $(words "$@") | sed '/^stage /,\$d' | grep -v 'more GPU time'"
}

# explain_to FILE ARGS...: `photonmap render ARGS --explain`, what runs and
# is skipped and the estimate's summary line, without the stage table's times.
explain_to() {
    local file="$1"
    shift
    mkdir -p "$(dirname "$file")"
    echo "book-figures: photonmap render $* --explain" >&2
    "$bin" render "$@" --explain -o "$scratch/explain.png" 2>&1 >/dev/null |
        grep -v -e '^\[' -e '^wrote ' | sed '/^stage /,/^total /d' >"$file"
    note "$file" "photonmap render $(words "$@") --explain -o IMAGE.png 2>&1 >/dev/null | grep -v -e '^\\[' -e '^wrote ' | sed '/^stage /,/^total /d'"
}

# render_to BASE ARGS...: `photonmap render ARGS --json`: the JSON report into
# BASE.json and what it prints on stderr (the stage table, its summary lines),
# less the progress lines, into BASE.txt.
render_to() {
    local base="$1"
    shift
    mkdir -p "$(dirname "$base")"
    echo "book-figures: photonmap render $*" >&2
    "$bin" render "$@" --json -o "$scratch/render.exr" >"$base.json" 2>"$scratch/render.err"
    grep -v -e '^\[' -e '^wrote ' "$scratch/render.err" >"$base.txt"
    note "$base.json" "photonmap render $(words "$@") --json -o IMAGE.exr"
    note "$base.txt" "photonmap render $(words "$@") --json -o IMAGE.exr, its stderr less the progress lines"
}

deterministic() {
    # docs/src/paper/photons.md (projection maps, how the emitted count hits
    # photons_stored) and docs/src/evaluation/skips.md (photons aimed).
    photons_to $res/photons/ring.txt ring
    photons_to $res/photons/ring_no_projection_map.txt ring --no-projection-map
    photons_to $res/photons/glass_ball.txt glass_ball
    photons_to $res/photons/glass_ball_caustics_only.txt variants/glass_ball_caustics_only
    photons_to $res/photons/glass_ball_caustics_only_no_projection_map.txt \
        variants/glass_ball_caustics_only --no-projection-map

    # docs/src/guide/regression.md: RING as it is, a 10% brighter light, the
    # camera one pixel to the right at the reference's 96 rows (in f32 and
    # printed as Rust prints an f32), no caustic: the defects of tests/cli/regress.rs,
    # regress_catches_a_brighter_light_a_shifted_camera_and_a_missing_caustic.
    local pixel
    pixel="$(python3 -c 'import math,struct
f=lambda x: struct.unpack("f", struct.pack("f", x))[0]
d=f(math.sqrt(f(f(3.2*3.2)+f(3.1*3.1))))
p=f(2.0*d*f(math.tan(math.radians(17.5)))/96.0)
print(next(t for t in (f"{p:.{n}g}" for n in range(1, 10)) if f(float(t)) == p))')"
    for c in as_is brighter shifted no_caustic; do
        local extra=()
        case $c in
        brighter) extra=(--set 'light[0].intensity=[44.0, 44.0, 44.0]') ;;
        shifted) extra=(--set "camera.position=[$pixel, 3.2, 3.2]" --set "camera.look_at=[$pixel, 0.0, 0.1]") ;;
        no_caustic) extra=(--direct-only) ;;
        esac
        local file=$res/regress/ring/$c.json
        mkdir -p "$(dirname "$file")"
        echo "book-figures: photonmap regress scenes/ring.toml ${extra[*]}" >&2
        "$bin" regress scenes/ring.toml --reference reference_images --json \
            --out "$scratch/regress_$c" ${extra[@]+"${extra[@]}"} >"$file" || true
        note "$file" "photonmap regress scenes/ring.toml --reference reference_images --json --out DIR${extra[*]+ $(words "${extra[@]}")}"
    done

    # docs/src/evaluation/skips.md: what runs and what is skipped.
    explain_to $res/skips/furnace_64_bounces.txt variants/furnace_64_bounces
    explain_to $res/skips/glass_ball.txt glass_ball
    explain_to $res/skips/cornell_box.txt cornell_box
    explain_to $res/skips/ring.txt ring
    explain_to $res/skips/glass_ball_fitted_grid.txt variants/glass_ball_fitted_grid

    # docs/src/paper/final-gather-adaptive.md: the pixels adaptive sampling
    # computes at 256 x 256.
    explain_to $res/section_4_5/adaptive/cornell_box_256_adaptive.txt \
        cornell_box --width 256 --height 256 --adaptive
}

timings() {
    # docs/src/paper/photons.md: both builds and the fused sort, 2^10 .. 2^20.
    run_to $res/build/bench_build.txt bench build

    # docs/src/paper/radiance-estimate.md (and the paper's tables page): where
    # the estimate's time goes, each variant of the search.
    run_to $res/estimate/table.md bench estimate

    # docs/src/paper/radiance-estimate.md: whether the stencil test skips work.
    run_to $res/mask/bench_mask.txt bench mask

    # docs/src/paper/leak-test.md: what the visibility test costs.
    render_to $res/leak_test/cornell_box_visibility cornell_box
    render_to $res/leak_test/cornell_box_none cornell_box --leak-test none
    render_to $res/leak_test/cornell_box_visibility_paper_search cornell_box --paper-search
    render_to $res/leak_test/ring_visibility ring
    render_to $res/leak_test/ring_none ring --leak-test none

    # docs/src/paper/tables.md: the faithful CORNELL BOX with the paper's
    # estimate, its stages and its search's counters (`estimates` in the JSON).
    render_to $res/table1_faithful/render_cornell_box cornell_box --faithful --leak-test none

    # docs/src/paper/final-gather-adaptive.md: adaptive sampling's and final
    # gather's estimate at 128 x 128; adaptive SPPM at 256 x 256.
    local s45=$res/section_4_5/render
    render_to $s45/cornell_box_128 cornell_box --width 128 --height 128 --leak-test none
    render_to $s45/cornell_box_128_adaptive cornell_box --width 128 --height 128 --leak-test none --adaptive
    render_to $s45/cornell_box_128_final_gather_16 cornell_box --width 128 --height 128 --leak-test none --final-gather 16
    render_to $s45/cornell_box_256_sppm cornell_box --method sppm --width 256 --height 256
    render_to $s45/cornell_box_256_sppm_adaptive cornell_box --method sppm --width 256 --height 256 --adaptive

    # docs/src/methods/igi.md: time by component (each scene at its
    # reference's size, the mesh stage at 512 x 384), and the caustic map's k.
    local s
    for s in cornell_box glass_ball ring; do
        run_to $res/igi/bench/$s/table.txt bench igi --scene scenes/$s.toml --out $res/igi/bench/$s
    done
    run_to $res/igi/bench/stage_131072/table.txt bench igi --triangles 131072 --out $res/igi/bench/stage_131072
    local k
    for k in 50 500; do
        render_to $res/igi/caustic_k/k$k cornell_box --method igi --width 256 --height 256 \
            --leak-test visibility --seed 7 --set photon_map.k=$k
        echo "book-figures: photonmap compare (k = $k)" >&2
        "$bin" compare "$scratch/render.exr" reference_images/cornell_box.sppm.exr \
            >$res/igi/caustic_k/compare_k$k.txt
        note $res/igi/caustic_k/compare_k$k.txt \
            "photonmap compare IMAGE.exr reference_images/cornell_box.sppm.exr (IMAGE.exr: the render of k$k.json)"
    done

    # docs/src/evaluation/meshes.md: the BVH at scale, and small meshes at a
    # small size.
    run_to $res/meshes/bench/table.txt bench meshes --out $res/meshes/bench
    run_to $res/meshes/bench_256x192/table.txt bench meshes --width 256 --height 192 \
        --triangles 12,1280,16000,20480 --out $res/meshes/bench_256x192

    # docs/src/evaluation/skips.md: what each skip saves.
    local sk=$res/skips/render
    render_to $sk/furnace_64_bounces variants/furnace_64_bounces
    render_to $sk/furnace_64_bounces_all_bounces variants/furnace_64_bounces --all-bounces
    render_to $sk/glass_ball_fitted_grid variants/glass_ball_fitted_grid
    render_to $sk/glass_ball_scene_box_grid variants/glass_ball_scene_box_grid
    render_to $sk/glass_ball_caustics_only variants/glass_ball_caustics_only
    render_to $sk/glass_ball_caustics_only_no_projection_map variants/glass_ball_caustics_only --no-projection-map
    for s in glass_ball ring cornell_box; do
        render_to $sk/$s $s
        render_to $sk/${s}_all_bounces $s --all-bounces
    done
    render_to $sk/ring_no_projection_map ring --no-projection-map
    # A camera path of 8 frames on one photon map, against 8 renders that each
    # trace their own (bash's `time` around both).
    {
        time "$bin" render scenes/glass_ball.toml --camera-path scenes/paths/glass_ball_orbit.toml \
            --out "$scratch/path" --width 256 --height 192 --quiet
    } 2>"$sk/camera_path.time"
    note "$sk/camera_path.time" "bash: time photonmap render scenes/glass_ball.toml --camera-path scenes/paths/glass_ball_orbit.toml --out DIR --width 256 --height 192 --quiet"
    {
        time for i in 1 2 3 4 5 6 7 8; do
            "$bin" render scenes/glass_ball.toml --width 256 --height 192 --quiet -o "$scratch/frame_$i.png"
        done
    } 2>"$sk/eight_renders.time"
    note "$sk/eight_renders.time" "bash: time for i in 1..8: photonmap render scenes/glass_ball.toml --width 256 --height 192 --quiet -o FRAME.png"

    # docs/src/evaluation/accuracy.md: the one-shot estimate against SPPM at
    # equal time (2 seeds a row), and CORNELL BOX with and without the leak test.
    for s in ring glass_ball cornell_box; do
        run_to $res/accuracy/equal_time/$s/run.txt bench accuracy --scene scenes/$s.toml --seeds 2 \
            --only "scene defaults" --only "4 spp" --only "SPPM 4 " --only "SPPM 16 " --only "SPPM 64 " \
            --out $res/accuracy/equal_time/$s
    done
    local run
    for run in 1 2; do
        render_to $res/accuracy/leak_test/cornell_box_256_visibility_$run cornell_box --width 256 --height 256
        render_to $res/accuracy/leak_test/cornell_box_256_none_$run cornell_box --width 256 --height 256 --leak-test none
    done
}

# test_log TARGET FILTER LOG [ENV=VALUE ...]: the output of one test target
# (`--test gpu`, `--test cli`, `--lib`) filtered to one module (`igi::`) into
# tests/LOG.txt, its tests one at a time so that their printed figures do not
# interleave.
test_log() {
    local target="$1" filter="$2" file="$res/tests/$3.txt"
    shift 3
    mkdir -p "$(dirname "$file")"
    local cmd="cargo test --release $target $filter -- --nocapture --test-threads=1"
    echo "book-figures: ${*:+$* }$cmd" >&2
    # shellcheck disable=SC2086 # target is two words on purpose
    env "$@" cargo test --release $target "$filter" -- --nocapture --test-threads=1 >"$file" 2>&1
    note "$file" "${*:+$* }$cmd (stdout and stderr)"
}

tests() {
    # docs/src/developer/testing.md and the chapters that quote a test's
    # figures (photons.md, leak-test.md, sppm.md, skips.md, meshes.md,
    # stress.md, radiosity.md): each test module that prints its figures.
    local t
    for t in adaptive bvh differentials final_gather fused_eye_path gpu_substrate hash_grid \
        igi intersections obj_scenes photon_trace radiance_estimate radiosity ray_tracer \
        reference_images sppm stress truth; do
        test_log "--test gpu" "$t::" "$t"
    done
    test_log "--test gpu" "bit_identical::" bit_identical PHOTONMAP_BIT_IDENTICAL=1
    test_log "--test cli" "" cli
    test_log "--lib" "scene::load::tests::fuzz" fuzz_loading
    test_log "--lib" "scene::load::tests::rebase" rebase
    # docs/src/developer/testing.md: the whole suite's run time, as CI runs it.
    local file=$res/tests/suite.txt
    echo "book-figures: cargo test --release (timed)" >&2
    { time cargo test --release 2>&1 | grep -E -e '^ +Running ' -e '^test result: '; } >"$file" 2>&1
    note "$file" "bash: time cargo test --release, its Running and test result lines"
}

fuzz() {
    # docs/src/evaluation/stress.md: the long run of the mutation tests.
    local seed
    for seed in 1 2; do
        test_log fuzz_loading fuzz_loading_seed_$seed \
            PHOTONMAP_FUZZ_SEED=$seed PHOTONMAP_FUZZ_ITERATIONS=100000
    done
}

parts=("$@")
((${#parts[@]})) || parts=(timings)
for p in "${parts[@]}"; do
    case "$p" in
    deterministic | timings | tests | fuzz) "$p" ;;
    all) deterministic && timings && tests && fuzz ;;
    *)
        sed -n '2,23p' "$0" >&2
        exit 2
        ;;
    esac
done
echo "book-figures: done: ${parts[*]}" >&2
