//! The two headless paths, EGL surfaceless and OSMesa, give the same llvmpipe:
//! the same seed renders the same image bit for bit through either. A missing
//! OSMesa library is a clear error naming the package.

use crate::common::{self, OwnGpu, Printed, Run};

use photonmap::gpu::Platform;
use photonmap::render::{render, Image, RenderOptions};

/// A paper scene at 1/8 size on a fresh context of `platform`, in a thread of
/// its own (a thread holds one current context).
fn render_on(platform: Platform, name: &'static str) -> Image {
    std::thread::spawn(move || {
        let gpu = OwnGpu::new(platform).expect("the platform gives a GL 4.5 context");
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
    let _turn = common::rendering_turn();
    for name in ["glass_ball", "ring", "cornell_box"] {
        let a = render_on(Platform::Osmesa, name);
        let b = render_on(Platform::EglSurfaceless, name);
        assert!(a.mean()[0] > 0.0, "{name}: a lit image");
        let differing = common::channels_differing(&a, &b);
        assert_eq!(
            differing, 0,
            "{name}: channels that differ between the platforms"
        );
    }
}

#[test]
fn info_names_the_osmesa_platform_and_its_limits() {
    let v = Run::new(["info", "--platform", "osmesa", "--json"]).json();
    assert_eq!(v["platform"], "osmesa");
    assert!(
        v["gl_renderer"].as_str().unwrap().contains("llvmpipe"),
        "{v}"
    );
    assert!(v["max_texture_size"].as_i64().unwrap() >= 8192, "{v}");
    assert_eq!(v["stencil_bits"], 8);
    let text = Run::new(["info", "--platform", "osmesa"]).run();
    assert!(text.stdout_text().contains("platform          osmesa"));
}

#[test]
fn a_missing_osmesa_library_is_a_clear_error() {
    let err = Run::new(["info", "--platform", "osmesa"])
        .env("PHOTONMAP_OSMESA_LIBRARY", "/nonexistent/libOSMesa.so.8")
        .refused_with("/nonexistent/libOSMesa.so.8");
    assert!(err.contains("libosmesa6"), "{err}");
}

#[test]
fn the_same_render_command_writes_identical_files_on_both_platforms() {
    let d = common::TempDir::new("platforms");
    for platform in ["osmesa", "egl-surfaceless"] {
        Run::new(["render", "scenes/ring.toml", "--quiet"])
            .args(["--width", "96", "--height", "64", "--platform", platform])
            .output_to(d.join(format!("{platform}.png")))
            .in_dir(common::root())
            .succeeds();
    }
    let a = std::fs::read(d.join("osmesa.png")).unwrap();
    let b = std::fs::read(d.join("egl-surfaceless.png")).unwrap();
    assert_eq!(a, b, "the PNG files differ");
}
