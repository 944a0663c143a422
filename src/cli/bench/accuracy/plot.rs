//! `bench accuracy`'s pictures and CSV: the bias map, the table of runs, and
//! RMSE against seconds as SVG and PNG.

use photonmap::render::{IgiOptions, Image};

use super::report::{AccuracyReport, AccuracyRun, RunMethod};

/// Where `mean` is biased against `reference`: the reference in dim grey,
/// turning red where the mean is brighter and blue where it is darker, fully
/// at a luminance difference of the returned scale (half the reference's
/// mean luminance).
pub(super) fn bias_map(mean: &Image, reference: &Image) -> (Image, f64) {
    let [wr, wg, wb] = photonmap::layout::LUMINANCE;
    let luminance = |p: &[f32; 3]| wr * p[0] + wg * p[1] + wb * p[2];
    let mean_luminance =
        reference.pixels.iter().map(luminance).sum::<f32>() / reference.pixels.len().max(1) as f32;
    let scale = if mean_luminance > 0.0 {
        0.5 * mean_luminance
    } else {
        1.0
    };
    let mut out = Image::new(reference.width, reference.height);
    for ((o, m), r) in out
        .pixels
        .iter_mut()
        .zip(&mean.pixels)
        .zip(&reference.pixels)
    {
        let grey = 0.15 * (luminance(r) / (4.0 * scale)).clamp(0.0, 1.0);
        let d = (luminance(m) - luminance(r)) / scale;
        let t = d.abs().clamp(0.0, 1.0);
        let colour = if d > 0.0 {
            [1.0, 0.0, 0.0]
        } else {
            [0.0, 0.2, 1.0]
        };
        *o = colour.map(|c| grey * (1.0 - t) + c * t);
    }
    (out, scale as f64)
}

/// A CSV field in quotes, its quotes doubled: run labels hold commas.
pub fn csv_quoted(t: &str) -> String {
    format!("\"{}\"", t.replace('"', "\"\""))
}

pub fn csv(r: &AccuracyReport) -> String {
    let mut s = String::from("label,method,photons_stored,k,max_radius,leak,shadow_rays,build,grid,tile,spp,sppm_iterations,gather_rays,adaptive,vpl_paths,imperfect_visibility,interleave,downsample,seconds,rmse,bias_rmse,noise_rmse,rel_mse,ssim,pareto\n");
    for x in &r.runs {
        let igi = match &x.method {
            RunMethod::Igi(o) => o.clone(),
            _ => IgiOptions {
                vpl_paths: 0,
                interleave: 1,
                ..IgiOptions::default()
            },
        };
        let (sppm_iterations, gather_rays) = match x.method {
            RunMethod::Sppm { sppm_iterations } => (sppm_iterations, 0),
            RunMethod::FinalGather { gather_rays } => (0, gather_rays),
            RunMethod::Radiosity(ref o) => (0, o.gather_rays),
            _ => (0, 0),
        };
        s += &format!(
            "{},{},{},{},{},{:?},{},{:?},{:?},{},{},{},{},{},{},{},{},{},{:.4},{:.6},{:.6},{:.6},{:.6},{:.6},{}\n",
            csv_quoted(&x.label),
            x.method.name(),
            x.photons_stored,
            x.k,
            x.max_radius,
            x.leak,
            x.shadow_rays,
            x.build,
            x.grid,
            x.tile,
            x.spp,
            sppm_iterations,
            gather_rays,
            x.adaptive,
            igi.vpl_paths,
            igi.imperfect_visibility,
            igi.interleave,
            igi.downsample,
            x.seconds,
            x.rmse,
            x.bias_rmse,
            x.noise_rmse,
            x.rel_mse,
            x.ssim,
            x.on_pareto_front
        );
    }
    s
}

/// Each run's log10 seconds and log10 RMSE (floored above zero): the points
/// both plots draw.
fn log_points(r: &AccuracyReport) -> (Vec<f64>, Vec<f64>) {
    let xs = r.runs.iter().map(|x| x.seconds.max(1e-4).log10());
    let ys = r.runs.iter().map(|x| x.rmse.max(1e-9).log10());
    (xs.collect(), ys.collect())
}

