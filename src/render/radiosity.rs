//! Progressive refinement radiosity (Coombe and Harris, GPU Gems 2, chapter
//! 39) as a fourth method beside photon mapping, IGI and photon
//! differentials (`--method radiosity`). It rasterises rather than ray traces:
//!
//! 1. **Elements as texels.** Every diffuse primitive has two patches (its
//!    sides), each a res x res tile of an element atlas laid out by the
//!    primitive's parameterisation (`element_point`; glsl/radiosity/
//!    parameterisation.glsl inverts it). Each element's position, normal,
//!    area and reflectance are textures made once; radiosity, residual and
//!    the direct part are atlas textures. Emitters are patches on their
//!    emitting side, with residual pi L_e; mirror and glass are not patches
//!    but still block.
//! 2. **The shooter** is the patch of most residual power (`patch_power`, a
//!    loop over its tile in place of the chapter's mipmap), chosen by the
//!    chapter's z-buffer sort: one point a patch into a 1 x 1 target at depth
//!    threshold / power (`select`). No fragment means converged: the far
//!    plane is the convergence threshold.
//! 3. **Shooting**, batched: the patch's tile in S x S sub-elements
//!    (substructuring; `shooters`), each with its item buffer, the scene
//!    drawn through the hemispherical projection (`item_buffer.vert`) as
//!    patch IDs into one tile of a shared texture; then one pass over the
//!    atlas (`shoot`) adds every sub-element's oriented-disc form factor times
//!    visibility into radiosity and residual; the patch's residual is zeroed.
//!    Point lights shoot once, first, as six hemispheres about the axes,
//!    each receiver taking the one whose axis is nearest its direction (so
//!    none is seen near a hemisphere's rim, where the projection is coarsest).
//! 4. **The image**: direct light and specular paths from the ray tracer, the
//!    radiosity less its direct part at each first diffuse hit (`lookup`), and
//!    caustics from a caustic photon map: radiosity has none, and light from
//!    a diffuse surface through glass or a mirror is in neither.
//!
//! Not built: the chapter's adaptive subdivision (quadtrees of 16 x 16
//! tiles); every patch has one uniform tile.

use glam::Vec3;

use crate::error::Error;
use crate::gpu::{
    Compare, DepthTest, DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture,
    VertexBuffer,
};
use crate::layout::PATCH_ROW;
use crate::scene::pack::SceneTextures;
use crate::scene::{Geometry, Light, Material, Scene};

use super::{DirectLight, Image, Timings};

/// How the radiosity solution runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RadiosityOptions {
    /// Elements per side of each patch's tile.
    pub resolution: u32,
    /// Shooters per side of a shooting patch (substructuring; divides `resolution`).
    pub substructure: u32,
    /// Texels per side of each item buffer.
    pub item_buffer: u32,
    /// Shots at most.
    pub max_shots: u32,
    /// Converged once no patch holds this fraction of the emitted power unshot.
    pub convergence: f32,
}

impl Default for RadiosityOptions {
    /// 16 x 16 elements a patch side (the chapter's leaf tiles), 4 x 4
    /// shooters a patch, 256^2 item buffers, and a patch shoots while it
    /// holds 0.01% of the emitted power (a priori; the unshot total is
    /// reported).
    fn default() -> Self {
        Self {
            resolution: 16,
            substructure: 4,
            item_buffer: 256,
            max_shots: 10_000,
            convergence: 1e-4,
        }
    }
}

impl RadiosityOptions {
    pub fn check(&self) -> Result<()> {
        let bad = |what: String| Err(Error::InvalidOption(what));
        if !(2..=256).contains(&self.resolution) {
            return bad(format!(
                "--elements {}: the allowed range is 2..=256",
                self.resolution
            ));
        }
        if self.substructure == 0 || !self.resolution.is_multiple_of(self.substructure) {
            return bad(format!(
                "--substructure {}: give a divisor of --elements ({})",
                self.substructure, self.resolution
            ));
        }
        if self.substructure > 8 {
            return bad(format!(
                "--substructure {}: at most 8 (64 item buffers a shot)",
                self.substructure
            ));
        }
        if !(16..=2048).contains(&self.item_buffer) {
            return bad(format!(
                "--item-buffer {}: the allowed range is 16..=2048",
                self.item_buffer
            ));
        }
        if !(self.convergence > 0.0 && self.convergence < 1.0) {
            return bad(format!(
                "--convergence {}: the allowed range is (0, 1)",
                self.convergence
            ));
        }
        Ok(())
    }
}

