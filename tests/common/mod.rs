#![allow(dead_code)]
//! Helpers shared by the integration tests, in one place for every test
//! binary: the GL context (`context`), scratch folders (`temp`), the built
//! binary run as a user runs it (`run`), scenes (the paper's and the test
//! fixtures in scenes/tests/), image metrics and the one random source.

pub mod browser;
mod context;
mod run;
mod temp;

use std::path::{Path, PathBuf};

use photonmap::gpu::Gpu;
use photonmap::render::Image;
use photonmap::scene::{load_scene, Scene};

mod moved_text;
mod rng;

// Every test binary compiles this module; none uses all of it.
#[allow(unused_imports)]
pub use context::{gpu, rendering_turn, OwnGpu};
#[allow(unused_imports)]
pub use moved_text::moved_scene_text;
#[allow(unused_imports)]
pub use rng::Rng;
#[allow(unused_imports)]
pub use run::{Printed, Run};
#[allow(unused_imports)]
pub use temp::TempDir;

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// scenes/<name>.toml (`ring`, `variants/...`, `tests/...`).
pub fn scene_file(name: &str) -> PathBuf {
    root().join("scenes").join(format!("{name}.toml"))
}

pub fn paper_scene(name: &str) -> Scene {
    load_scene(&scene_file(name)).expect("paper scene loads")
}

/// A test scene of scenes/tests/ by name: `fixture_file("mirror_box")`.
pub fn fixture_file(name: &str) -> PathBuf {
    scene_file(&format!("tests/{name}"))
}

pub fn fixture_text(name: &str) -> String {
    let file = fixture_file(name);
    std::fs::read_to_string(&file).unwrap_or_else(|e| panic!("{}: {e}", file.display()))
}

pub fn fixture(name: &str) -> Scene {
    load_scene(&fixture_file(name)).unwrap_or_else(|e| panic!("{e}"))
}

/// `text` with `from`, which it must hold exactly once, replaced by `to`: a
/// variant of a scene file, edited as a user would edit it.
pub fn replace_once(text: &str, from: &str, to: &str) -> String {
    assert_eq!(text.matches(from).count(), 1, "'{from}' once in: {text}");
    text.replacen(from, to, 1)
}

/// Root-mean-square difference over all channels (sizes must match).
pub fn rmse(a: &Image, b: &Image) -> f64 {
    photonmap::metrics::rmse(a, b).unwrap()
}

/// How many channels of two images differ in any bit (sizes must match).
/// Pixels of `img` exactly `value` (an emitter seen directly shows its own radiance).
pub fn pixels_equal_to(img: &Image, value: [f32; 3]) -> usize {
    img.pixels.iter().filter(|p| **p == value).count()
}

pub fn channels_differing(a: &Image, b: &Image) -> usize {
    a.pixels
        .iter()
        .flatten()
        .zip(b.pixels.iter().flatten())
        .filter(|(x, y)| x.to_bits() != y.to_bits())
        .count()
}

pub fn write_exr(path: &Path, img: &Image) {
    photonmap::image::write_atomically(path, &img.exr_bytes().unwrap()).unwrap();
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
    let (bw, bh) = (a[0].width / block, a[0].height / block);
    let blocks = (0..bh).flat_map(|by| (0..bw).map(move |bx| (bx, by)));
    chi2_over_blocks(
        blocks.map(|(bx, by)| (seed_stats(a, block, bx, by), seed_stats(b, block, bx, by))),
        n,
    )
}

/// `block_chi2` of A's seeds against a reference made of two independent
/// runs (Mitsuba's, `bench mitsuba --mitsuba-reference`): per block, the
/// runs' mean, and the variance of that mean from their difference,
/// (r1 - r2)^2 / 4. The bound is block_chi2's from A's seeds alone; it holds
/// where the reference's noise is small beside A's, and adding the
/// reference's variance to each block's only loosens the test.
pub fn block_chi2_against_runs(a: &[Image], runs: [&Image; 2], block: u32) -> (f64, usize, f64) {
    let (bw, bh) = (a[0].width / block, a[0].height / block);
    let blocks = (0..bh).flat_map(|by| (0..bw).map(move |bx| (bx, by)));
    chi2_over_blocks(
        blocks.map(|(bx, by)| {
            let (r1, r2) = (
                block_mean(runs[0], block, bx, by),
                block_mean(runs[1], block, bx, by),
            );
            (
                seed_stats(a, block, bx, by),
                (0.5 * (r1 + r2), (r1 - r2).powi(2) / 4.0),
            )
        }),
        a.len(),
    )
}

/// The mean over a block's pixels and channels.
pub fn block_mean(img: &Image, block: u32, bx: u32, by: u32) -> f64 {
    let mut s = 0.0f64;
    for y in by * block..(by + 1) * block {
        for x in bx * block..(bx + 1) * block {
            s += img.get(x, y).iter().map(|&v| v as f64).sum::<f64>() / 3.0;
        }
    }
    s / (block * block) as f64
}