/// RMSE against seconds, log-log, the Pareto front joined.
pub fn svg_plot(r: &AccuracyReport) -> String {
    let mut plot = crate::cli::bench::plot::LogLog::new(
        &format!(
            "{}: RMSE against the SPPM reference, by run time (log-log)",
            r.scene
        ),
        "seconds per render (wall clock)",
        "RMSE of one render (bias and noise)",
    );
    let point = |x: &AccuracyRun| (x.seconds, x.rmse, x.label.clone());
    let front = r
        .runs
        .iter()
        .filter(|x| x.on_pareto_front)
        .map(point)
        .collect();
    plot.points("#d62728", front, true);
    for (method, colour) in [
        ("sppm", "#2ca02c"),
        ("igi", "#9467bd"),
        ("differentials", "#ff7f0e"),
        ("radiosity", "#8c564b"),
        ("photon map", "#1f77b4"),
    ] {
        let kind = |m: &str| match m {
            "sppm" | "igi" | "differentials" | "radiosity" => m.to_string(),
            _ => "photon map".into(),
        };
        let others = r
            .runs
            .iter()
            .filter(|x| !x.on_pareto_front && kind(x.method.name()) == method)
            .map(point)
            .collect();
        plot.points(colour, others, false);
    }
    plot.svg()
}

/// The same plot as a PNG: points and the front on log-log axes (no text; the SVG has the labels).
pub fn png_plot(r: &AccuracyReport) -> Vec<u8> {
    let (w, h, m) = (480u32, 320u32, 30.0f64);
    let mut img = image::RgbImage::from_pixel(w, h, image::Rgb([255, 255, 255]));
    let (xs, ys) = log_points(r);
    let (x0, x1) = (
        xs.iter().copied().fold(f64::INFINITY, f64::min) - 0.1,
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.1,
    );
    let (y0, y1) = (
        ys.iter().copied().fold(f64::INFINITY, f64::min) - 0.1,
        ys.iter().copied().fold(f64::NEG_INFINITY, f64::max) + 0.1,
    );
    let px = |x: f64| (m + (x - x0) / (x1 - x0) * (w as f64 - 2.0 * m)) as i64;
    let py = |y: f64| (h as f64 - m - (y - y0) / (y1 - y0) * (h as f64 - 2.0 * m)) as i64;
    let mut put = |x: i64, y: i64, c: [u8; 3]| {
        if x >= 0 && y >= 0 && (x as u32) < w && (y as u32) < h {
            img.put_pixel(x as u32, y as u32, image::Rgb(c));
        }
    };
    for x in m as i64..(w as i64 - m as i64) {
        put(x, h as i64 - m as i64, [0, 0, 0]);
    }
    for y in m as i64..(h as i64 - m as i64) {
        put(m as i64, y, [0, 0, 0]);
    }
    let mut front: Vec<usize> = (0..r.runs.len())
        .filter(|&i| r.runs[i].on_pareto_front)
        .collect();
    front.sort_by(|&a, &b| xs[a].total_cmp(&xs[b]));
    for pair in front.windows(2) {
        let (ax, ay, bx, by) = (
            px(xs[pair[0]]),
            py(ys[pair[0]]),
            px(xs[pair[1]]),
            py(ys[pair[1]]),
        );
        let steps = (bx - ax).abs().max((by - ay).abs()).max(1);
        for t in 0..=steps {
            put(
                ax + (bx - ax) * t / steps,
                ay + (by - ay) * t / steps,
                [214, 39, 40],
            );
        }
    }
    for (i, run) in r.runs.iter().enumerate() {
        let c = match (run.on_pareto_front, run.method.name()) {
            (true, _) => [214, 39, 40],
            (false, "sppm") => [44, 160, 44],
            (false, "igi") => [148, 103, 189],
            (false, "differentials") => [255, 127, 14],
            (false, "radiosity") => [140, 86, 75],
            _ => [31, 119, 180],
        };
        for dy in -3..=3i64 {
            for dx in -3..=3i64 {
                if dx * dx + dy * dy <= 9 {
                    put(px(xs[i]) + dx, py(ys[i]) + dy, c);
                }
            }
        }
    }
    let mut out = std::io::Cursor::new(Vec::new());
    img.write_to(&mut out, image::ImageFormat::Png)
        .expect("encoding a PNG in memory");
    out.into_inner()
}
