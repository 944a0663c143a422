//! What `bench mitsuba` scores every image against: the committed ground
//! truth, a given or SPPM reference, or one Mitsuba's path tracer makes
//! (--mitsuba-reference), with its mask; and each image's row or curve
//! point, compared and written.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context, Result};

use photonmap::bench::regions::{masked_rectangles, region_energies, Region};
use photonmap::image::{write_all_atomically, write_atomically};
use photonmap::metrics::{compare, Metrics};
use photonmap::render::Image;
use photonmap::scene::Scene;

use super::args::MitsubaBenchArgs;
use super::report::{Curve, CurvePoint, Row};
use super::runner::{render_mitsuba, Taken};
use crate::cli::bench::scene::default_reference;
use crate::cli::compare::read_mask;

/// The committed ground truth: <scene>.exr, <scene>_interior_mask.png and
/// noise.json (relative to the working directory, as the SPPM references).
const TRUTH: &str = "reference_images/truth";

/// What every image is compared with.
pub(super) struct Target {
    pub(super) path: PathBuf,
    pub(super) kind: &'static str,
    pub(super) image: Image,
    pub(super) mask: Option<(PathBuf, Vec<bool>)>,
    /// The truth's noise.json figure, with the default truth.
    pub(super) noise: Option<f64>,
}

impl Target {
    fn compare(&self, image: &Image) -> Result<Metrics> {
        let mask = self.mask.as_ref().map(|m| m.1.as_slice());
        Ok(compare(image, &self.image, mask)?)
    }
}

/// The reference and mask from the options, or the defaults; checked
/// against the scene's size before anything renders. Returns it and the
/// scale that renders at its size.
pub(super) fn target(a: &MitsubaBenchArgs, scene: &Scene, name: &str) -> Result<(Target, u32)> {
    let truth = Path::new(TRUTH).join(format!("{name}.exr"));
    let (path, kind) = match &a.reference {
        Some(p) if !p.is_file() => bail!("--reference {}: no such file", p.display()),
        Some(p) => (p.clone(), "given"),
        None if truth.is_file() => (truth, "truth"),
        None => {
            let sppm = default_reference(&a.scene);
            if !sppm.is_file() {
                bail!(
                    "no reference for {name} (neither {} nor {}): give --reference",
                    truth.display(),
                    sppm.display()
                );
            }
            (sppm, "SPPM reference")
        }
    };
    let image =
        Image::read_exr(&path).with_context(|| format!("--reference {}", path.display()))?;
    let (w, h) = (scene.camera.width, scene.camera.height);
    let scale = w.checked_div(image.width).unwrap_or(0);
    if scale == 0 || image.width * scale != w || image.height * scale != h {
        bail!(
            "--reference {}: {} x {} pixels is not the scene's {w} x {h} divided by a whole number",
            path.display(),
            image.width,
            image.height
        );
    }
    let mask = match &a.mask {
        Some(m) => Some(m.clone()),
        None if kind == "truth" => {
            Some(Path::new(TRUTH).join(format!("{name}_interior_mask.png"))).filter(|m| m.is_file())
        }
        None => None,
    };
    let mask = mask.map(|m| checked_mask(&m, &image)).transpose()?;
    let noise = (kind == "truth").then(|| truth_noise(name)).flatten();
    Ok((
        Target {
            path,
            kind,
            image,
            mask,
            noise,
        },
        scale,
    ))
}

/// The size a --mitsuba-reference renders at: the scene's over --scale.
pub(super) fn mitsuba_reference_size(a: &MitsubaBenchArgs, scene: &Scene) -> Result<(u32, u32)> {
    let (w, h) = (scene.camera.width, scene.camera.height);
    if w % a.scale != 0 || h % a.scale != 0 {
        bail!(
            "--scale {}: does not divide the scene's {w} x {h} pixels",
            a.scale
        );
    }
    Ok((w / a.scale, h / a.scale))
}

/// --mask, read and checked against a width x height image.
pub(super) fn mask_of_size(
    a: &MitsubaBenchArgs,
    width: u32,
    height: u32,
) -> Result<Option<(PathBuf, Vec<bool>)>> {
    let blank = Image {
        width,
        height,
        pixels: vec![[0.0; 3]; (width * height) as usize],
    };
    a.mask.as_ref().map(|m| checked_mask(m, &blank)).transpose()
}

/// The mask at `m`, which must be `image`'s size and keep some pixel.
fn checked_mask(m: &Path, image: &Image) -> Result<(PathBuf, Vec<bool>)> {
    let keep = read_mask(m, image)?;
    if !keep.contains(&true) {
        bail!("--mask {}: keeps no pixel", m.display());
    }
    Ok((m.to_path_buf(), keep))
}

