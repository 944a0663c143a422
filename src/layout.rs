//! Numbers that Rust and GLSL must agree on, defined once here. Every program
//! is compiled with them as `#define`s (`glsl_defines`), so no shader spells a
//! texel count or a kind code itself.

/// Texels per row of each packed-scene texture (src/scene/pack.rs).
pub const PRIMITIVE_TEXELS: u32 = 4;
pub const MATERIAL_TEXELS: u32 = 4;
/// Primitive records in one row of the primitive texture (so its width is
/// PRIMITIVE_TEXELS x this, and its height grows by one per this many).
pub const PRIMITIVES_PER_ROW: u32 = 1024;
/// Width of the BVH textures (nodes: 2 texels each; leaf order: 1 each).
pub const BVH_ROW_TEXELS: u32 = 4096;
/// Entries of the ordered BVH walk's stack in glsl/common/scene.glsl; a deeper
/// tree is refused. obvhs trees of 1M triangles reach depth 65; the stack's
/// size costs nothing measurable on llvmpipe (64 and 128 time the same).
pub const BVH_STACK: usize = 128;
/// A BVH leaf's texel packs its first position and primitive count as
/// -(first x LEAF_COUNT_SPAN + count): above any leaf's count.
pub const LEAF_COUNT_SPAN: i32 = 8;
/// A hierarchy whose nodes, leaf order and primitives fit this many bytes
/// (or the driver's GL_MAX_UNIFORM_BLOCK_SIZE, if less) is read from a
/// uniform block by the threaded walk (SCENE_BVH_BLOCK).
pub const BVH_BLOCK_BYTES: usize = 65536;
/// A scene may be traced by a loop over every primitive (SCENE_LINEAR_SCAN
/// in glsl/common/scene.glsl) instead of the BVH where the loop costs less
/// than the walk (`FlatBvh::loses_to_a_loop`) and its primitives fit a
/// uniform block of 16 KiB, the least GL_MAX_UNIFORM_BLOCK_SIZE that GL 4.5
/// allows: at most this many.
pub const LINEAR_SCAN_MAX: usize = 256;
const _: () = assert!(LINEAR_SCAN_MAX * PRIMITIVE_TEXELS as usize * 16 <= 16384);
/// The uniform-block binding point of a scene's block: the loop's primitives
/// or a hierarchy's (SCENE_PRIMITIVE_BLOCK, SCENE_BVH_BLOCK in
/// glsl/common/scene.glsl).
pub const SCENE_BLOCK_BINDING: u32 = 0;
/// 1 + 2 gamma(3) in f32: the slab test's far distance widened by its worst
/// rounding, so a box never culls a ray its primitives would hit (pbrt-v4 6.1).
pub const BOX_ROBUST: f32 = 1.0 + 3.0 * f32::EPSILON;
pub const LIGHT_TEXELS: u32 = 6;
/// Texels of one triangle's vertex normals (n0, n1, n2) in the normals
/// texture, and records in one row of it. A primitive's head texel names
/// its record (.z = record + 1; 0: none, so a primitive without normals
/// costs nothing).
pub const NORMAL_TEXELS: u32 = 3;
pub const NORMALS_PER_ROW: u32 = 1024;
/// Texels in one row of the emissive-triangle texture: one texel an
/// emissive triangle, (cumulative area fraction within its light, primitive).
pub const LIGHT_TRIANGLE_ROW_TEXELS: u32 = 4096;

/// Primitive kinds, the first float of a primitive's head texel.
pub const PRIM_SPHERE: u32 = 0;
pub const PRIM_CYLINDER: u32 = 1;
pub const PRIM_PARALLELOGRAM: u32 = 2;
pub const PRIM_TRIANGLE: u32 = 3;

/// Material kinds, the first float of a material's head texel.
pub const MAT_DIFFUSE: u32 = 0;
pub const MAT_MIRROR: u32 = 1;
pub const MAT_GLASS: u32 = 2;
pub const MAT_EMITTER: u32 = 3;
/// A metal: complex Fresnel from eta + i k, smooth or rough (Trowbridge-Reitz).
pub const MAT_CONDUCTOR: u32 = 4;

