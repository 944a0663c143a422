//! The scene packed into float textures once, in the layout glsl/common/scene.glsl reads.

use crate::error::Error;
use crate::gpu::{Gpu, Result, TexFormat, Texture};
use crate::layout::{
    BVH_ROW_TEXELS, LIGHT_AREA, LIGHT_POINT, LIGHT_TEXELS, MATERIAL_TEXELS, MAT_DIFFUSE,
    MAT_EMITTER, MAT_GLASS, MAT_MIRROR, PRIMITIVES_PER_ROW, PRIMITIVE_TEXELS, PRIM_CYLINDER,
    PRIM_PARALLELOGRAM, PRIM_SPHERE, PRIM_TRIANGLE,
};

use super::bvh::FlatBvh;
use super::{Geometry, Light, Material, Scene};

/// RGBA float texels: PRIMITIVE_TEXELS a primitive (PRIMITIVES_PER_ROW to a
/// row of the texture), one row per material and per light.
pub struct PackedScene {
    pub primitives: Vec<[f32; 4]>,
    pub materials: Vec<[f32; 4]>,
    pub lights: Vec<[f32; 4]>,
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

impl PackedScene {
    pub fn new(scene: &Scene) -> Self {
        let mut primitives = Vec::new();
        for s in &scene.shapes {
            primitives.push([geometry_kind(&s.geometry), s.material as f32, 0.0, 0.0]);
            primitives.extend(pack_geometry(&s.geometry));
        }
        let mut materials = Vec::new();
        for m in &scene.materials {
            let (kind, ior, color, normal) = match *m {
                Material::Diffuse { albedo } => (MAT_DIFFUSE, 1.0, albedo, glam::Vec3::ZERO),
                Material::Mirror { reflectance } => {
                    (MAT_MIRROR, 1.0, reflectance, glam::Vec3::ZERO)
                }
                Material::Glass { ior } => (MAT_GLASS, ior, glam::Vec3::ONE, glam::Vec3::ZERO),
                Material::Emitter { radiance, normal } => (MAT_EMITTER, 1.0, radiance, normal),
            };
            materials.push([kind as f32, ior, 0.0, 0.0]);
            materials.push([color.x, color.y, color.z, 0.0]);
            materials.push([normal.x, normal.y, normal.z, 0.0]);
        }
        // Photon emission picks a light in proportion to its power (sum of channels).
        let weights: Vec<f32> = scene
            .lights
            .iter()
            .map(|l| l.power().element_sum())
            .collect();
        let total: f32 = weights.iter().sum();
        let mut cdf = 0.0;
        // Area light k is the k-th emitter shape (the loader appends them in order).
        let mut emitter_shapes = scene
            .shapes
            .iter()
            .enumerate()
            .filter(|(_, s)| matches!(scene.materials[s.material], Material::Emitter { .. }))
            .map(|(i, _)| i as f32);
        let mut lights = Vec::new();
        for (l, w) in scene.lights.iter().zip(&weights) {
            let v = |a: glam::Vec3| [a.x, a.y, a.z, 0.0];
            let probability = if total > 0.0 {
                w / total
            } else {
                1.0 / scene.lights.len() as f32
            };
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
            };
            lights.push([cdf, probability, primitive, 0.0]);
        }
        Self {
            primitives,
            materials,
            lights,
            primitive_count: scene.shapes.len(),
            light_count: scene.lights.len(),
            offset_floor: 1e-6 * scene.size(),
        }
    }
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
    pub primitive_count: usize,
    pub light_count: usize,
    pub offset_floor: f32,
}

fn upload(gpu: &Gpu, rows: &[[f32; 4]], width: u32) -> Result<Texture> {
    let height = (rows.len().div_ceil(width as usize) as u32).max(1);
    let mut data: Vec<f32> = rows.iter().flatten().copied().collect();
    data.resize(width as usize * height as usize * 4, 0.0);
    Texture::from_f32(gpu, width, height, TexFormat::Rgba32F, &data)
}

/// `values` (channels of `format` a texel) in rows of BVH_ROW_TEXELS texels.
fn upload_ints(gpu: &Gpu, mut values: Vec<i32>, format: TexFormat) -> Result<Texture> {
    let row = BVH_ROW_TEXELS as usize * format.channels();
    let height = values.len().div_ceil(row).max(1);
    values.resize(row * height, 0);
    Texture::from_i32_format(gpu, BVH_ROW_TEXELS, height as u32, format, &values)
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
        let nodes: Vec<i32> = bvh.nodes.iter().flat_map(|n| n.texels()).collect();
        let order: Vec<i32> = bvh.order.iter().map(|&i| i as i32).collect();
        Ok(Self {
            primitives: upload(gpu, &p.primitives, PRIMITIVE_TEXELS * PRIMITIVES_PER_ROW)?,
            bvh_nodes: upload_ints(gpu, nodes, TexFormat::Rgba32I)?,
            bvh_order: upload_ints(gpu, order, TexFormat::R32I)?,
            bvh_depth: bvh.depth,
            bvh_node_count: bvh.nodes.len(),
            materials: upload(gpu, &p.materials, MATERIAL_TEXELS)?,
            lights: upload(gpu, &p.lights, LIGHT_TEXELS)?,
            primitive_count: p.primitive_count,
            light_count: p.light_count,
            offset_floor: p.offset_floor,
        })
    }

    /// Binds the textures and counts that glsl/common/scene.glsl declares.
    pub fn bind(&self, b: &mut crate::gpu::Bindings<'_>) {
        b.texture("u_primitives", &self.primitives)
            .texture("u_bvh_nodes", &self.bvh_nodes)
            .texture("u_bvh_order", &self.bvh_order)
            .texture("u_materials", &self.materials)
            .texture("u_lights", &self.lights)
            .int("u_primitive_count", self.primitive_count as i32)
            .int("u_light_count", self.light_count as i32)
            .float("u_offset_floor", self.offset_floor);
    }
}
