//! The scene packed into float textures once, in the layout glsl/common/scene.glsl reads.

use crate::error::Error;
use crate::gpu::{Gpu, Result, TexFormat, Texture, UniformBlock};
use crate::layout::{
    BVH_ROW_TEXELS, LIGHT_AREA, LIGHT_POINT, LIGHT_TEXELS, LIGHT_TRIANGLES,
    LIGHT_TRIANGLE_ROW_TEXELS, MATERIAL_TEXELS, MAT_CONDUCTOR, MAT_DIFFUSE, MAT_EMITTER, MAT_GLASS,
    MAT_MIRROR, NORMALS_PER_ROW, NORMAL_TEXELS, PRIMITIVES_PER_ROW, PRIMITIVE_TEXELS,
    PRIM_CYLINDER, PRIM_PARALLELOGRAM, PRIM_SPHERE, PRIM_TRIANGLE,
};

use super::bvh::FlatBvh;
use super::{triangle_area, Geometry, Light, Material, Scene};

/// RGBA float texels: PRIMITIVE_TEXELS a primitive (PRIMITIVES_PER_ROW to a
/// row of the texture), one row per material and per light; NORMAL_TEXELS
/// per triangle with vertex normals; one per emissive triangle of a
/// `Light::Triangles`.
pub struct PackedScene {
    /// Each primitive's head texel (kind, material, normals record + 1,
    /// light + 1 for a light's emitting primitive, else 0), then its geometry.
    pub primitives: Vec<[f32; 4]>,
    pub materials: Vec<[f32; 4]>,
    pub lights: Vec<[f32; 4]>,
    /// n0, n1, n2 of each triangle with vertex normals, in primitive order;
    /// a primitive's head texel .z is its record + 1 (0: none).
    pub normals: Vec<[f32; 4]>,
    /// For each `Light::Triangles`, its triangles in order: (the cumulative
    /// fraction of the light's area up to and including this triangle, the
    /// primitive, 0, 0). The last of a light is exactly 1.
    pub light_triangles: Vec<[f32; 4]>,
    pub primitive_count: usize,
    pub light_count: usize,
    /// Absolute floor of ray-origin offsets: a millionth of the scene's size (its
    /// position is covered by the offset's term relative to |p|).
    pub offset_floor: f32,
}

pub fn pack_geometry(g: &Geometry) -> [[f32; 4]; 3] {
    let v = |a: glam::Vec3, w: f32| [a.x, a.y, a.z, w];
    match *g {
        Geometry::Sphere { center, radius } => [v(center, radius), [0.0; 4], [0.0; 4]],
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => [v(base, radius), v(axis, height), [0.0; 4]],
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => [v(corner, 0.0), v(edge1, 0.0), v(edge2, 0.0)],
        // Vertices, not edges: triangles sharing a vertex must share its exact bits
        // for the watertight test (v0 + (v1 - v0) need not round to v1).
        Geometry::Triangle { v0, v1, v2 } => [v(v0, 0.0), v(v1, 0.0), v(v2, 0.0)],
    }
}

pub fn geometry_kind(g: &Geometry) -> f32 {
    match g {
        Geometry::Sphere { .. } => PRIM_SPHERE as f32,
        Geometry::Cylinder { .. } => PRIM_CYLINDER as f32,
        Geometry::Parallelogram { .. } => PRIM_PARALLELOGRAM as f32,
        Geometry::Triangle { .. } => PRIM_TRIANGLE as f32,
    }
}

/// The probability photon emission picks each light with: in proportion to
/// its power (sum of channels), or uniform when no light has any.
pub fn light_probabilities(scene: &Scene) -> Vec<f32> {
    let weights: Vec<f32> = scene
        .lights
        .iter()
        .map(|l| l.power(&scene.shapes).element_sum())
        .collect();
    let total: f32 = weights.iter().sum();
    weights
        .iter()
        .map(|w| {
            if total > 0.0 {
                w / total
            } else {
                1.0 / scene.lights.len() as f32
            }
        })
        .collect()
}

