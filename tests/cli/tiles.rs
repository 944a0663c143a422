//! Crops and tiles: a crop (`--pixel-bounds`, `--crop-window`) holds the
//! frame's own pixels bit for bit under every method, its EXR keeps the crop
//! as its data window in the frame's display window, and tiles rendered as
//! contrib/slurm's array renders them stitch (`merge --tiles`) into the full
//! render bit for bit, for the one-shot estimate and for SPPM. Tiles that are
//! not one render's, overlap or leave gaps are refused, writing nothing.

use std::path::{Path, PathBuf};

use crate::common::{Run, TempDir};

use photonmap::render::Image;

const FRAME: [&str; 4] = ["--width", "41", "--height", "31"];

fn render(out: &Path, scene: &str, args: &[&str]) -> Image {
    Run::new(["render", scene, "--quiet"])
        .args(FRAME)
        .args(args)
        .output_to(out)
        .succeeds();
    Image::read_exr(out).unwrap()
}

/// Every method's crop equals the same pixels of its whole frame, and
/// its EXR places them in the frame.
#[test]
fn a_crop_holds_the_frames_own_pixels_under_every_method() {
    let d = TempDir::new("crop-methods");
    let methods: [(&str, &[&str]); 10] = [
        ("paper", &[]),
        ("final-gather", &["--final-gather", "8"]),
        ("adaptive", &["--final-gather", "8", "--adaptive"]),
        ("igi", &["--method", "igi"]),
        ("igi-downsampled", &["--method", "igi", "--downsample", "2"]),
        ("differentials", &["--method", "differentials"]),
        ("radiosity", &["--method", "radiosity"]),
        ("direct", &["--direct-only"]),
        ("sppm", &["--method", "sppm", "--iterations", "2"]),
        (
            "vcm",
            &[
                "--method",
                "vcm",
                "--iterations",
                "2",
                "--light-paths",
                "2048",
            ],
        ),
    ];
    for (name, args) in methods {
        let full = render(&d.join(format!("{name}.exr")), "cornell_box", args);
        let crop_path = d.join(format!("{name}-crop.exr"));
        let crop = render(
            &crop_path,
            "cornell_box",
            &[args, &["--pixel-bounds", "9", "30", "5", "22"]].concat(),
        );
        assert_eq!(crop, full.crop(9, 5, 21, 17), "{name}");
        assert_eq!(
            Image::exr_placement(&crop_path).unwrap(),
            ((9, 5), (41, 31)),
            "{name}"
        );
    }
}

/// Runs contrib/slurm/`script` as Slurm would for array task `task` (None:
/// not an array job), with `env`.
pub(crate) fn slurm(script: &str, task: Option<u32>, env: &[(&str, &str)]) {
    let mut c = std::process::Command::new("bash");
    c.arg(format!("contrib/slurm/{script}"))
        .current_dir(crate::common::root())
        .env("PHOTONMAP", env!("CARGO_BIN_EXE_photonmap"))
        .env_remove("SLURM_ARRAY_TASK_ID");
    for (k, v) in env {
        c.env(k, v);
    }
    if let Some(t) = task {
        c.env("SLURM_ARRAY_TASK_ID", t.to_string());
    }
    let out = c.output().unwrap();
    assert!(
        out.status.success(),
        "{script}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// Four tiles from contrib/slurm's tile array, merged by its merge job,
/// equal the full render bit for bit: the one-shot estimate at 2 spp, and
/// SPPM.
#[test]
fn four_slurm_tiles_merge_into_the_full_render_bit_for_bit() {
    for (name, args) in [
        ("paper", "--spp 2"),
        ("sppm", "--method sppm --iterations 3"),
    ] {
        let d = TempDir::new(&format!("tiles-{name}"));
        let render_args = format!("{} {args}", FRAME.join(" "));
        let out = d.as_ref() as &Path;
        let env = [
            ("SCENE", "scenes/ring.toml"),
            ("OUT", out.to_str().unwrap()),
            ("RENDER_ARGS", render_args.as_str()),
            ("TILES", "2"),
            ("MODE", "tiles"),
        ];
        for task in 1..=4 {
            slurm("tiles.sbatch", Some(task), &env);
        }
        slurm("merge.sbatch", None, &env);
        let args: Vec<&str> = args.split(' ').collect();
        let scene = crate::common::root().join("scenes/ring.toml");
        let full = render(&d.join("full.exr"), scene.to_str().unwrap(), &args);
        let merged = Image::read_exr(&d.join("merged.exr")).unwrap();
        assert_eq!(merged, full, "{name}");
        // The tiles are the frame's four quarters, rounded up as pbrt rounds.
        let first = Image::read_exr(&d.join("tile-1.exr")).unwrap();
        assert_eq!((first.width, first.height), (21, 16), "{name}");
    }
}

/// Tiles that do not make one frame of one render are refused, writing
/// nothing; so are bad crops.
#[test]
fn tiles_that_are_not_one_frame_are_refused() {
    let d = TempDir::new("tiles-bad");
    let tile = |name: &str, bounds: [&str; 4], seed: &str| -> PathBuf {
        let p = d.join(format!("{name}.exr"));
        render(
            &p,
            "ring",
            &[&["--seed", seed, "--pixel-bounds"], &bounds[..]].concat(),
        );
        p
    };
    let left = tile("left", ["0", "20", "0", "31"], "1");
    let right = tile("right", ["20", "41", "0", "31"], "1");
    let wide = tile("wide", ["19", "41", "0", "31"], "1");
    let other_seed = tile("other", ["20", "41", "0", "31"], "2");
    let merged = d.join("merged.exr");
    let merge = |inputs: &[&PathBuf], says: &str| {
        Run::new(["merge", "--tiles"])
            .writing_arg(&merged)
            .args(inputs.iter().copied())
            .refused_with(says);
    };
    merge(&[&left], "uncovered, the first at (20, 0)");
    merge(&[&left, &wide], "overlap (pixel 19, 0)");
    merge(&[&left, &other_seed], "seed differs");
    Run::new(["merge", "--passes"])
        .writing_arg(&merged)
        .args([&left, &other_seed])
        .refused_with("stitch the tiles with merge --tiles first");
    Run::new(["merge", "--tiles"])
        .writing_arg(&merged)
        .args([&left, &right])
        .succeeds();
    let crop = |args: &[&str], says: &str| {
        Run::new(["render", "ring", "--quiet"])
            .args(FRAME)
            .args(args)
            .output_to(d.join("bad.exr"))
            .refused_with(says);
    };
    crop(&["--pixel-bounds", "0", "42", "0", "31"], "x0 < x1 <= 41");
    crop(&["--pixel-bounds", "5", "5", "0", "31"], "x0 < x1 <= 41");
    crop(&["--crop-window", "0", "1.5", "0", "1"], "must be in 0..=1");
    crop(&["--crop-window", "0.5", "0.5", "0", "1"], "holds no pixel");
}
