#![allow(dead_code)]
//! Helpers shared by the integration tests: a real GL context on whatever EGL
//! offers (Mesa llvmpipe on CI), scenes, and image metrics.

use std::path::{Path, PathBuf};

use photonmap::gpu::{Gpu, Platform};
use photonmap::render::Image;
use photonmap::scene::{load_scene, Scene};

mod moved_text;
mod rng;

// Not every test uses every helper (as with `dead_code` above).
#[allow(unused_imports)]
pub use moved_text::moved_scene_text;
#[allow(unused_imports)]
pub use rng::Rng;

pub fn gpu() -> Gpu {
    Gpu::new(Platform::Auto).expect("a GL 4 context (install libegl1 libegl-mesa0 libgl1-mesa-dri)")
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn paper_scene(name: &str) -> Scene {
    load_scene(&root().join("scenes").join(format!("{name}.toml"))).expect("paper scene loads")
}

/// Root-mean-square difference over all channels (sizes must match).
pub fn rmse(a: &Image, b: &Image) -> f64 {
    photonmap::metrics::rmse(a, b).unwrap()
}

pub fn write_exr(path: &Path, img: &Image) {
    photonmap::image::write_atomically(path, &img.exr_bytes().unwrap()).unwrap();
}

/// A fresh folder under the system's temporary directory for this test run.
pub fn tempdir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("photonmap-{}-{name}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Writes a UV sphere of about `triangles` triangles (unit radius, outward
/// winding) as OBJ to `path`, with its exact normals (the normalised
/// positions) as `vn` when `normals`.
pub fn write_sphere_obj(path: &Path, triangles: usize, normals: bool) {
    let m = photonmap::scene::generate::uv_sphere(triangles, 0.0);
    let n = m.radial_normals();
    std::fs::write(path, m.obj_text(normals.then_some(n.as_slice()))).unwrap();
}

/// Two renderers' images over seeds, compared block by block: each seed's
/// image is cut into `block` x `block` pixel blocks and each block's mean
/// (over its pixels and channels) taken; per block, t is the difference of
/// the means over A's seeds and over B's, over its standard error (from the
/// seed-to-seed variance of each). Returns (sum of t^2 / blocks, blocks, the bound that
/// sum may reach when A and B have one expectation).
///
/// The bound is derived, not chosen: with n seeds a side, t^2 is at worst
/// F(1, n - 1) distributed (Welch's t with the fewest degrees of freedom),
/// of mean v / (v - 2) and variance 2 v^2 (v - 1) / ((v - 2)^2 (v - 4)),
/// v = n - 1; the mean over B blocks may exceed its mean by 4 of its
/// standard deviations (sd / sqrt(B), blocks taken as independent).
pub fn block_chi2(a: &[Image], b: &[Image], block: u32) -> (f64, usize, f64) {
    let n = a.len().min(b.len());
    assert!(
        n >= 6,
        "at least 6 seeds a side (F(1, n - 1) needs n - 1 > 4)"
    );
    let (w, h) = (a[0].width, a[0].height);
    let (bw, bh) = (w / block, h / block);
    let value = |img: &Image, bx: u32, by: u32| {
        let mut s = 0.0f64;
        for y in by * block..(by + 1) * block {
            for x in bx * block..(bx + 1) * block {
                s += img.get(x, y).iter().map(|&v| v as f64).sum::<f64>() / 3.0;
            }
        }
        s / (block * block) as f64
    };
    let stats = |imgs: &[Image], bx: u32, by: u32| {
        let v: Vec<f64> = imgs.iter().map(|i| value(i, bx, by)).collect();
        let m = v.iter().sum::<f64>() / v.len() as f64;
        let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
        (m, var / v.len() as f64)
    };
    let (mut chi2, mut blocks) = (0.0, 0usize);
    for by in 0..bh {
        for bx in 0..bw {
            let (ma, va) = stats(a, bx, by);
            let (mb, vb) = stats(b, bx, by);
            if va + vb == 0.0 {
                // Noiseless (an emitter seen directly): equal, or as far
                // apart as can be.
                if ma != mb {
                    chi2 = f64::INFINITY;
                }
                continue;
            }
            chi2 += (ma - mb).powi(2) / (va + vb);
            blocks += 1;
        }
    }
    let v = (n - 1) as f64;
    let mean = v / (v - 2.0);
    let var = 2.0 * v * v * (v - 1.0) / ((v - 2.0).powi(2) * (v - 4.0));
    let bound = mean + 4.0 * (var / blocks as f64).sqrt();
    (chi2 / blocks as f64, blocks, bound)
}

/// A closed box with a mirror ball and a glass ball (gather rays follow both),
/// a point light and an area light.
pub const MIRROR_BOX: &str = r#"
[camera]
position = [0.5, 0.5, 1.4]
look_at = [0.5, 0.45, 0.0]
vfov = 55.0
width = 24
height = 24
[render]
shadow_rays = 4
max_specular_depth = 6
[photon_map]
photons_stored = 20000
grid_resolution = [16, 16, 24]
k = 40
max_radius = 0.15
[materials]
white = { type = "diffuse", albedo = [0.7, 0.7, 0.7] }
red = { type = "diffuse", albedo = [0.7, 0.2, 0.2] }
mirror = { type = "mirror", reflectance = [0.9, 0.9, 0.9] }
glass = { type = "glass", ior = 1.5 }
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 0.0]
edge1 = [0.0, 0.0, 1.5]
edge2 = [1.0, 0.0, 0.0]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 1.0, 0.0]
edge1 = [1.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 1.5]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 0.0]
edge1 = [1.0, 0.0, 0.0]
edge2 = [0.0, 1.0, 0.0]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 1.5]
edge1 = [0.0, 1.0, 0.0]
edge2 = [1.0, 0.0, 0.0]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 0.0]
edge1 = [0.0, 1.0, 0.0]
edge2 = [0.0, 0.0, 1.5]
material = "red"
[[shape]]
type = "parallelogram"
corner = [1.0, 0.0, 0.0]
edge1 = [0.0, 0.0, 1.5]
edge2 = [0.0, 1.0, 0.0]
material = "white"
[[shape]]
type = "sphere"
center = [0.3, 0.2, 0.5]
radius = 0.18
material = "mirror"
[[shape]]
type = "sphere"
center = [0.72, 0.2, 0.6]
radius = 0.16
material = "glass"
[[light]]
type = "point"
position = [0.5, 0.85, 0.7]
intensity = [0.4, 0.4, 0.4]
[[light]]
type = "area"
corner = [0.4, 0.999, 0.4]
edge1 = [0.2, 0.0, 0.0]
edge2 = [0.0, 0.0, 0.2]
radiance = [5.0, 5.0, 5.0]
"#;