impl PackedScene {
    pub fn new(scene: &Scene) -> Self {
        let mut primitives = Vec::new();
        let mut normals = Vec::new();
        for s in &scene.shapes {
            let record = match (s.normals, s.geometry) {
                (Some(n), Geometry::Triangle { .. }) => {
                    normals.extend(n.map(|n| [n.x, n.y, n.z, 0.0]));
                    (normals.len() / NORMAL_TEXELS as usize) as f32
                }
                _ => 0.0,
            };
            primitives.push([geometry_kind(&s.geometry), s.material as f32, record, 0.0]);
            primitives.extend(pack_geometry(&s.geometry));
        }
        let materials = scene.materials.iter().flat_map(pack_material).collect();
        let probabilities = light_probabilities(scene);
        let mut cdf = 0.0;
        // Area light k is the k-th emitter shape (the loader appends them in order).
        let mut emitter_shapes = scene
            .shapes
            .iter()
            .enumerate()
            .filter(|(_, s)| {
                matches!(
                    (s.geometry, scene.materials[s.material]),
                    (
                        Geometry::Parallelogram { .. },
                        Material::Emitter {
                            normal: Some(_),
                            ..
                        }
                    )
                )
            })
            .map(|(i, _)| i as f32);
        let mut lights = Vec::new();
        let mut light_triangles = Vec::new();
        let mut emitting = Vec::new();
        for (index, (l, &probability)) in scene.lights.iter().zip(&probabilities).enumerate() {
            let v = |a: glam::Vec3| [a.x, a.y, a.z, 0.0];
            cdf += probability;
            let primitive = match *l {
                Light::Area {
                    corner,
                    edge1,
                    edge2,
                    normal,
                    radiance,
                } => {
                    lights.extend([
                        [LIGHT_AREA as f32, normal.x, normal.y, normal.z],
                        v(corner),
                        v(edge1),
                        v(edge2),
                        v(radiance),
                    ]);
                    emitter_shapes.next().unwrap_or(-1.0)
                }
                Light::Point {
                    position,
                    intensity,
                } => {
                    lights.extend([
                        [LIGHT_POINT as f32, 0.0, 0.0, 0.0],
                        v(position),
                        [0.0; 4],
                        [0.0; 4],
                        v(intensity),
                    ]);
                    -1.0
                }
                Light::Triangles {
                    first,
                    count,
                    radiance,
                } => {
                    let start = light_triangles.len() as f32;
                    let area = l.area(&scene.shapes);
                    light_triangles.extend(area_cdf(scene, first, count));
                    lights.extend([
                        [LIGHT_TRIANGLES as f32, 0.0, 0.0, 0.0],
                        [start, count as f32, area, 0.0],
                        [0.0; 4],
                        [0.0; 4],
                        v(radiance),
                    ]);
                    -1.0
                }
            };
            lights.push([cdf, probability, primitive, 0.0]);
            match *l {
                Light::Triangles { first, count, .. } => {
                    emitting.extend((first..first + count).map(|p| (p, index)))
                }
                _ if primitive >= 0.0 => emitting.push((primitive as usize, index)),
                _ => {}
            }
        }
        // Each emitting primitive names its light (head .w = light + 1), for
        // the pdfs of a path that hits it (VCM's MIS weights).
        for (prim, light) in emitting {
            primitives[prim * PRIMITIVE_TEXELS as usize][3] = (light + 1) as f32;
        }
        Self {
            primitives,
            materials,
            lights,
            normals,
            light_triangles,
            primitive_count: scene.shapes.len(),
            light_count: scene.lights.len(),
            offset_floor: 1e-6 * scene.size(),
        }
    }
}

/// A material's MATERIAL_TEXELS texels, as glsl/common/bsdf.glsl's
/// `material_bsdf` and direct light read them: (kind, ior, alpha, alpha),
/// colour (albedo, reflectance, a metal's tint or an emitter's radiance;
/// .w a rough metal's MICROFACET_* bits),
/// then a metal's eta and k, or an emitter's normal (.w = 1: each
/// primitive's front face instead).
fn pack_material(m: &Material) -> [[f32; 4]; MATERIAL_TEXELS as usize] {
    let z = glam::Vec3::ZERO;
    let (kind, ior, alpha, color, third, fourth, own_face) = match *m {
        Material::Diffuse { albedo } => (MAT_DIFFUSE, 1.0, 0.0, albedo, z, z, 0.0),
        Material::Mirror { reflectance } => (MAT_MIRROR, 1.0, 0.0, reflectance, z, z, 0.0),
        Material::Glass { ior } => (MAT_GLASS, ior, 0.0, glam::Vec3::ONE, z, z, 0.0),
        Material::Conductor {
            eta,
            k,
            tint,
            alpha,
            ..
        } => (MAT_CONDUCTOR, 1.0, alpha, tint, eta, k, 0.0),
        Material::Emitter { radiance, normal } => (
            MAT_EMITTER,
            1.0,
            0.0,
            radiance,
            normal.unwrap_or(z),
            z,
            f32::from(normal.is_none()),
        ),
    };
    let model = match m {
        Material::Conductor { microfacet, .. } => microfacet.bits() as f32,
        _ => 0.0,
    };
    [
        [kind as f32, ior, alpha, alpha],
        [color.x, color.y, color.z, model],
        [third.x, third.y, third.z, own_face],
        [fourth.x, fourth.y, fourth.z, 0.0],
    ]
}