/// The lobes of glsl/common/bsdf.glsl: a diffuse lobe (visible points,
/// stored photons), a delta lobe (mirror, glass, smooth conductor: the path
/// goes on in one direction), a glossy lobe (sampled and evaluated).
pub const BSDF_DIFFUSE: u32 = 1;
pub const BSDF_DELTA: u32 = 2;
pub const BSDF_GLOSSY: u32 = 4;

/// A rough lobe's microfacet model (a material's colour texel .w, bits):
/// Beckmann's distribution instead of Trowbridge-Reitz (GGX), and the
/// masking-shadowing term as the product of the two directions' G1
/// (Mitsuba) instead of height-correlated (pbrt).
pub const MICROFACET_BECKMANN: u32 = 1;
pub const MICROFACET_SEPARABLE: u32 = 2;

/// Light kinds, the first float of a light's head texel.
pub const LIGHT_AREA: u32 = 0;
pub const LIGHT_POINT: u32 = 1;
/// The emissive triangles of an OBJ (object, material) group, sampled by area.
pub const LIGHT_TRIANGLES: u32 = 2;

/// The key of photon records that are not in the map: they sort last.
pub const INVALID_KEY: i32 = i32::MAX;

/// Random numbers per photon per frame in the `--faithful` random-number
/// texture: two RGBA texels side by side.
pub const RANDOM_PER_PHOTON_FRAME: usize = 8;

/// The kNN estimate's disc test (`LeakTest::Disc`): photons farther than this
/// fraction of the maximum radius from the query's tangent plane are not its own.
pub const DISC_THICKNESS: f32 = 0.1;

/// The kNN search skips a grid cell whose box, shrunk by this fraction of a
/// cell on every side, lies beyond its reach (glsl/render/knn_search.frag):
/// a photon is in its cell's box up to f32 rounding, far below this slack.
pub const CULL_SLACK: f32 = 1e-3;

/// The random stream of final-gather ray g of a pixel is GATHER_STREAM | g
/// (glsl/render/gather_rays.frag; the eye side's other streams use other top bits).
pub const GATHER_STREAM: u32 = 0x5000_0000;

/// The random stream of a VCM camera path's vertex s (segments from the
/// camera) is VCM_CAMERA_STREAM | s (glsl/vcm/camera_path.frag).
pub const VCM_CAMERA_STREAM: u32 = 0x8000_0000;

/// VCM's techniques (`--vcm-mode`): path tracing with next-event estimation,
/// light tracing, progressive photon mapping (merging at the first diffuse
/// vertex), bidirectional path tracing, and all of them.
pub const VCM_MODE_PT: u32 = 0;
pub const VCM_MODE_LT: u32 = 1;
pub const VCM_MODE_PPM: u32 = 2;
pub const VCM_MODE_BPT: u32 = 3;
pub const VCM_MODE_VCM: u32 = 4;
/// Path tracing alone (`--vcm-mode pt`) plays Russian roulette from a camera
/// path's hit of this index on (the eye ray's hit is 1); before it every
/// path goes on. The other modes cannot wait: their MIS weights need the
/// camera's continuation at a vertex to be the vertex's alone, whatever the
/// path's length. Measured at equal time against roulette from the first
/// hit: `results/llvmpipe/vcm_pt_roulette.md`.
pub const VCM_PT_ROULETTE_FROM: u32 = 4;

/// Adaptive sampling interpolates a pixel only from corners whose first-hit
/// normal is within this cosine of its own (about 18 degrees) and whose
/// material is the same (glsl/render/adaptive_plan.glsl).
pub const ADAPTIVE_NORMAL_COS: f32 = 0.95;

/// Adaptive sampling's plan of a pixel at one level (glsl/render/adaptive_plan.glsl):
/// not this level's, computed, interpolated, or empty (no diffuse hit).
pub const PLAN_NONE: u32 = 0;
pub const PLAN_COMPUTE: u32 = 1;
pub const PLAN_INTERPOLATE: u32 = 2;
pub const PLAN_EMPTY: u32 = 3;

