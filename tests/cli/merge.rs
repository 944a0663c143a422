//! `merge --passes`: independent renders of one frame averaged. Four seeds
//! merged have half the noise of one (within the spread measured across
//! pairs of seeds), the variance layer predicts that noise, passes that are
//! not of one frame are refused, writing nothing, and contrib/slurm's job
//! scripts run as a job array and its merge.

use std::path::{Path, PathBuf};

use crate::common::{Run, TempDir};

use photonmap::render::Image;

fn render(dir: &Path, scene: &str, seed: u32, extra: &[&str]) -> PathBuf {
    let out = dir.join(format!("{scene}-{seed}{}.exr", extra.join("")));
    Run::new([
        "render", scene, "--quiet", "--width", "32", "--height", "24",
    ])
    .args(["--seed", &seed.to_string()])
    .args(extra)
    .output_to(&out)
    .succeeds();
    out
}

/// Root-mean-square difference of two images over the first's mean, over
/// sqrt(2): the noise of one of two independent images.
fn noise_between(a: &Image, b: &Image) -> f64 {
    let n = (a.pixels.len() * 3) as f64;
    let sq: f64 = a
        .pixels
        .iter()
        .zip(&b.pixels)
        .flat_map(|(p, q)| (0..3).map(move |c| (f64::from(p[c]) - f64::from(q[c])).powi(2)))
        .sum();
    let mean = a.mean().iter().sum::<f64>() / 3.0;
    (sq / n / 2.0).sqrt() / mean
}

/// Sixteen seeds: eight pairs of single passes and two pairs of four-pass
/// merges, each pair's difference giving one noise figure. The ratio of the
/// merges' noise to the single passes' must be 1/2 within three standard
/// errors, taken from the spread of the eight single-pass figures; the
/// merges' variance layers must predict their measured noise likewise.
#[test]
fn four_passes_merged_have_half_the_noise_of_one() {
    let d = TempDir::new("merge");
    let seeds: Vec<PathBuf> = (1..=16).map(|s| render(&d, "ring", s, &[])).collect();
    let images: Vec<Image> = seeds.iter().map(|p| Image::read_exr(p).unwrap()).collect();
    let merged: Vec<(Image, serde_json::Value)> = (0..4)
        .map(|g| {
            let out = d.join(format!("merged-{g}.exr"));
            let json = Run::new(["merge", "--passes", "--json"])
                .arg(&out)
                .args(&seeds[4 * g..4 * g + 4])
                .json();
            (Image::read_exr(&out).unwrap(), json)
        })
        .collect();
    // The mean of equal weights (one eye sample each).
    let (a, a_json) = &merged[0];
    for (i, px) in a.pixels.iter().enumerate() {
        for (c, &got) in px.iter().enumerate() {
            let mean = images[..4]
                .iter()
                .map(|im| f64::from(im.pixels[i][c]))
                .sum::<f64>()
                / 4.0;
            assert!((f64::from(got) - mean).abs() <= 1e-6 * mean.abs().max(1e-3));
        }
    }
    assert_eq!(a_json["seeds"], serde_json::json!([1, 2, 3, 4]));
    let mean_of = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let one: Vec<f64> = (0..8)
        .map(|i| noise_between(&images[i], &images[i + 8]))
        .collect();
    let four = [
        noise_between(&merged[0].0, &merged[1].0),
        noise_between(&merged[2].0, &merged[3].0),
    ];
    let (mean_one, mean_four) = (mean_of(&one), mean_of(&four));
    let sd = (one.iter().map(|n| (n - mean_one).powi(2)).sum::<f64>() / 7.0).sqrt();
    // Relative standard errors: of the eight single figures' mean, and of the
    // two merged figures' mean, each figure spreading as a single one does.
    let cv = sd / mean_one;
    let ratio = mean_four / mean_one;
    let tolerance = 3.0 * 0.5 * (cv * cv / 8.0 + cv * cv / 2.0).sqrt();
    let predicted = mean_of(
        &merged
            .iter()
            .map(|(_, j)| j["relative_noise"].as_f64().unwrap())
            .collect::<Vec<_>>(),
    );
    let predicted_tolerance = 3.0 * cv / 2f64.sqrt();
    println!(
        "noise: one seed {mean_one:.4} (pairs {one:.4?}), four merged {mean_four:.4} ({four:.4?}), ratio {ratio:.3} (0.5 +- {tolerance:.3}); the variance layers predict {predicted:.4} (+- {:.1}%)",
        100.0 * predicted_tolerance
    );
    assert!((ratio - 0.5).abs() <= tolerance, "ratio {ratio}");
    assert!(
        (predicted / mean_four - 1.0).abs() <= predicted_tolerance,
        "predicted {predicted}, measured {mean_four}"
    );
}

#[test]
fn passes_of_different_frames_are_refused() {
    let d = TempDir::new("merge-bad");
    let ring1 = render(&d, "ring", 1, &[]);
    let ring2 = render(&d, "ring", 2, &[]);
    let glass = render(&d, "glass_ball", 2, &[]);
    let k8 = render(&d, "ring", 3, &["--set", "photon_map.k=8"]);
    let out = d.join("merged.exr");
    let refused = |inputs: &[&PathBuf], says: &str| {
        Run::new(["merge", "--passes"])
            .writing_arg(&out)
            .args(inputs)
            .refused_with(says);
    };
    refused(&[&ring1, &glass], "scene_hash differs");
    refused(&[&ring1, &k8], "overrides differs");
    refused(&[&ring1, &ring1], "same seed");
    let disc = render(&d, "ring", 4, &["--leak-test", "disc"]);
    refused(&[&ring1, &disc], "method_options differs");
    let once = d.join("once.exr");
    Run::new(["merge", "--passes"])
        .arg(&once)
        .args([&ring1, &ring2])
        .succeeds();
    refused(&[&once, &glass], "already a merge");
    refused(&[&ring1, &ring2, &out], "also an input");
    let png = d.join("x.png");
    std::fs::write(&png, b"not an exr").unwrap();
    refused(&[&ring1, &png], "cannot read EXR");
}

/// contrib/slurm's job scripts, run as Slurm would run them but locally: four
/// array tasks, then the merge job, which merges their four passes.
#[test]
fn the_slurm_job_scripts_render_passes_and_merge_them() {
    let d = TempDir::new("slurm");
    let out = d.as_ref() as &Path;
    let env = [
        ("SCENE", "scenes/ring.toml"),
        ("OUT", out.to_str().unwrap()),
        ("RENDER_ARGS", "--width 32 --height 24"),
    ];
    let run = |script: &str, task: Option<u32>| crate::tiles::slurm(script, task, &env);
    for task in 1..=4 {
        run("seeds.sbatch", Some(task));
    }
    run("merge.sbatch", None);
    let merged = d.join("merged.exr");
    let header = Image::exr_attributes(&merged).unwrap();
    let merge = header.iter().find(|(k, _)| k == "photonmap.merge").unwrap();
    let merge: serde_json::Value = serde_json::from_str(&merge.1).unwrap();
    assert_eq!(merge["seeds"], serde_json::json!([1, 2, 3, 4]));
    let one = Image::read_exr(&d.join("pass-1.exr")).unwrap();
    assert_eq!((one.width, one.height), (32, 24));
}