/// The texels of a `Light::Triangles` over shapes[first..first + count]:
/// cumulative area fractions (summed in f64; the last exactly 1) and primitives.
fn area_cdf(scene: &Scene, first: usize, count: usize) -> Vec<[f32; 4]> {
    let areas: Vec<f64> = scene.shapes[first..first + count]
        .iter()
        .map(|s| f64::from(triangle_area(&s.geometry)))
        .collect();
    let total: f64 = areas.iter().sum();
    let mut sum = 0.0;
    areas
        .iter()
        .enumerate()
        .map(|(k, a)| {
            sum += a;
            let cdf = if k + 1 == count { 1.0 } else { sum / total };
            [cdf as f32, (first + k) as f32, 0.0, 0.0]
        })
        .collect()
}

/// The packed scene on the GPU.
pub struct SceneTextures {
    pub primitives: Texture,
    /// The BVH's nodes (RGBA32I, 2 texels a node) and its leaf order (R32I).
    pub bvh_nodes: Texture,
    pub bvh_order: Texture,
    /// Levels and nodes of the BVH, for reports.
    pub bvh_depth: u32,
    pub bvh_node_count: usize,
    pub materials: Texture,
    pub lights: Texture,
    /// Vertex normals (NORMAL_TEXELS a record) and emissive triangles.
    pub normals: Texture,
    pub light_triangles: Texture,
    pub primitive_count: usize,
    pub light_count: usize,
    pub offset_floor: f32,
    /// The scene's uniform block, if it has one (see `SceneBlock`).
    block: Option<SceneBlock>,
    /// The scene's kind masks as `scene_masks` gives them.
    masks: Vec<(&'static str, u32)>,
}

/// The masks of kinds a packed scene holds, as scene defines name them
/// (glsl/common/scene.glsl): SCENE_KINDS (bit PRIM_* for each primitive
/// kind), SCENE_MATERIALS (bit MAT_* for each kind of material on a
/// shape), SCENE_LIGHTS (bit LIGHT_* for each light kind) and
/// SCENE_SHADING_NORMALS (1 where a triangle has vertex normals); each kind
/// read from the head texel the shaders read it from.
fn scene_masks(scene: &Scene, p: &PackedScene) -> Vec<(&'static str, u32)> {
    let kind =
        |texels: &[[f32; 4]], stride: u32, i: usize| 1u32 << texels[i * stride as usize][0] as u32;
    let primitives =
        (0..scene.shapes.len()).fold(0, |m, i| m | kind(&p.primitives, PRIMITIVE_TEXELS, i));
    let materials = scene.shapes.iter().fold(0, |m, s| {
        m | kind(&p.materials, MATERIAL_TEXELS, s.material)
    });
    let lights = (0..scene.lights.len()).fold(0, |m, l| m | kind(&p.lights, LIGHT_TEXELS, l));
    let normals = u32::from(scene.shapes.iter().any(|s| s.normals.is_some()));
    vec![
        ("SCENE_KINDS", primitives),
        ("SCENE_MATERIALS", materials),
        ("SCENE_LIGHTS", lights),
        ("SCENE_SHADING_NORMALS", normals),
    ]
}

/// A scene's data again in a uniform block (SCENE_BLOCK_BINDING), read
/// there by the walk it is laid out for, with the defines that place it:
/// the primitives of a scene traced by the loop (SCENE_PRIMITIVE_BLOCK) or a
/// mid-size scene's hierarchy, leaf order and primitives (SCENE_BVH_BLOCK,
/// the threaded walk).
struct SceneBlock {
    buffer: UniformBlock,
    defines: Vec<(&'static str, String)>,
}

/// Every define that places a scene block: a program compiled with any of
/// them reads a block laid out as they say.
const BLOCK_DEFINES: [&str; 4] = [
    "SCENE_PRIMITIVE_BLOCK",
    "SCENE_BVH_BLOCK",
    "BVH_BLOCK_ORDER_AT",
    "BVH_BLOCK_PRIMITIVES_AT",
];

impl SceneBlock {
    /// The block of a scene traced by the loop (`looped`), or of a hierarchy whose words
    /// (its `node_words`, the leaf order four to a texel, the primitives'
    /// texels) fit BVH_BLOCK_BYTES and the driver's limit; else None.
    fn new(
        gpu: &Gpu,
        looped: bool,
        node_words: &[i32],
        bvh: &FlatBvh,
        p: &PackedScene,
    ) -> Result<Option<Self>> {
        let bits = |texels: &[[f32; 4]]| -> Vec<u32> {
            texels.iter().flatten().map(|v| v.to_bits()).collect()
        };
        if looped {
            // The block's whole declared size (GL reads none past the buffer).
            let mut words = bits(&p.primitives);
            words.resize(
                crate::layout::LINEAR_SCAN_MAX * PRIMITIVE_TEXELS as usize * 4,
                0,
            );
            return Ok(Some(Self {
                buffer: UniformBlock::from_words(gpu, words)?,
                defines: vec![
                    ("SCENE_LINEAR_SCAN", "1".to_string()),
                    ("SCENE_PRIMITIVE_BLOCK", "1".to_string()),
                ],
            }));
        }
        let mut words: Vec<u32> = node_words.iter().map(|&v| v as u32).collect();
        let order_at = words.len() / 4;
        words.extend(bvh.order.iter().copied());
        words.resize(words.len().div_ceil(4) * 4, 0);
        let primitives_at = words.len() / 4;
        words.extend(bits(&p.primitives));
        let limit = crate::layout::BVH_BLOCK_BYTES.min(gpu.max_uniform_block_bytes());
        if words.len() * 4 > limit {
            return Ok(None);
        }
        let defines = vec![
            ("SCENE_BVH_BLOCK", (words.len() / 4).to_string()),
            ("BVH_BLOCK_ORDER_AT", order_at.to_string()),
            ("BVH_BLOCK_PRIMITIVES_AT", primitives_at.to_string()),
        ];
        Ok(Some(Self {
            buffer: UniformBlock::from_words(gpu, words)?,
            defines,
        }))
    }

