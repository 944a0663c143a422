//! cargo fuzz target: a scene with a mesh from fuzzed OBJ bytes never panics,
//! and every triangle it accepts is finite.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let dir = std::env::temp_dir().join(format!("photonmap-cargo-fuzz-{}", std::process::id()));
    let _ = std::fs::create_dir_all(&dir);
    let scene = "[camera]\nposition = [0.0, 1.0, 3.0]\nlook_at = [0.0, 0.0, 0.0]\nvfov = 40.0\nwidth = 8\nheight = 8\n[materials]\nm = { type = \"diffuse\", albedo = [0.5, 0.5, 0.5] }\n[[shape]]\ntype = \"mesh\"\nfile = \"fuzz.obj\"\nmaterial = \"m\"\n[[light]]\ntype = \"point\"\nposition = [0.0, 3.0, 0.0]\nintensity = [1.0, 1.0, 1.0]\n";
    if std::fs::write(dir.join("scene.toml"), scene).is_err() || std::fs::write(dir.join("fuzz.obj"), data).is_err() {
        return;
    }
    if let Ok(s) = photonmap::scene::load_scene(&dir.join("scene.toml")) {
        for shape in &s.shapes {
            if let photonmap::scene::Geometry::Triangle { v0, v1, v2 } = shape.geometry {
                assert!(v0.is_finite() && v1.is_finite() && v2.is_finite());
            }
        }
    }
});