/// Texels an element atlas may hold (each of its seven textures is RGBA32F:
/// 256 MiB apiece at this size).
pub const MAX_ATLAS_TEXELS: u64 = 1 << 24;

/// One side of a primitive, with its tile of elements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Patch {
    pub primitive: usize,
    /// 0: the side the geometric normal points to; 1: the other.
    pub side: u32,
    pub emitter: bool,
}

/// The element atlas, as made on the CPU.
pub struct Elements {
    pub patches: Vec<Patch>,
    pub res: u32,
    pub tile_columns: u32,
    pub width: u32,
    pub height: u32,
    /// Per texel: position + area (0: no element), normal + patch, albedo, initial residual.
    pub position: Vec<[f32; 4]>,
    pub normal: Vec<[f32; 4]>,
    pub albedo: Vec<[f32; 4]>,
    pub emission: Vec<[f32; 4]>,
    /// Patch of (2 primitive + side), or -1.
    pub patch_of: Vec<i32>,
    pub elements: usize,
}

/// The point and outward normal of `g` at parameters (u, v) (the inverse of
/// glsl/radiosity/parameterisation.glsl's `patch_uv`).
pub fn element_point(g: &Geometry, u: f32, v: f32) -> (Vec3, Vec3) {
    use std::f32::consts::PI;
    match *g {
        Geometry::Sphere { center, radius } => {
            let (phi, theta) = (2.0 * PI * u, PI * v);
            let d = Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            );
            (center + radius * d, d)
        }
        Geometry::Cylinder {
            base,
            axis,
            radius,
            height,
        } => {
            let (t, s) = crate::sampling::basis_around(axis);
            let phi = 2.0 * PI * u;
            let r = phi.cos() * t + phi.sin() * s;
            (base + radius * r + v * height * axis, r)
        }
        Geometry::Parallelogram {
            corner,
            edge1,
            edge2,
        } => (
            corner + u * edge1 + v * edge2,
            edge1.cross(edge2).normalize(),
        ),
        Geometry::Triangle { v0, v1, v2 } => (
            v0 + u * (v1 - v0) + v * (v2 - v0),
            (v1 - v0).cross(v2 - v0).normalize(),
        ),
    }
}

/// Element (i, j)'s parameters: its cell's centre, or on a triangle's
/// diagonal the centroid of the half cell inside it (u + v < 1).
fn element_uv(g: &Geometry, i: u32, j: u32, res: u32) -> (f32, f32) {
    let n = res as f32;
    let third = matches!(g, Geometry::Triangle { .. }) && i + j + 1 == res;
    let c = if third { 1.0 / 3.0 } else { 0.5 };
    ((i as f32 + c) / n, (j as f32 + c) / n)
}

/// Segments around a sphere or cylinder in the item buffers' tessellation
/// (a sphere has half as many rows).
pub const CURVED_SEGMENTS: u32 = 32;

/// Where a sub-element shooter of a curved patch stands: its block's
/// centroid lies inside a sphere or cylinder, and would see the primitive's
/// inside, so it goes onto the surface and then, along its own normal n
/// (out for the outside patch, in for the inside one), twice the
/// tessellation's sagitta further, so that the facets nearest it are on the
/// side it shoots from. Planar shooters stay at their centroid.
pub fn onto_surface(g: &Geometry, p: Vec3, n: Vec3) -> Vec3 {
    let sagitta =
        |radius: f32| 2.0 * radius * (1.0 - (std::f32::consts::PI / CURVED_SEGMENTS as f32).cos());
    match *g {
        Geometry::Sphere { center, radius } => {
            center + radius * (p - center).normalize() + sagitta(radius) * n
        }
        Geometry::Cylinder {
            base, axis, radius, ..
        } => {
            let r = p - base;
            let along = r.dot(axis) * axis;
            base + along + radius * (r - along).normalize() + sagitta(radius) * n
        }
        _ => p,
    }
}