    fn value(&self, name: &str) -> Option<&String> {
        self.defines
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v)
    }
}

fn upload(gpu: &Gpu, rows: &[[f32; 4]], width: u32) -> Result<Texture> {
    let height = (rows.len().div_ceil(width as usize) as u32).max(1);
    let mut data: Vec<f32> = rows.iter().flatten().copied().collect();
    data.resize(width as usize * height as usize * 4, 0.0);
    Texture::from_texels(gpu, width, height, TexFormat::Rgba32F, &data)
}

/// `values` (channels of `format` a texel) in rows of BVH_ROW_TEXELS texels.
fn upload_ints(gpu: &Gpu, mut values: Vec<i32>, format: TexFormat) -> Result<Texture> {
    let row = BVH_ROW_TEXELS as usize * format.channels();
    let height = values.len().div_ceil(row).max(1);
    values.resize(row * height, 0);
    Texture::from_texels(gpu, BVH_ROW_TEXELS, height as u32, format, &values)
}

/// Refuses a scene whose primitive texture this driver cannot hold.
fn check_primitive_capacity(gpu: &Gpu, count: usize) -> Result<()> {
    let rows = count.div_ceil(PRIMITIVES_PER_ROW as usize);
    let max = gpu.max_texture_size() as usize;
    if rows > max {
        return Err(Error::TooLarge(format!(
            "{count} primitives: this driver's textures hold at most {} ({PRIMITIVES_PER_ROW} a row, {max} rows)",
            max * PRIMITIVES_PER_ROW as usize
        )));
    }
    Ok(())
}

impl SceneTextures {
    pub fn new(gpu: &Gpu, scene: &Scene) -> Result<Self> {
        check_primitive_capacity(gpu, scene.shapes.len())?;
        let bvh = super::bvh::build(scene)?;
        Self::with_bvh(gpu, scene, &bvh)
    }