/// Photon frames with one frame of `records` photons at the given points.
pub fn frames_from_points(
    gpu: &Gpu,
    points: &[[f32; 3]],
    power: impl Fn(usize) -> [f32; 3],
) -> photonmap::photon::PhotonFrames {
    let n = points.len() as u32;
    let width = 64u32;
    let frame_height = n.div_ceil(width);
    let texels = (width * frame_height) as usize;
    let mut pos = vec![0f32; texels * 4];
    let mut pow = vec![0f32; texels * 4];
    let mut inc = vec![0f32; texels * 4];
    for (i, p) in points.iter().enumerate() {
        pos[4 * i..4 * i + 4].copy_from_slice(&[p[0], p[1], p[2], 0.0]);
        let q = power(i);
        pow[4 * i..4 * i + 4].copy_from_slice(&[q[0], q[1], q[2], 1.0]);
        inc[4 * i..4 * i + 4].copy_from_slice(&[0.0, -1.0, 0.0, 1.0]);
    }
    photonmap::photon::PhotonFrames::from_records(
        gpu,
        width,
        frame_height,
        1,
        &pos,
        &pow,
        &inc,
        width * frame_height,
    )
    .unwrap()
}

/// A texture read back as RGBA texels, in GL order.
pub fn texels(t: &photonmap::gpu::Texture) -> Vec<[f32; 4]> {
    t.read_f32()
        .chunks(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect()
}

/// A texel's rgb (xyz).
pub fn v3(t: [f32; 4]) -> glam::Vec3 {
    glam::Vec3::new(t[0], t[1], t[2])
}

/// A diffuse box with a point light and a small area light (the SPPM and IGI
/// tests against the CPU path tracer).
pub const TWO_LIGHT_BOX: &str = r#"
[camera]
position = [0.5, 0.5, 1.45]
look_at = [0.5, 0.45, 0.0]
vfov = 60.0
width = 32
height = 32
[photon_map]
max_radius = 0.08
[materials]
white = { type = "diffuse", albedo = [0.7, 0.7, 0.7] }
red = { type = "diffuse", albedo = [0.7, 0.2, 0.2] }
green = { type = "diffuse", albedo = [0.2, 0.6, 0.3] }
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 0.0]
edge1 = [1.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 1.5]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 1.0, 0.0]
edge1 = [0.0, 0.0, 1.5]
edge2 = [1.0, 0.0, 0.0]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 0.0]
edge1 = [0.0, 1.0, 0.0]
edge2 = [1.0, 0.0, 0.0]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 1.5]
edge1 = [1.0, 0.0, 0.0]
edge2 = [0.0, 1.0, 0.0]
material = "white"
[[shape]]
type = "parallelogram"
corner = [0.0, 0.0, 0.0]
edge1 = [0.0, 0.0, 1.5]
edge2 = [0.0, 1.0, 0.0]
material = "red"
[[shape]]
type = "parallelogram"
corner = [1.0, 0.0, 0.0]
edge1 = [0.0, 1.0, 0.0]
edge2 = [0.0, 0.0, 1.5]
material = "green"
[[light]]
type = "point"
position = [0.3, 0.7, 0.5]
intensity = [0.3, 0.3, 0.3]
[[light]]
type = "area"
corner = [0.6, 0.999, 0.4]
edge1 = [0.2, 0.0, 0.0]
edge2 = [0.0, 0.0, 0.2]
radiance = [6.0, 6.0, 6.0]
"#;