/// The reference as Mitsuba's path tracer makes it (--mitsuba-reference):
/// two runs with distinct seeds, averaged, written as `reference.exr`; its
/// relative noise is half the RMSE between the runs over the mean, on the
/// mask's pixels.
pub(super) fn mitsuba_target(
    a: &MitsubaBenchArgs,
    dir: &Path,
    mask: Option<(PathBuf, Vec<bool>)>,
    progress: &dyn Fn(&str),
) -> Result<(Target, u32)> {
    let seconds = a.mitsuba_reference.expect("only with --mitsuba-reference");
    let mut halves = Vec::new();
    for half in 0..2u32 {
        progress(&format!(
            "reference: Mitsuba path, run {} of 2, {seconds:.1} s",
            half + 1
        ));
        let ((_, _, image), _) =
            render_mitsuba(a, dir, "path", seconds, &[], REFERENCE_SEEDS * (half + 1))?;
        halves.push(image);
    }
    let mut image = halves[0].clone();
    for (p, q) in image.pixels.iter_mut().zip(&halves[1].pixels) {
        for c in 0..3 {
            p[c] = 0.5 * (p[c] + q[c]);
        }
    }
    let keep = |i: usize| mask.as_ref().is_none_or(|m| m.1[i]);
    let (mut squared, mut sum, mut n) = (0.0f64, 0.0f64, 0usize);
    for (i, (p, q)) in halves[0].pixels.iter().zip(&halves[1].pixels).enumerate() {
        if keep(i) {
            for c in 0..3 {
                squared += f64::from(p[c] - q[c]).powi(2);
                sum += 0.5 * f64::from(p[c] + q[c]);
            }
            n += 3;
        }
    }
    let noise = 0.5 * (squared / n as f64).sqrt() / (sum / n as f64);
    // The two runs too: their per-pixel difference is the reference's noise.
    let path = dir.join("reference.exr");
    let (run1, run2) = (
        dir.join("reference_run1.exr"),
        dir.join("reference_run2.exr"),
    );
    let bytes = [
        image.exr_bytes()?,
        halves[0].exr_bytes()?,
        halves[1].exr_bytes()?,
    ];
    write_all_atomically(&[(&path, &bytes[0]), (&run1, &bytes[1]), (&run2, &bytes[2])])?;
    Ok((
        Target {
            path,
            kind: "Mitsuba path reference",
            image,
            mask,
            noise: Some(noise),
        },
        a.scale,
    ))
}

/// `--region`'s rectangles at the reference's `width` x `height`, each less
/// what the mask leaves out; refused when one lies outside the image or
/// keeps no pixel.
pub(super) fn regions(
    a: &MitsubaBenchArgs,
    size: (u32, u32),
    mask: Option<&[bool]>,
) -> Result<Vec<Region>> {
    masked_rectangles(&a.region, size, mask).map_err(|e| anyhow::anyhow!("{e} of the reference"))
}

/// The reference runs' first seeds: far from the benchmark's own (0..).
const REFERENCE_SEEDS: u32 = 1 << 20;

/// The truth's relative noise (full-size image) from its noise.json.
fn truth_noise(name: &str) -> Option<f64> {
    let text = std::fs::read_to_string(Path::new(TRUTH).join("noise.json")).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v[name]["rel_rmse_estimate_full"].as_f64()
}

/// Where rows are written and what they are compared with.
pub(super) struct Bench<'a> {
    pub(super) dir: &'a Path,
    pub(super) target: &'a Target,
    pub(super) regions: &'a [Region],
    pub(super) width: u32,
    pub(super) height: u32,
}

impl Bench<'_> {
    /// `image` compared with the target and written as `<stem>.png`
    /// (and `<stem>.exr` when `exr`).
    fn measure(&self, image: &Image, stem: &str, exr: bool) -> Result<(Metrics, String)> {
        let m = self.target.compare(image)?;
        let file = format!("{stem}.png");
        write_atomically(&self.dir.join(&file), &image.png_bytes()?)?;
        if exr {
            write_atomically(&self.dir.join(format!("{stem}.exr")), &image.exr_bytes()?)?;
        }
        Ok((m, file))
    }

    /// A row: `image`, taken in (seconds, samples), compared and written.
    pub(super) fn row(
        &self,
        renderer: &str,
        budget: Option<f64>,
        (seconds, samples, image): &Taken,
        photons: Option<u64>,
        stem: &str,
    ) -> Result<Row> {
        let (m, file) = self.measure(image, stem, true)?;
        let pixels = self.width as f64 * self.height as f64;
        Ok(Row {
            renderer: renderer.into(),
            budget,
            seconds: *seconds,
            samples: *samples,
            paths_per_second: *samples as f64 * pixels / seconds,
            photons_per_second: photons.map(|p| p as f64 / seconds),
            rel_rmse: m.rel_rmse,
            energy: m.energy,
            rel_mse: m.rel_mse,
            rmse: m.rmse,
            regions: region_energies(self.regions, image, &self.target.image),
            image: file,
        })
    }

    /// A curve: the images along a run, then its final row.
    pub(super) fn curve(
        &self,
        renderer: &str,
        stem: &str,
        along: &[Taken],
        last: &Row,
    ) -> Result<Curve> {
        let mut points = Vec::new();
        for (i, (seconds, samples, image)) in along.iter().enumerate() {
            let (m, file) = self.measure(image, &format!("{stem}_at{i}"), false)?;
            points.push(CurvePoint {
                seconds: *seconds,
                samples: *samples,
                rel_rmse: m.rel_rmse,
                energy: m.energy,
                rel_mse: m.rel_mse,
                image: file,
            });
        }
        points.push(CurvePoint {
            seconds: last.seconds,
            samples: last.samples,
            rel_rmse: last.rel_rmse,
            energy: last.energy,
            rel_mse: last.rel_mse,
            image: last.image.clone(),
        });
        Ok(Curve {
            renderer: renderer.into(),
            points,
        })
    }
}