/// Element (i, j)'s area on a tile of res x res, 0 where it holds none.
fn element_area(g: &Geometry, i: u32, j: u32, res: u32) -> f32 {
    use std::f32::consts::PI;
    let n = res as f32;
    match *g {
        Geometry::Sphere { radius, .. } => {
            let (t0, t1) = (PI * j as f32 / n, PI * (j + 1) as f32 / n);
            radius * radius * (t0.cos() - t1.cos()) * 2.0 * PI / n
        }
        Geometry::Triangle { .. } => {
            // Whole cells of the (u, v) grid inside u + v <= 1, and the half
            // cells along the diagonal: the triangle's area exactly.
            let whole = 2.0 * crate::scene::triangle_area(g) / (n * n);
            match (i + j + 1).cmp(&res) {
                std::cmp::Ordering::Less => whole,
                std::cmp::Ordering::Equal => 0.5 * whole,
                std::cmp::Ordering::Greater => 0.0,
            }
        }
        _ => crate::scene::surface_area(g) / (n * n),
    }
}

impl Elements {
    /// The atlas of `scene` at `res` elements a side, or why it cannot be
    /// made: the driver's texture size, or MAX_ATLAS_TEXELS.
    pub fn new(scene: &Scene, res: u32, max_side: u32) -> Result<Self> {
        let patches = scene
            .shapes
            .iter()
            .map(|s| match scene.materials[s.material] {
                Material::Diffuse { .. } => 2u64,
                Material::Emitter { .. } => 1,
                _ => 0,
            })
            .sum::<u64>()
            .max(1);
        let columns = (patches as f64).sqrt().ceil() as u64;
        let (w, h) = (columns * res as u64, patches.div_ceil(columns) * res as u64);
        if w > max_side as u64 || h > max_side as u64 || w * h > MAX_ATLAS_TEXELS {
            return Err(Error::TooLarge(format!(
                "{patches} patches of {res} x {res} elements need an atlas of {w} x {h} texels; the limit is {max_side} a side and {MAX_ATLAS_TEXELS} in all: lower --elements (radiosity gives every side of every diffuse primitive its own tile, so large meshes do not fit)"
            )));
        }
        Ok(Self::layout(scene, res))
    }

    fn layout(scene: &Scene, res: u32) -> Self {
        let mut patches = Vec::new();
        let mut patch_of = vec![-1i32; 2 * scene.shapes.len()];
        for (prim, shape) in scene.shapes.iter().enumerate() {
            match scene.materials[shape.material] {
                Material::Diffuse { .. } => {
                    for side in 0..2 {
                        patch_of[2 * prim + side as usize] = patches.len() as i32;
                        patches.push(Patch {
                            primitive: prim,
                            side,
                            emitter: false,
                        });
                    }
                }
                Material::Emitter { normal, .. } => {
                    let n = element_point(&shape.geometry, 0.5, 0.5).1;
                    let side = u32::from(normal.is_some_and(|e| e.dot(n) < 0.0));
                    patch_of[2 * prim + side as usize] = patches.len() as i32;
                    patches.push(Patch {
                        primitive: prim,
                        side,
                        emitter: true,
                    });
                }
                _ => {}
            }
        }
        let count = patches.len().max(1) as u32;
        let tile_columns = (count as f64).sqrt().ceil() as u32;
        let tile_rows = count.div_ceil(tile_columns);
        let (width, height) = (tile_columns * res, tile_rows * res);
        let texels = (width * height) as usize;
        let mut e = Elements {
            patches,
            res,
            tile_columns,
            width,
            height,
            position: vec![[0.0; 4]; texels],
            normal: vec![[0.0; 4]; texels],
            albedo: vec![[0.0; 4]; texels],
            emission: vec![[0.0; 4]; texels],
            patch_of,
            elements: 0,
        };
        for (p, patch) in e.patches.clone().iter().enumerate() {
            let shape = &scene.shapes[patch.primitive];
            let (albedo, emitted) = match scene.materials[shape.material] {
                Material::Diffuse { albedo } => (albedo, Vec3::ZERO),
                Material::Emitter { radiance, .. } => (Vec3::ZERO, std::f32::consts::PI * radiance),
                _ => (Vec3::ZERO, Vec3::ZERO),
            };
            let sign = if patch.side == 0 { 1.0 } else { -1.0 };
            let base = (
                (p as u32 % tile_columns) * res,
                (p as u32 / tile_columns) * res,
            );
            for j in 0..res {
                for i in 0..res {
                    let area = element_area(&shape.geometry, i, j, res);
                    if area <= 0.0 {
                        continue;
                    }
                    let (u, v) = element_uv(&shape.geometry, i, j, res);
                    let (point, normal) = element_point(&shape.geometry, u, v);
                    let t = ((base.1 + j) * width + base.0 + i) as usize;
                    e.position[t] = point.extend(area).to_array();
                    e.normal[t] = (sign * normal).extend(p as f32).to_array();
                    e.albedo[t] = albedo.extend(0.0).to_array();
                    e.emission[t] = emitted.extend(0.0).to_array();
                    e.elements += 1;
                }
            }
        }
        e
    }
}

