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