    /// The textures with a hierarchy built already (tests pass their own).
    pub fn with_bvh(gpu: &Gpu, scene: &Scene, bvh: &FlatBvh) -> Result<Self> {
        let p = PackedScene::new(scene);
        let masks = scene_masks(scene, &p);
        // A scene whose boxes cull too little to pay for the walk is traced by
        // a loop over its primitives (both ways find the same hits), read from
        // a uniform block.
        let looped = bvh.loses_to_a_loop(scene.shapes.len());
        let nodes: Vec<i32> = bvh.nodes.iter().flat_map(|n| n.texels()).collect();
        let block = SceneBlock::new(gpu, looped, &nodes, bvh, &p)?;
        // Programs compiled from here on are specialised to this scene.
        let mut defines: Vec<(&'static str, String)> = masks
            .iter()
            .map(|&(name, mask)| (name, mask.to_string()))
            .collect();
        defines.extend(block.iter().flat_map(|b| b.defines.iter().cloned()));
        gpu.set_scene_defines(defines);
        let order: Vec<i32> = bvh.order.iter().map(|&i| i as i32).collect();
        Ok(Self {
            primitives: upload(gpu, &p.primitives, PRIMITIVE_TEXELS * PRIMITIVES_PER_ROW)?,
            bvh_nodes: upload_ints(gpu, nodes, TexFormat::Rgba32I)?,
            bvh_order: upload_ints(gpu, order, TexFormat::R32I)?,
            bvh_depth: bvh.depth,
            bvh_node_count: bvh.nodes.len(),
            materials: upload(gpu, &p.materials, MATERIAL_TEXELS)?,
            lights: upload(gpu, &p.lights, LIGHT_TEXELS)?,
            normals: upload(gpu, &p.normals, NORMAL_TEXELS * NORMALS_PER_ROW)?,
            light_triangles: upload(gpu, &p.light_triangles, LIGHT_TRIANGLE_ROW_TEXELS)?,
            primitive_count: p.primitive_count,
            light_count: p.light_count,
            offset_floor: p.offset_floor,
            block,
            masks,
        })
    }

    /// Whether a program compiled with these scene defines traces this
    /// scene: its masks cover every kind of primitive, material and light
    /// the scene holds (and its shading normals), and every define of a
    /// uniform block it reads is this scene's block's (one that reads
    /// textures traces any scene).
    fn traced_by(&self, defines: &[(&'static str, String)]) -> bool {
        let value = |name: &str| defines.iter().find(|(n, _)| *n == name).map(|(_, v)| v);
        let covered = self.masks.iter().all(|&(name, mask)| {
            value(name)
                .map_or(Some(u32::MAX), |v| v.parse::<u32>().ok())
                .is_some_and(|program| mask & !program == 0)
        });
        let block = BLOCK_DEFINES.iter().all(|&name| {
            value(name).is_none_or(|v| self.block.as_ref().and_then(|b| b.value(name)) == Some(v))
        });
        covered && block
    }

    /// Which walk traces this scene (glsl/common/scene.glsl's bvh_trace).
    pub fn walk(&self) -> &'static str {
        match &self.block {
            Some(b) if b.value("SCENE_PRIMITIVE_BLOCK").is_some() => {
                "a loop over every primitive, from a uniform block"
            }
            Some(_) => "the threaded BVH walk, from a uniform block",
            None => "the ordered BVH walk, from textures",
        }
    }

    /// Binds the textures and counts that glsl/common/scene.glsl declares.
    pub fn bind(&self, b: &mut crate::gpu::Bindings<'_>) {
        if !self.traced_by(b.scene_defines()) {
            b.fail(Error::SceneMismatch(b.program_name().to_string()));
        }
        if let Some(block) = &self.block {
            b.uniform_block(crate::layout::SCENE_BLOCK_BINDING, &block.buffer);
        }
        b.texture("u_primitives", &self.primitives)
            .texture("u_bvh_nodes", &self.bvh_nodes)
            .texture("u_bvh_order", &self.bvh_order)
            .texture("u_materials", &self.materials)
            .texture("u_lights", &self.lights)
            .texture("u_normals", &self.normals)
            .texture("u_light_triangles", &self.light_triangles)
            .int("u_primitive_count", self.primitive_count as i32)
            .int("u_light_count", self.light_count as i32)
            .float("u_offset_floor", self.offset_floor);
    }
}