/// Every primitive as triangles for the item buffers: (x, y, z, primitive)
/// a vertex. Planar shapes are subdivided, since the hemispherical projection
/// bends their edges.
pub fn tessellate(scene: &Scene) -> Vec<f32> {
    let mut out = Vec::new();
    let fine = scene.shapes.len() < 4096;
    for (prim, shape) in scene.shapes.iter().enumerate() {
        let g = &shape.geometry;
        let (nu, nv) = match g {
            Geometry::Sphere { .. } => (CURVED_SEGMENTS, CURVED_SEGMENTS / 2),
            Geometry::Cylinder { .. } => (CURVED_SEGMENTS, 4),
            Geometry::Parallelogram { .. } => (16, 16),
            Geometry::Triangle { .. } => {
                if fine {
                    (4, 4)
                } else {
                    (1, 1)
                }
            }
        };
        let triangle = matches!(g, Geometry::Triangle { .. });
        let at = |i: u32, j: u32| element_point(g, i as f32 / nu as f32, j as f32 / nv as f32).0;
        let mut push = |p: Vec3| out.extend([p.x, p.y, p.z, prim as f32]);
        for j in 0..nv {
            for i in 0..nu {
                if triangle {
                    // The lower-left triangles of the (u, v) grid inside u + v <= 1.
                    if i + j < nu {
                        push(at(i, j));
                        push(at(i + 1, j));
                        push(at(i, j + 1));
                    }
                    if i + j + 1 < nu {
                        push(at(i + 1, j));
                        push(at(i + 1, j + 1));
                        push(at(i, j + 1));
                    }
                    continue;
                }
                push(at(i, j));
                push(at(i + 1, j));
                push(at(i + 1, j + 1));
                push(at(i, j));
                push(at(i + 1, j + 1));
                push(at(i, j + 1));
            }
        }
    }
    out
}

/// The convergence of a solution: after each recorded shot, the unshot
/// power as a fraction of all emitted.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct ConvergencePoint {
    pub shot: u32,
    pub seconds: f64,
    pub unshot_fraction: f64,
}

/// What a solution did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct RadiosityReport {
    pub patches: usize,
    pub elements: usize,
    pub element_resolution: u32,
    pub shots: u32,
    pub converged: bool,
    pub unshot_fraction: f64,
    pub seconds: f64,
    pub convergence: Vec<ConvergencePoint>,
}

/// A shooter as the shoot pass reads it.
#[derive(Clone, Copy, Debug)]
struct Shooter {
    position: Vec3,
    point: bool,
    normal: Vec3,
    area: f32,
    energy: Vec3,
}