/// Texels in one row of IGI's primitive-box texture (2 texels a primitive:
/// min, max) for imperfect visibility.
pub const PRIMITIVE_BOX_ROW: u32 = 4096;
/// VPLs gathered per IGI pass at most, per pixel (bounds work per pass).
pub const VPL_BATCH: u32 = 64;
/// IGI's discontinuity buffer: a neighbour's incident light is averaged in
/// where its first-hit normal is within this cosine of the pixel's (about 25
/// degrees) and its hit lies within VPL_DEPTH_TOLERANCE of the pixel's
/// distance from the eye off the pixel's tangent plane (a priori values).
pub const VPL_NORMAL_COS: f32 = 0.9;
pub const VPL_DEPTH_TOLERANCE: f32 = 0.05;
/// The random stream of IGI's VPL paths (seeded apart from the caustic map's).
pub const VPL_STREAM: u32 = 0x6000_0000;

/// A photon footprint's normal semi-axis as a fraction of its longer surface
/// semi-axis (glsl/common/footprint.glsl): the ellipsoid is a thin disc, so
/// a query on another wall at a corner is not in it. The paper leaves it open.
pub const FOOTPRINT_THICKNESS: f32 = 0.1;
/// Nodes of the footprint BVH one pass of the footprint estimate visits per
/// pixel at most (bounds work per pass).
pub const FOOTPRINT_BUDGET: u32 = 256;
/// A coverage probe (photon/footprints.frag) lands on the photon's surface
/// only where the surface it meets is within this cosine of the footprint's
/// plane.
pub const COVERAGE_NORMAL_COS: f32 = 0.5;
/// Surfaces of other materials a coverage probe passes through at most.
pub const COVERAGE_CROSSINGS: u32 = 4;

/// Vertices of a radiosity shooter's outline at most (glsl/radiosity/
/// form_factor.glsl): a curved block's four edges in CURVED_OUTLINE_SEGMENTS
/// each; a triangle's block of cells cut by its diagonal has 5.
pub const SHOOTER_OUTLINE: u32 = 4 * CURVED_OUTLINE_SEGMENTS;
/// Segments along each edge of a curved shooter's outline (it follows the
/// surface, so its form factor is the curved block's).
pub const CURVED_OUTLINE_SEGMENTS: u32 = 4;
/// Texels of a shooter record: position, normal, energy, then the outline.
pub const SHOOTER_TEXELS: u32 = 3 + SHOOTER_OUTLINE;

/// The fused sort's local block: its local pass runs every step of a stage
/// below this distance in registers, for blocks of this many texels of a row
/// (glsl/photon/bitonic_local.frag). 2 on llvmpipe: blocks of 4, 8 and 16
/// made the sort 1.4, 2.3 and 5.3 times slower (arrays indexed in a loop).
pub const SORT_BLOCK: u32 = 2;

/// Progressive radiosity's per-tile and per-node textures (tile powers,
/// quadtree nodes): record r at texel (r mod TILE_ROW, r / TILE_ROW).
pub const TILE_ROW: u32 = 1024;

/// Rec. 709 luminance weights of linear RGB.
pub const LUMINANCE: [f32; 3] = [0.2126, 0.7152, 0.0722];

/// pi as every shader writes it (the same f32 as `std::f32::consts::PI`).
const PI_GLSL: &str = "3.14159265358979";

