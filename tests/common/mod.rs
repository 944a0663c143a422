#![allow(dead_code)]
//! Helpers shared by the integration tests: a real GL context on whatever EGL
//! offers (Mesa llvmpipe on CI), scenes, and image metrics.

use std::path::{Path, PathBuf};

use photonmap::gpu::{Gpu, Platform};
use photonmap::render::Image;
use photonmap::scene::{load_scene, Scene};

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

/// The keys whose values are points (read in f64 and rebased by the loader).
pub const POINT_KEYS: [&str; 8] = [
    "position",
    "look_at",
    "grid_min",
    "grid_max",
    "corner",
    "base",
    "center",
    "translate",
];

/// A scene file's text with every point written on one line as
/// `key = [x, y, z]` moved by `t`, as a user would move a scene by editing
/// its file; and how many points it moved.
pub fn moved_scene_text(text: &str, t: glam::DVec3) -> (String, usize) {
    let mut moved = 0;
    let lines: Vec<String> = text
        .lines()
        .map(|line| {
            let Some((key, value)) = line.split_once('=') else {
                return line.to_string();
            };
            let (value, comment) = value.split_once('#').unwrap_or((value, ""));
            let inner = value
                .trim()
                .strip_prefix('[')
                .and_then(|v| v.strip_suffix(']'));
            let (Some(inner), true) = (inner, POINT_KEYS.contains(&key.trim())) else {
                return line.to_string();
            };
            let p: Vec<f64> = inner
                .split(',')
                .map(|x| x.trim().parse().unwrap())
                .collect();
            assert_eq!(p.len(), 3, "{line}");
            moved += 1;
            let p = glam::DVec3::new(p[0], p[1], p[2]) + t;
            let comment = if comment.is_empty() {
                String::new()
            } else {
                format!(" #{comment}")
            };
            format!("{key}= [{:?}, {:?}, {:?}]{comment}", p.x, p.y, p.z)
        })
        .collect();
    (lines.join("\n") + "\n", moved)
}

/// The tests' one random source: xorshift64, reproducible from its seed.
pub struct Rng(pub u64);

impl Rng {
    pub fn next_u64(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    /// A whole number in 0..n (0 when n is 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.next_u64() % n.max(1) as u64) as usize
    }

    /// A double in [0, 1).
    pub fn f64(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// A unit vector, uniform on the sphere (by rejection from the cube).
    pub fn unit(&mut self) -> glam::DVec3 {
        loop {
            let v = glam::DVec3::new(
                self.f64() * 2.0 - 1.0,
                self.f64() * 2.0 - 1.0,
                self.f64() * 2.0 - 1.0,
            );
            let l = v.length();
            if l > 1e-3 && l <= 1.0 {
                return v / l;
            }
        }
    }
}