/// A block's mean over seeds, and the variance of that mean (from the seeds' spread).
fn seed_stats(imgs: &[Image], block: u32, bx: u32, by: u32) -> (f64, f64) {
    let v: Vec<f64> = imgs.iter().map(|i| block_mean(i, block, bx, by)).collect();
    let m = v.iter().sum::<f64>() / v.len() as f64;
    let var = v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (v.len() - 1) as f64;
    (m, var / v.len() as f64)
}

/// Sum of t^2 / blocks over ((mean, variance of the mean) of A, of B) per
/// block, the blocks counted, and the bound derived for n seeds a side.
fn chi2_over_blocks(
    stats: impl Iterator<Item = ((f64, f64), (f64, f64))>,
    n: usize,
) -> (f64, usize, f64) {
    assert!(
        n >= 6,
        "at least 6 seeds a side (F(1, n - 1) needs n - 1 > 4)"
    );
    let (mut chi2, mut blocks) = (0.0, 0usize);
    for ((ma, va), (mb, vb)) in stats {
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
    let v = (n - 1) as f64;
    let mean = v / (v - 2.0);
    let var = 2.0 * v * v * (v - 1.0) / ((v - 2.0).powi(2) * (v - 4.0));
    let bound = mean + 4.0 * (var / blocks as f64).sqrt();
    (chi2 / blocks as f64, blocks, bound)
}

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

/// Runs glsl/test/intersect_twin.frag in `mode` on `textures`' scene over
/// rays, one texel each in rows of `width`: `[origins, directions, normals]`
/// (the normals only some modes read); returns each ray's output texel.
pub fn intersect_twin(
    gpu: &Gpu,
    textures: &photonmap::scene::pack::SceneTextures,
    width: u32,
    [origins, directions, normals]: [&[[f32; 4]]; 3],
    mode: i32,
) -> Vec<[f32; 4]> {
    use photonmap::gpu::{DrawState, Program, Target, TexFormat, Texture};
    let n = origins.len();
    let height = n.div_ceil(width as usize) as u32;
    let upload = |texels: &[[f32; 4]]| {
        let mut d: Vec<f32> = texels.iter().flatten().copied().collect();
        d.resize((width * height * 4) as usize, 0.0);
        Texture::from_texels(gpu, width, height, TexFormat::Rgba32F, &d).unwrap()
    };
    let (to, td, tn) = (upload(origins), upload(directions), upload(normals));
    let out = Texture::new(gpu, width, height, TexFormat::Rgba32F).unwrap();
    let target = Target::new(gpu, &[&out]).unwrap();
    let program = Program::fullscreen(gpu, "test/intersect_twin.frag").unwrap();
    let mut b = program.bind();
    textures.bind(&mut b);
    b.texture("u_ray_origin", &to)
        .texture("u_ray_direction", &td)
        .texture("u_ray_normal", &tn)
        .int("u_primitive", 0)
        .int("u_mode", mode)
        .draw_fullscreen(&target, &DrawState::PLAIN)
        .unwrap();
    texels(&out).into_iter().take(n).collect()
}

/// A point or vector as an RGBA texel (w = 0).
pub fn texel(v: glam::Vec3) -> [f32; 4] {
    [v.x, v.y, v.z, 0.0]
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

/// A frame's first diffuse hits read back: the image's size, and each
/// pixel's position (w > 0 where a hit), normal (w = material + 1) and
/// throughput (w = the primitive).
pub struct FirstHits {
    pub width: u32,
    pub height: u32,
    pub position: Vec<[f32; 4]>,
    pub normal: Vec<[f32; 4]>,
    pub throughput: Vec<[f32; 4]>,
}

pub fn first_hits(direct: &photonmap::render::DirectLight) -> FirstHits {
    FirstHits {
        width: direct.diffuse_position.width,
        height: direct.diffuse_position.height,
        position: texels(&direct.diffuse_position),
        normal: texels(&direct.diffuse_normal),
        throughput: texels(&direct.diffuse_throughput),
    }
}

/// Every file under `path` (a file, or a folder walked whole) has the mode
/// that `File::create` gives under `umask`: 0666 less the mask. Returns how
/// many files it checked.
pub fn assert_output_modes(path: &Path, umask: u32) -> usize {
    use std::os::unix::fs::PermissionsExt;
    let meta = std::fs::metadata(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if meta.is_dir() {
        let entries = std::fs::read_dir(path).unwrap().flatten();
        return entries.map(|e| assert_output_modes(&e.path(), umask)).sum();
    }
    let mode = meta.permissions().mode() & 0o777;
    assert_eq!(
        mode,
        0o666 & !umask,
        "{} is {mode:03o} under umask {umask:03o}",
        path.display()
    );
    1
}