/// The constants above as `(name, value)` pairs for the GLSL preprocessor.
pub fn glsl_defines() -> Vec<(&'static str, String)> {
    let u = |v: u32| v.to_string();
    vec![
        ("PRIMITIVE_TEXELS", u(PRIMITIVE_TEXELS)),
        ("MATERIAL_TEXELS", u(MATERIAL_TEXELS)),
        ("LIGHT_TEXELS", u(LIGHT_TEXELS)),
        ("NORMAL_TEXELS", u(NORMAL_TEXELS)),
        ("NORMALS_PER_ROW", u(NORMALS_PER_ROW)),
        ("LIGHT_TRIANGLE_ROW_TEXELS", u(LIGHT_TRIANGLE_ROW_TEXELS)),
        ("PRIMITIVES_PER_ROW", u(PRIMITIVES_PER_ROW)),
        ("BVH_ROW_TEXELS", u(BVH_ROW_TEXELS)),
        ("BVH_STACK", BVH_STACK.to_string()),
        ("LEAF_COUNT_SPAN", LEAF_COUNT_SPAN.to_string()),
        ("LINEAR_SCAN_MAX", LINEAR_SCAN_MAX.to_string()),
        ("SCENE_BLOCK_BINDING", u(SCENE_BLOCK_BINDING)),
        ("BOX_ROBUST", format!("{BOX_ROBUST:?}")),
        ("PRIM_SPHERE", u(PRIM_SPHERE)),
        ("PRIM_CYLINDER", u(PRIM_CYLINDER)),
        ("PRIM_PARALLELOGRAM", u(PRIM_PARALLELOGRAM)),
        ("PRIM_TRIANGLE", u(PRIM_TRIANGLE)),
        ("MAT_DIFFUSE", u(MAT_DIFFUSE)),
        ("MAT_MIRROR", u(MAT_MIRROR)),
        ("MAT_GLASS", u(MAT_GLASS)),
        ("MAT_EMITTER", u(MAT_EMITTER)),
        ("MAT_CONDUCTOR", u(MAT_CONDUCTOR)),
        ("BSDF_DIFFUSE", u(BSDF_DIFFUSE)),
        ("BSDF_DELTA", u(BSDF_DELTA)),
        ("BSDF_GLOSSY", u(BSDF_GLOSSY)),
        ("MICROFACET_BECKMANN", u(MICROFACET_BECKMANN)),
        ("MICROFACET_SEPARABLE", u(MICROFACET_SEPARABLE)),
        ("LIGHT_AREA", u(LIGHT_AREA)),
        ("LIGHT_POINT", u(LIGHT_POINT)),
        ("LIGHT_TRIANGLES", u(LIGHT_TRIANGLES)),
        ("INVALID_KEY", format!("0x{INVALID_KEY:x}")),
        (
            "RANDOM_PER_PHOTON_FRAME",
            RANDOM_PER_PHOTON_FRAME.to_string(),
        ),
        ("PI", PI_GLSL.into()),
        ("DISC_THICKNESS", format!("{DISC_THICKNESS:?}")),
        ("CULL_SLACK", format!("{CULL_SLACK:?}")),
        ("FOOTPRINT_THICKNESS", format!("{FOOTPRINT_THICKNESS:?}")),
        ("COVERAGE_NORMAL_COS", format!("{COVERAGE_NORMAL_COS:?}")),
        ("COVERAGE_CROSSINGS", u(COVERAGE_CROSSINGS)),
        ("TILE_ROW", u(TILE_ROW)),
        ("LOCAL_BLOCK", u(SORT_BLOCK)),
        ("SHOOTER_OUTLINE", u(SHOOTER_OUTLINE)),
        ("SHOOTER_TEXELS", u(SHOOTER_TEXELS)),
        ("GATHER_STREAM", format!("0x{GATHER_STREAM:x}u")),
        ("VCM_CAMERA_STREAM", format!("0x{VCM_CAMERA_STREAM:x}u")),
        ("VCM_MODE_PT", u(VCM_MODE_PT)),
        ("VCM_MODE_LT", u(VCM_MODE_LT)),
        ("VCM_MODE_PPM", u(VCM_MODE_PPM)),
        ("VCM_MODE_BPT", u(VCM_MODE_BPT)),
        ("VCM_MODE_VCM", u(VCM_MODE_VCM)),
        ("VCM_PT_ROULETTE_FROM", u(VCM_PT_ROULETTE_FROM)),
        ("ADAPTIVE_NORMAL_COS", format!("{ADAPTIVE_NORMAL_COS:?}")),
        ("PRIMITIVE_BOX_ROW", u(PRIMITIVE_BOX_ROW)),
        ("VPL_NORMAL_COS", format!("{VPL_NORMAL_COS:?}")),
        ("VPL_DEPTH_TOLERANCE", format!("{VPL_DEPTH_TOLERANCE:?}")),
        ("PLAN_NONE", u(PLAN_NONE)),
        ("PLAN_COMPUTE", u(PLAN_COMPUTE)),
        ("PLAN_INTERPOLATE", u(PLAN_INTERPOLATE)),
        ("PLAN_EMPTY", u(PLAN_EMPTY)),
        (
            "LUMINANCE",
            format!(
                "vec3({:?}, {:?}, {:?})",
                LUMINANCE[0], LUMINANCE[1], LUMINANCE[2]
            ),
        ),
    ]
}

#[cfg(test)]
mod tests {
    #[test]
    fn glsl_pi_is_the_f32_pi() {
        assert_eq!(super::PI_GLSL.parse::<f32>().unwrap(), std::f32::consts::PI);
    }
}
