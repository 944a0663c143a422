//! The two headless paths, EGL surfaceless and OSMesa, give the same llvmpipe:
//! the same seed renders the same image bit for bit through either. A missing
//! OSMesa library is a clear error naming the package.

use crate::common;

use std::process::Command;

use photonmap::gpu::{Gpu, Platform};
use photonmap::render::{render, Image, RenderOptions};

fn photonmap() -> Command {
    Command::new(env!("CARGO_BIN_EXE_photonmap"))
}

/// A paper scene at 1/8 size on a fresh context of `platform`, in a thread of
/// its own (a thread holds one current context).
fn render_on(platform: Platform, name: &'static str) -> Image {
    std::thread::spawn(move || {
        let gpu = Gpu::new(platform).expect("the platform gives a GL 4.5 context");
        assert_eq!(
            gpu.capabilities().platform,
            platform.name(),
            "the context is on the platform asked for"
        );
        let scene = common::paper_scene(name);
        let mut o = RenderOptions::for_scene(&scene);
        (o.width, o.height, o.seed) = (scene.camera.width / 8, scene.camera.height / 8, 5);
        render(&gpu, &scene, &o, &mut ()).unwrap().image
    })
    .join()
    .unwrap()
}

#[test]
fn osmesa_and_egl_surfaceless_render_the_paper_scenes_bit_identical() {
    for name in ["glass_ball", "ring", "cornell_box"] {
        let a = render_on(Platform::Osmesa, name);
        let b = render_on(Platform::EglSurfaceless, name);
        assert!(a.mean()[0] > 0.0, "{name}: a lit image");
        let differing = a
            .pixels
            .iter()
            .flatten()
            .zip(b.pixels.iter().flatten())
            .filter(|(x, y)| x.to_bits() != y.to_bits())
            .count();
        assert_eq!(
            differing, 0,
            "{name}: channels that differ between the platforms"
        );
    }
}

#[test]
fn info_names_the_osmesa_platform_and_its_limits() {
    let out = photonmap()
        .args(["info", "--platform", "osmesa", "--json"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["platform"], "osmesa");
    assert!(
        v["gl_renderer"].as_str().unwrap().contains("llvmpipe"),
        "{v}"
    );
    assert!(v["max_texture_size"].as_i64().unwrap() >= 8192, "{v}");
    assert_eq!(v["stencil_bits"], 8);
    let text = photonmap()
        .args(["info", "--platform", "osmesa"])
        .output()
        .unwrap();
    assert!(String::from_utf8_lossy(&text.stdout).contains("platform          osmesa"));
}

#[test]
fn a_missing_osmesa_library_is_a_clear_error() {
    let out = photonmap()
        .args(["info", "--platform", "osmesa"])
        .env("PHOTONMAP_OSMESA_LIBRARY", "/nonexistent/libOSMesa.so.8")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("/nonexistent/libOSMesa.so.8") && err.contains("libosmesa6"),
        "{err}"
    );
    assert!(!err.contains("panicked"), "{err}");
}

#[test]
fn the_same_render_command_writes_identical_files_on_both_platforms() {
    let d = std::env::temp_dir().join(format!("photonmap-platforms-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    for platform in ["osmesa", "egl-surfaceless"] {
        let out = photonmap()
            .args([
                "render",
                "scenes/ring.toml",
                "--quiet",
                "--width",
                "96",
                "--height",
                "64",
            ])
            .args(["--platform", platform, "-o"])
            .arg(d.join(format!("{platform}.png")))
            .current_dir(common::root())
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let a = std::fs::read(d.join("osmesa.png")).unwrap();
    let b = std::fs::read(d.join("egl-surfaceless.png")).unwrap();
    assert_eq!(a, b, "the PNG files differ");
    let _ = std::fs::remove_dir_all(&d);
}
