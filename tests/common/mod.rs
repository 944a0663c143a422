#![allow(dead_code)]
//! Helpers shared by the integration tests: a real GL context on whatever EGL
//! offers (Mesa llvmpipe on CI), scenes, and image metrics.

use std::path::{Path, PathBuf};

use photonmap::gpu::{EglPlatform, Gpu};
use photonmap::render::Image;
use photonmap::scene::{load_scene, Scene};

pub fn gpu() -> Gpu {
    Gpu::new(EglPlatform::Auto)
        .expect("a GL 4 context (install libegl1 libegl-mesa0 libgl1-mesa-dri)")
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn paper_scene(name: &str) -> Scene {
    load_scene(&root().join("scenes").join(format!("{name}.toml"))).expect("paper scene loads")
}

/// Root-mean-square difference over all channels.
pub fn rmse(a: &Image, b: &Image) -> f64 {
    assert_eq!(
        (a.width, a.height),
        (b.width, b.height),
        "image sizes differ"
    );
    let mut s = 0f64;
    for (p, q) in a.pixels.iter().zip(&b.pixels) {
        for c in 0..3 {
            let d = p[c] as f64 - q[c] as f64;
            s += d * d;
        }
    }
    (s / (a.pixels.len() * 3) as f64).sqrt()
}

pub fn mean_image(images: &[Image]) -> Image {
    let mut out = Image::new(images[0].width, images[0].height);
    for img in images {
        for (o, p) in out.pixels.iter_mut().zip(&img.pixels) {
            for c in 0..3 {
                o[c] += p[c] / images.len() as f32;
            }
        }
    }
    out
}

pub fn write_exr(path: &Path, img: &Image) {
    photonmap::render::image::write_atomically(path, &img.exr_bytes().unwrap()).unwrap();
}
