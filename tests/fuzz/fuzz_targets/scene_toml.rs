//! cargo fuzz target: scene TOML loading never panics, and what loads is finite.
#![no_main]
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        if let Ok(scene) = photonmap::scene::load_scene_str(text, std::path::Path::new("fuzz.toml")) {
            assert!(scene.camera.position.is_finite() && scene.photon_map.max_radius.is_finite());
            assert!(scene.size().is_finite());
        }
    }
});
