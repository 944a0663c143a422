//! Every default and limit of the scene format, in one place: the loader
//! fills absent fields from here and checks ranges against these limits,
//! `Scene::with_shapes` builds its parameters from here, and the book's
//! scene-format section quotes these numbers (the loader's unit tests,
//! src/scene/load/tests/defaults.rs, check that it still does).

use glam::{DVec3, Vec3};

use super::{bounds_size, Camera, Light, Material, PhotonMapParams, RenderParams, Scene, Shape};

// ---- defaults of optional fields ---------------------------------------------

/// `camera.up`.
pub const DEFAULT_UP: Vec3 = Vec3::Y;
/// `render.shadow_rays`.
pub const DEFAULT_SHADOW_RAYS: u32 = 1;
/// `render.max_specular_depth`.
pub const DEFAULT_MAX_SPECULAR_DEPTH: u32 = 10;
/// `photon_map.photons_stored`.
pub const DEFAULT_PHOTONS_STORED: u32 = 10_000;
/// `photon_map.grid_resolution`.
pub const DEFAULT_GRID_RESOLUTION: [u32; 3] = [64, 64, 64];
/// `photon_map.k`.
pub const DEFAULT_K: u32 = 50;
/// `photon_map.max_radius`, as a fraction of the scene's size (the longest
/// side of the shapes' bounds, area lights included, point lights not).
pub const DEFAULT_MAX_RADIUS_OF_SIZE: f32 = 0.1;
/// `photon_map.max_bounces`.
pub const DEFAULT_MAX_BOUNCES: u32 = 8;
/// `photon_map.store_direct`.
pub const DEFAULT_STORE_DIRECT: bool = false;
/// `photon_map.caustics_only`.
pub const DEFAULT_CAUSTICS_ONLY: bool = false;
/// `photon_map.projection_resolution` (re-exported by `photon::projection`
/// as `DEFAULT_RESOLUTION`).
pub const DEFAULT_PROJECTION_RESOLUTION: u32 = 64;
/// A mesh shape's `scale`.
pub const DEFAULT_MESH_SCALE: f32 = 1.0;
/// A mesh shape's `translate`.
pub const DEFAULT_MESH_TRANSLATE: [f32; 3] = [0.0; 3];

// ---- limits --------------------------------------------------------------------

/// `camera.width` and `camera.height`: 1..=MAX_IMAGE_SIDE.
pub const MAX_IMAGE_SIDE: i64 = 16384;
/// `camera.vfov`, degrees, exclusive at both ends.
pub const VFOV_RANGE: (f32, f32) = (0.0, 180.0);
/// `render.shadow_rays`: 1..=MAX_SHADOW_RAYS.
pub const MAX_SHADOW_RAYS: i64 = 1024;
/// `render.max_specular_depth`: 0..=MAX_SPECULAR_DEPTH.
pub const MAX_SPECULAR_DEPTH: i64 = 64;
/// 2^24: float-addressed photon textures stay exact below it.
pub const MAX_PHOTONS_STORED: i64 = 1 << 24;
/// Each of `photon_map.grid_resolution`: 1..=MAX_GRID_SIDE. 1024^3 = 2^30
/// cells keeps a cell's index an int; a grid of more than
/// MAX_UNIFORM_GRID_CELLS needs `--grid hash` (section 4.4).
pub const MAX_GRID_SIDE: i64 = 1024;
/// The most cells a uniform grid stores (512^3 = 2^27: its first-index
/// texture is then 2 GiB of RGBA32I texels); more are refused with a
/// pointer to `--grid hash`, whose memory follows the photons instead.
pub const MAX_UNIFORM_GRID_CELLS: u64 = 1 << 27;
/// `photon_map.k`: 1..=MAX_K.
pub const MAX_K: i64 = 4096;
/// `photon_map.max_bounces`: 1..=MAX_BOUNCES.
pub const MAX_BOUNCES: i64 = 64;
/// `photon_map.projection_resolution` (re-exported by `photon::projection`
/// as `MIN_RESOLUTION`).
pub const MIN_PROJECTION_RESOLUTION: u32 = 4;
/// 128² cells, 4 a texel, fit a 4,097-texel row on any GL 4.5 driver
/// (re-exported by `photon::projection` as `MAX_RESOLUTION`).
pub const MAX_PROJECTION_RESOLUTION: u32 = 128;
/// A glass material's `ior`, inclusive.
pub const IOR_RANGE: (f32, f32) = (1.0, 10.0);
/// A conductor's Trowbridge-Reitz `alpha`, inclusive; below
/// `SMOOTH_ALPHA` the surface is smooth (a delta lobe), as pbrt-v4 treats
/// an alpha under 1e-3 ("effectively smooth").
pub const ALPHA_RANGE: (f32, f32) = (0.0, 1.0);
pub const SMOOTH_ALPHA: f32 = 1e-3;
/// A conductor's `eta` and `k` per channel, inclusive (measured metals lie
/// well inside: Mitsuba's tables run from eta 0.03 to 5 and k 0 to 10).
pub const CONDUCTOR_INDEX_RANGE: (f32, f32) = (0.0, 100.0);
/// Every coordinate stays within this magnitude.
pub const MAX_COORDINATE: f32 = 1e15;

// ---- the defaults as parameter sets ------------------------------------------

impl Default for RenderParams {
    /// A scene file without `[render]`.
    fn default() -> Self {
        RenderParams {
            shadow_rays: DEFAULT_SHADOW_RAYS,
            max_specular_depth: DEFAULT_MAX_SPECULAR_DEPTH,
        }
    }
}

impl PhotonMapParams {
    /// A scene file without `[photon_map]`, for these shapes (the default
    /// maximum radius follows their size).
    pub fn defaults_for(shapes: &[Shape]) -> Self {
        PhotonMapParams {
            photons_stored: DEFAULT_PHOTONS_STORED,
            grid_resolution: DEFAULT_GRID_RESOLUTION,
            grid_bounds: None,
            k: DEFAULT_K,
            max_radius: default_max_radius(shapes),
            max_bounces: DEFAULT_MAX_BOUNCES,
            store_direct: DEFAULT_STORE_DIRECT,
            caustics_only: DEFAULT_CAUSTICS_ONLY,
            specular_last_only: false,
            projection_resolution: DEFAULT_PROJECTION_RESOLUTION,
        }
    }
}

/// The default `photon_map.max_radius` of a scene of these shapes.
pub fn default_max_radius(shapes: &[Shape]) -> f32 {
    DEFAULT_MAX_RADIUS_OF_SIZE * bounds_size(shapes, &[])
}

impl Scene {
    /// A scene of these shapes and lights with a neutral camera and the scene
    /// file's default parameters (`defaults`), for measuring geometry, and
    /// for tests.
    pub fn with_shapes(shapes: Vec<Shape>, materials: Vec<Material>, lights: Vec<Light>) -> Self {
        Scene {
            name: String::new(),
            camera: Camera {
                position: Vec3::Z,
                look_at: Vec3::ZERO,
                up: DEFAULT_UP,
                vfov_degrees: 40.0,
                width: 1,
                height: 1,
            },
            render: RenderParams::default(),
            photon_map: PhotonMapParams::defaults_for(&shapes),
            materials,
            shapes,
            lights,
            origin: DVec3::ZERO,
        }
    }
}
