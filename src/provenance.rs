//! What made an output: recorded in every `--json` report and every EXR
//! header, so an image or a number can be traced to the program, the scene
//! (and its exact text), the overrides, the seed and the driver.

/// The provenance of one run.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Provenance {
    pub program: String,
    pub version: String,
    /// The git commit the binary was built from, when it was built in a checkout.
    pub commit: Option<String>,
    /// The scene as given: a file path or an embedded scene's name.
    pub scene: String,
    /// FNV-1a (64-bit) of the scene file's text, in hex.
    pub scene_hash: String,
    /// `--set` overrides, as given.
    pub overrides: Vec<String>,
    pub method: String,
    /// FNV-1a (64-bit, hex) of the method's options as the run used them:
    /// two runs of one frame that differ in any option differ here.
    pub method_options: String,
    pub seed: u32,
    pub spp: u32,
    /// SPPM's iterations run (set once the render is done).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub iterations: Option<u32>,
    /// Photons emitted: SPPM's over all iterations, or the photons behind
    /// the photon map (or the footprints) of a frame render; set once the
    /// render is done, absent where no photons were traced.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub photons_emitted: Option<u64>,
    /// The frame's size (a crop's image is a part of it).
    pub width: u32,
    pub height: u32,
    /// A crop's pixels in the frame: x0, x1, y0, y1 (half-open, rows from
    /// the top); absent for the whole frame.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pixel_bounds: Option<[u32; 4]>,
    pub platform: String,
    pub renderer: String,
    pub gl_version: String,
}

impl Provenance {
    /// The program's own part; the rest is filled in by the run.
    pub fn program() -> Self {
        Self {
            program: env!("CARGO_PKG_NAME").into(),
            version: env!("CARGO_PKG_VERSION").into(),
            commit: option_env!("PHOTONMAP_GIT_COMMIT").map(str::to_string),
            ..Self::default()
        }
    }

    /// Where the image sits in the frame: its first pixel (column, row).
    pub fn origin(&self) -> (u32, u32) {
        self.pixel_bounds.map_or((0, 0), |b| (b[0], b[2]))
    }

    /// The image-header attribute that carries it: one text attribute,
    /// `photonmap.provenance`, holding this as JSON (one attribute, so the
    /// file's bytes do not depend on a hash map's order).
    pub fn pairs(&self) -> Vec<(String, String)> {
        vec![(
            "photonmap.provenance".to_string(),
            serde_json::to_string(self).unwrap_or_default(),
        )]
    }
}

/// FNV-1a, 64 bits: a stable fingerprint of a scene's text (not a security hash).
pub fn fnv1a64(bytes: &[u8]) -> u64 {
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for &b in bytes {
        h ^= b as u64;
        h = h.wrapping_mul(0x0100_0000_01b3);
    }
    h
}

#[cfg(test)]
mod tests {
    #[test]
    fn fnv1a64_matches_its_published_values() {
        assert_eq!(super::fnv1a64(b""), 0xcbf2_9ce4_8422_2325);
        assert_eq!(super::fnv1a64(b"a"), 0xaf63_dc4c_8601_ec8c);
    }
}