/// The radiosity solution's textures and passes.
pub struct Radiosity {
    gpu: Gpu,
    options: RadiosityOptions,
    pub elements: Elements,
    pub position: Texture,
    pub normal: Texture,
    albedo: Texture,
    pub radiosity: Texture,
    pub residual: Texture,
    pub direct: Texture,
    atlas_target: Target,
    residual_target: Target,
    patch_of: Texture,
    patch_of_width: u32,
    power: Texture,
    power_target: Target,
    pick: Texture,
    pick_target: Target,
    pub items: Texture,
    items_target: Target,
    shooters: Texture,
    shooters_target: Target,
    vertices: VertexBuffer,
    far: f32,
    programs: Programs,
    pub indirect: Texture,
    indirect_target: Target,
    width: u32,
    height: u32,
}

struct Programs {
    power: Program,
    select: Program,
    shooters: Program,
    items: Program,
    shoot: Program,
    zero: Program,
    lookup: Program,
}

impl Radiosity {
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &RadiosityOptions,
    ) -> Result<Self> {
        options.check()?;
        let elements = Elements::new(scene, options.resolution, gpu.max_texture_size())?;
        if elements.patches.is_empty() {
            return Err(Error::InvalidOption(format!(
                "{} has no diffuse surface: radiosity has nothing to solve",
                scene.name
            )));
        }
        let max = gpu.max_texture_size();
        // At least 3 x 3 item buffers: a point light shoots as six hemispheres.
        let items_side = options.substructure.max(3) * options.item_buffer;
        if elements.width > max || elements.height > max || items_side > max {
            return Err(Error::TooLarge(format!(
                "an element atlas of {} x {} texels and item buffers of {items_side} a side: this driver allows {max}; lower --elements or --item-buffer",
                elements.width, elements.height
            )));
        }
        let (w, h) = (elements.width, elements.height);
        let flat = |v: &[[f32; 4]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let upload = |v: &[[f32; 4]]| Texture::from_f32(gpu, w, h, TexFormat::Rgba32F, &flat(v));
        let position = upload(&elements.position)?;
        let normal = upload(&elements.normal)?;
        let albedo = upload(&elements.albedo)?;
        let radiosity = upload(&elements.emission)?;
        let residual = upload(&elements.emission)?;
        let direct = upload(&vec![[0.0; 4]; elements.emission.len()])?;
        let atlas_target = Target::new(gpu, &[&radiosity, &residual, &direct])?;
        let residual_target = Target::new(gpu, &[&residual])?;
        let patch_of_width = (elements.patch_of.len() as u32).clamp(1, 4096);
        let rows = (elements.patch_of.len() as u32)
            .div_ceil(patch_of_width)
            .max(1);
        let mut ids = elements.patch_of.clone();
        ids.resize((patch_of_width * rows) as usize, -1);
        let patch_of = Texture::from_i32_format(gpu, patch_of_width, rows, TexFormat::R32I, &ids)?;
        let patches = elements.patches.len() as u32;
        let power = Texture::new(
            gpu,
            patches.min(PATCH_ROW),
            patches.div_ceil(PATCH_ROW),
            TexFormat::Rgba32F,
        )?;
        let power_target = Target::new(gpu, &[&power])?;
        let pick = Texture::new(gpu, 1, 1, TexFormat::Rgba32F)?;
        let pick_target = Target::with_stencil(gpu, &[&pick])?;
        let items = Texture::new(gpu, items_side, items_side, TexFormat::Rgba32F)?;
        let items_target = Target::with_stencil(gpu, &[&items])?;
        let sub = options.substructure;
        // A shot's shooter records, 3 texels a row: drawn by `shooters`, read
        // back, moved onto the surface and uploaded again for `shoot`; as
        // many rows as item buffers (point lights use 6).
        let shooters = Texture::new(gpu, 3, sub.max(3).pow(2), TexFormat::Rgba32F)?;
        let shooters_target = Target::new(gpu, &[&shooters])?;
        let vertices = VertexBuffer::from_f32(gpu, &tessellate(scene), &[3, 1])?;
        let indirect = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let p = |name: &str| Program::fullscreen(gpu, name);
        Ok(Self {
            gpu: gpu.clone(),
            options: options.clone(),
            position,
            normal,
            albedo,
            radiosity,
            residual,
            direct,
            atlas_target,
            residual_target,
            patch_of,
            patch_of_width,
            power,
            power_target,
            pick,
            pick_target,
            items,
            items_target,
            shooters,
            shooters_target,
            vertices,
            far: 4.0 * scene.size(),
            programs: Programs {
                power: p("radiosity/patch_power.frag")?,
                select: Program::new(gpu, "radiosity/select.vert", "radiosity/select.frag", &[])?,
                shooters: p("radiosity/shooters.frag")?,
                items: Program::with_geometry(
                    gpu,
                    "radiosity/item_buffer.vert",
                    "radiosity/item_buffer.geom",
                    "radiosity/item_buffer.frag",
                    &[],
                )?,
                shoot: p("radiosity/shoot.frag")?,
                zero: p("radiosity/zero.frag")?,
                lookup: p("radiosity/lookup.frag")?,
            },
            indirect_target: Target::new(gpu, &[&indirect])?,
            indirect,
            elements,
            width,
            height,
        })
    }

    /// Solves to convergence or the shot limit, recording the unshot power
    /// after each shot. Adds "radiosity solve" to `timings`.
    pub fn solve(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        timings: &mut Timings,
        on_shot: &mut dyn FnMut(u32, f64),
    ) -> Result<RadiosityReport> {
        let gpu = &self.gpu;
        gpu.finish();
        let t0 = std::time::Instant::now();
        let mut report = RadiosityReport {
            patches: self.elements.patches.len(),
            elements: self.elements.elements,
            element_resolution: self.options.resolution,
            ..Default::default()
        };
        // Point lights first, each as six hemispheres about the axes.
        let mut point_power = 0.0f64;
        for light in &scene.lights {
            if let Light::Point {
                position,
                intensity,
            } = *light
            {
                point_power += 4.0
                    * std::f64::consts::PI
                    * f64::from(intensity.dot(Vec3::from(crate::layout::LUMINANCE)));
                let hemisphere = |normal: Vec3| Shooter {
                    position,
                    point: true,
                    normal,
                    area: 0.0,
                    energy: intensity,
                };
                let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
                self.shoot(textures, &axes.map(hemisphere), true)?;
            }
        }
        let patch_power = self.patch_powers()?;
        let total = patch_power.iter().map(|&p| f64::from(p)).sum::<f64>() + point_power;
        if total <= 0.0 {
            return Err(Error::InvalidOption(format!(
                "{}: no light reaches a patch; radiosity has nothing to shoot",
                scene.name
            )));
        }
        let threshold = (f64::from(self.options.convergence) * total) as f32;
        let occlusion = Query::occlusion(gpu)?;
        let mut unshot = patch_power.iter().map(|&p| f64::from(p)).sum::<f64>();
        report.convergence.push(ConvergencePoint {
            shot: 0,
            seconds: t0.elapsed().as_secs_f64(),
            unshot_fraction: unshot / total,
        });
        while report.shots < self.options.max_shots {
            crate::interrupt::check()?;
            let Some(patch) = self.select(threshold, &occlusion)? else {
                report.converged = true;
                break;
            };
            let shooters = self.sub_shooters(scene, patch)?;
            let light = self.elements.patches[patch].emitter;
            // Zeroed before the shot: a curved patch (the inside of a
            // sphere) receives some of its own light.
            self.zero_residual(patch)?;
            self.shoot(textures, &shooters, light)?;
            report.shots += 1;
            let powers = self.patch_powers()?;
            unshot = powers.iter().map(|&p| f64::from(p)).sum();
            gpu.finish();
            report.convergence.push(ConvergencePoint {
                shot: report.shots,
                seconds: t0.elapsed().as_secs_f64(),
                unshot_fraction: unshot / total,
            });
            on_shot(report.shots, unshot / total);
        }
        gpu.finish();
        gpu.check("radiosity solve")?;
        report.unshot_fraction = unshot / total;
        report.seconds = t0.elapsed().as_secs_f64();
        timings.add_both(
            "radiosity solve",
            0.0,
            report.seconds,
            report.shots as usize * 5,
        );
        Ok(report)
    }

    /// Each patch's residual power (read back).
    fn patch_powers(&self) -> Result<Vec<f32>> {
        self.gpu.texture_barrier();
        self.programs
            .power
            .bind()
            .texture("u_residual", &self.residual)
            .texture("u_element_position", &self.position)
            .int("u_patches", self.elements.patches.len() as i32)
            .int("u_res", self.elements.res as i32)
            .int("u_tile_columns", self.elements.tile_columns as i32)
            .draw_fullscreen(&self.power_target, &DrawState::PLAIN)?;
        let all = self.power.read_f32();
        Ok((0..self.elements.patches.len())
            .map(|p| all[4 * p])
            .collect())
    }

    /// The chapter's z-buffer sort over the patch powers last drawn: the
    /// patch of most power, or None when none reaches `threshold`.
    fn select(&self, threshold: f32, occlusion: &Query) -> Result<Option<usize>> {
        self.pick_target.clear([-1.0; 4]);
        self.pick_target.clear_depth_stencil(1.0, 0);
        let state = DrawState {
            depth: DepthTest::On {
                compare: Compare::Less,
                write: true,
            },
            ..DrawState::PLAIN
        };
        occlusion.begin();
        let drawn = self
            .programs
            .select
            .bind()
            .texture("u_power", &self.power)
            .float("u_threshold", threshold)
            .draw_points(
                &self.pick_target,
                &state,
                0,
                self.elements.patches.len() as i32,
            );
        occlusion.end();
        drawn?;
        if occlusion.count() == 0 {
            return Ok(None);
        }
        let id = self.pick.read_f32()[0];
        Ok((id >= 0.0).then_some(id as usize))
    }

    /// The patch's S x S sub-elements as shooters (read back: their frames
    /// set the item buffers' uniforms), each moved onto the surface.
    fn sub_shooters(&self, scene: &Scene, patch: usize) -> Result<Vec<Shooter>> {
        let g = &scene.shapes[self.elements.patches[patch].primitive].geometry;
        self.gpu.texture_barrier();
        self.programs
            .shooters
            .bind()
            .texture("u_residual", &self.residual)
            .texture("u_element_position", &self.position)
            .texture("u_element_normal", &self.normal)
            .int("u_patch", patch as i32)
            .int("u_res", self.elements.res as i32)
            .int("u_tile_columns", self.elements.tile_columns as i32)
            .int("u_sub", self.options.substructure as i32)
            .draw_region(
                &self.shooters_target,
                &DrawState::PLAIN,
                [0, 0, 3, (self.options.substructure.pow(2)) as i32],
            )?;
        let data = self.shooters.read_f32();
        let rows = self.options.substructure.pow(2) as usize;
        Ok(data[..12 * rows]
            .chunks(12)
            .filter(|r| r[7] > 0.0)
            .map(|r| Shooter {
                position: onto_surface(g, Vec3::new(r[0], r[1], r[2]), Vec3::new(r[4], r[5], r[6])),
                point: false,
                normal: Vec3::new(r[4], r[5], r[6]),
                area: r[7],
                energy: Vec3::new(r[8], r[9], r[10]),
            })
            .collect())
    }

    /// The shooters' item buffers, then their energy into every element.
    fn shoot(&self, textures: &SceneTextures, shooters: &[Shooter], lights: bool) -> Result<()> {
        let gpu = &self.gpu;
        let n = self.options.item_buffer;
        let columns = self.options.substructure.max(3);
        debug_assert!(shooters.len() as u32 <= columns * columns);
        // -2: no fragment (a rim texel); -1: a blocker that is no patch.
        self.items_target.clear([-2.0, 0.0, 0.0, 1.0]);
        self.items_target.clear_depth_stencil(1.0, 0);
        let state = DrawState {
            depth: DepthTest::On {
                compare: Compare::Less,
                write: true,
            },
            ..DrawState::PLAIN
        };
        for (k, s) in shooters.iter().enumerate() {
            let (t, b) = crate::sampling::basis_around(s.normal);
            let k = k as u32;
            let viewport = [
                ((k % columns) * n) as i32,
                ((k / columns) * n) as i32,
                n as i32,
                n as i32,
            ];
            let mut bind = self.programs.items.bind();
            textures.bind(&mut bind);
            bind.texture("u_patch_of", &self.patch_of)
                .int("u_patch_of_width", self.patch_of_width as i32)
                .vec3("u_origin", s.position.to_array())
                .vec3("u_tangent", t.to_array())
                .vec3("u_bitangent", b.to_array())
                .vec3("u_normal", s.normal.to_array())
                .float("u_far", self.far)
                .float("u_near", self.far * 1e-6)
                .draw_triangles(&self.items_target, &state, viewport, &self.vertices)?;
        }
        let mut data = vec![0f32; 12 * (columns * columns) as usize];
        for (k, s) in shooters.iter().enumerate() {
            data[12 * k..12 * k + 12].copy_from_slice(&[
                s.position.x,
                s.position.y,
                s.position.z,
                f32::from(u8::from(s.point)),
                s.normal.x,
                s.normal.y,
                s.normal.z,
                s.area,
                s.energy.x,
                s.energy.y,
                s.energy.z,
                0.0,
            ]);
        }
        self.shooters.upload_f32(&data)?;
        self.programs
            .shoot
            .bind()
            .texture("u_element_position", &self.position)
            .texture("u_element_normal", &self.normal)
            .texture("u_element_albedo", &self.albedo)
            .texture("u_shooters", &self.shooters)
            .int("u_shooter_count", shooters.len() as i32)
            .texture("u_item_buffers", &self.items)
            .int("u_item_size", n as i32)
            .int("u_item_columns", columns as i32)
            .int("u_lights", i32::from(lights))
            .draw_fullscreen(&self.atlas_target, &DrawState::ADDITIVE)?;
        gpu.check("radiosity shot")
    }

    fn zero_residual(&self, patch: usize) -> Result<()> {
        let res = self.elements.res;
        let c = self.elements.tile_columns;
        let region = [
            ((patch as u32 % c) * res) as i32,
            ((patch as u32 / c) * res) as i32,
            res as i32,
            res as i32,
        ];
        self.programs
            .zero
            .bind()
            .draw_region(&self.residual_target, &DrawState::PLAIN, region)
    }

    /// The indirect light at `direct`'s first hits, left in `indirect`.
    pub fn run(
        &self,
        textures: &SceneTextures,
        direct: &DirectLight,
        timings: &mut Timings,
    ) -> Result<()> {
        self.gpu.finish();
        let t0 = std::time::Instant::now();
        let mut b = self.programs.lookup.bind();
        textures.bind(&mut b);
        b.texture("u_diffuse_position", &direct.diffuse_position)
            .texture("u_diffuse_normal", &direct.diffuse_normal)
            .texture("u_diffuse_throughput", &direct.diffuse_throughput)
            .texture("u_radiosity", &self.radiosity)
            .texture("u_direct", &self.direct)
            .texture("u_element_position", &self.position)
            .texture("u_patch_of", &self.patch_of)
            .int("u_patch_of_width", self.patch_of_width as i32)
            .int("u_res", self.elements.res as i32)
            .int("u_tile_columns", self.elements.tile_columns as i32)
            .draw_fullscreen(&self.indirect_target, &DrawState::PLAIN)?;
        drop(b);
        self.gpu.finish();
        timings.add_both("radiosity lookup", 0.0, t0.elapsed().as_secs_f64(), 1);
        self.gpu.check("radiosity lookup")
    }

    pub fn read_indirect(&self) -> Image {
        Image::from_gl_rgba(self.width, self.height, &self.indirect.read_f32())
    }
}