/// Two independent 32 x 32 renders against the CPU path tracer, block by
/// block over the interior 6 x 6 blocks of 4 x 4 pixels (the outer ring, the
/// walls' edges and corners, left out), in mean channel value: the z of each
/// block with the two runs' spread ((a - b)^2 / 4, their mean's variance in
/// expectation) and the tracer's own variance. Returns (blocks, chi^2/n,
/// largest relative difference).
pub fn blocks_against_path_tracer(
    pt: &photonmap::twins::path_trace::PathTraced,
    runs: [&photonmap::render::Image; 2],
) -> (usize, f64, f64) {
    let block = |f: &dyn Fn(usize) -> f64, bx: usize, by: usize| {
        let mut s = 0.0;
        for y in by * 4..by * 4 + 4 {
            for x in bx * 4..bx * 4 + 4 {
                s += f(y * 32 + x);
            }
        }
        s / 16.0
    };
    let lum = |p: [f64; 3]| (p[0] + p[1] + p[2]) / 3.0;
    let pix = |r: usize, i: usize| runs[r].pixels[i].iter().map(|&v| v as f64).sum::<f64>() / 3.0;
    let (mut worst, mut chi2, mut n) = (0f64, 0f64, 0);
    for by in 1..7 {
        for bx in 1..7 {
            let pt_mean = block(&|i| lum(pt.mean[i]), bx, by);
            let pt_var = block(&|i| lum(pt.variance_of_mean[i]), bx, by) / 16.0;
            let (a, b) = (block(&|i| pix(0, i), bx, by), block(&|i| pix(1, i), bx, by));
            let var = (a - b).powi(2) / 4.0;
            let z = (0.5 * (a + b) - pt_mean) / (pt_var + var).sqrt().max(1e-9);
            worst = worst.max((0.5 * (a + b) / pt_mean - 1.0).abs());
            chi2 += z * z;
            n += 1;
        }
    }
    (n, chi2 / n as f64, worst)
}
