//! Progressive refinement radiosity (Coombe and Harris, GPU Gems 2, chapter
//! 39) as a fourth method beside photon mapping, IGI and photon
//! differentials (`--method radiosity`). It rasterises rather than ray traces:
//!
//! 1. **Elements as texels.** Every diffuse primitive has two patches (its
//!    sides), each the root of a quadtree of res x res tiles of an element
//!    atlas (`elements`), laid out by the primitive's parameterisation
//!    (`element_point`; glsl/radiosity/parameterisation.glsl inverts it).
//!    Each element's position, normal, area and reflectance are textures;
//!    radiosity, residual and the direct part are atlas textures. Emitters
//!    are patches on their emitting side, with residual pi L_e; mirror and
//!    glass are not patches but still block.
//! 2. **The shooter** is the tile of most residual power (`tile_power`, a
//!    loop over its elements in place of the chapter's mipmap), chosen by
//!    the chapter's z-buffer sort: one point a tile into a 1 x 1 target at
//!    depth threshold / power (`select`). No fragment means converged: the
//!    far plane is the convergence threshold.
//! 3. **Shooting**, batched: the tile in S x S sub-elements (substructuring;
//!    `shooters`), each with its item buffer, the scene drawn through the
//!    hemispherical projection (`item_buffer.vert`) as patch IDs into one
//!    tile of a shared texture; then one pass over the atlas (`shoot`) puts
//!    every sub-element's oriented-disc form factor times visibility into a
//!    shot texture. Point lights shoot once, first, as six hemispheres about
//!    the axes, each receiver taking the one whose axis is nearest its
//!    direction (so none is seen near a hemisphere's rim, where the
//!    projection is coarsest).
//! 4. **Adaptive subdivision** (39.3, `--subdivide D`): after each shot,
//!    every live tile above depth D is tested for gradient discontinuities
//!    (`discontinuity`, counted by an occlusion query a tile); a tile with
//!    more than res / 2 of them splits into four children, which inherit its
//!    radiosity and residual (`inherit`) and take the shot again at their
//!    own elements, then are tested in turn. Then the shot is added
//!    (`accumulate`).
//! 5. **The image**: direct light and specular paths from the ray tracer, the
//!    radiosity less its direct part at each first diffuse hit (`lookup`,
//!    down the quadtree to the leaf), and from a caustic photon map the light
//!    that reaches x from a mirror or glass, which shots (stopped by both)
//!    cannot carry: by default every such path (`CausticPaths::All`), light
//!    a diffuse surface sends through them included. With `shoot_caustics`
//!    that light also bounces on: before the first shot each caustic
//!    record's reflected power is deposited into its element (`deposit`),
//!    and the lookup leaves that first reflection to the caustic map.
//!    With `gather_rays`, final gather (`gather`): rays from each first hit
//!    read the solution where they land, in place of the lookup at the hit.

mod elements;
mod gather;
mod options;
pub mod run;
mod subdivide;

pub use elements::{
    block_outline, element_point, full_tree, is_curved, onto_surface, tessellate, Elements, Node,
    Patch, Tile, CURVED_SEGMENTS, MAX_ATLAS_TEXELS,
};
pub use gather::SolutionGather;
pub use options::{
    ConvergencePoint, FormFactor, RadiosityOptions, RadiosityReport, MAX_GATHER_RAYS,
    MAX_SUBDIVIDE, SPLIT_FLOOR, SPLIT_SHARE,
};
pub use run::RadiosityRun;

use glam::Vec3;

use crate::error::Error;
use crate::gpu::{
    Bindings, DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture, VertexBuffer,
};
use crate::layout::{SHOOTER_OUTLINE, SHOOTER_TEXELS, TILE_ROW};
use crate::photon::PhotonFrames;
use crate::scene::pack::SceneTextures;
use crate::scene::{Light, Scene};

use super::{DirectLight, Image, Timings};

/// A shooter as the shoot pass reads it.
#[derive(Clone, Debug)]
struct Shooter {
    position: Vec3,
    point: bool,
    normal: Vec3,
    area: f32,
    energy: Vec3,
    /// The sub-element's outline (none for a point light).
    outline: Vec<Vec3>,
    /// The block's first texel in the atlas (its own elements).
    block_base: [u32; 2],
}

impl Shooter {
    /// The largest distance between two points of its outline (a disc's of
    /// its area where it has none).
    fn width(&self) -> f32 {
        let o = &self.outline;
        if o.is_empty() {
            return 2.0 * (self.area / std::f32::consts::PI).sqrt();
        }
        o.iter()
            .flat_map(|a| o.iter().map(move |b| a.distance(*b)))
            .fold(0.0, f32::max)
    }
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
    /// What the caustic deposit put into each element (also in `direct`).
    pub deposit: Texture,
    atlas_target: Target,
    residual_target: Target,
    /// The last shot's energy at each element (before `accumulate`).
    pub shot: Texture,
    shot_target: Target,
    nodes: Texture,
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
    queries: Vec<Query>,
    programs: Programs,
    pub indirect: Texture,
    indirect_target: Target,
    width: u32,
    height: u32,
    /// Power deposited from a caustic trace (`deposit`), luminance.
    deposited: f64,
}

struct Programs {
    power: Program,
    select: Program,
    shooters: Program,
    items: Program,
    shoot: Program,
    accumulate: Program,
    discontinuity: Program,
    inherit: Program,
    zero: Program,
    lookup: Program,
    gather_sum: Program,
    deposit: Program,
}

impl Programs {
    fn new(gpu: &Gpu) -> Result<Self> {
        let p = |name: &str| Program::fullscreen(gpu, name);
        Ok(Self {
            power: p("radiosity/tile_power.frag")?,
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
            accumulate: p("radiosity/accumulate.frag")?,
            discontinuity: p("radiosity/discontinuity.frag")?,
            inherit: p("radiosity/inherit.frag")?,
            zero: p("radiosity/zero.frag")?,
            lookup: p("radiosity/lookup.frag")?,
            gather_sum: p("radiosity/gather_sum.frag")?,
            deposit: Program::new(gpu, "radiosity/deposit.vert", "radiosity/deposit.frag", &[])?,
        })
    }
}

/// A texture of `count` records of one i32 or RGBA32F, TILE_ROW a row.
fn record_texture(gpu: &Gpu, count: usize, format: TexFormat) -> Result<Texture> {
    let count = count.max(1) as u32;
    Texture::new(gpu, count.min(TILE_ROW), count.div_ceil(TILE_ROW), format)
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
        let max = gpu.max_texture_size();
        let elements = Elements::new(scene, options.resolution, options.subdivide, max)?;
        if elements.patches.is_empty() {
            return Err(Error::InvalidOption(format!(
                "{} has no diffuse surface: radiosity has nothing to solve",
                scene.name
            )));
        }
        // At least 3 x 3 item buffers: a point light shoots as six hemispheres.
        let items_side = options.substructure.max(3) * options.item_buffer;
        if items_side > max {
            return Err(Error::TooLarge(format!(
                "item buffers of {items_side} texels a side: this driver allows {max}; lower --item-buffer"
            )));
        }
        let (w, h) = (elements.width, elements.height);
        let flat = |v: &[[f32; 4]]| v.iter().flatten().copied().collect::<Vec<f32>>();
        let upload = |v: &[[f32; 4]]| Texture::from_texels(gpu, w, h, TexFormat::Rgba32F, &flat(v));
        let position = upload(&elements.position)?;
        let normal = upload(&elements.normal)?;
        let albedo = upload(&elements.albedo)?;
        let radiosity = upload(&elements.emission)?;
        let residual = upload(&elements.emission)?;
        let direct = Texture::new(gpu, w, h, TexFormat::Rgba32F)?;
        let deposit = Texture::new(gpu, w, h, TexFormat::Rgba32F)?;
        Target::new(gpu, &[&direct, &deposit])?.clear([0.0; 4]);
        let atlas_target = Target::new(gpu, &[&radiosity, &residual, &direct, &deposit])?;
        let residual_target = Target::new(gpu, &[&residual])?;
        let shot = Texture::new(gpu, w, h, TexFormat::Rgba32F)?;
        let shot_target = Target::new(gpu, &[&shot])?;
        shot_target.clear([0.0; 4]);
        let nodes = record_texture(gpu, elements.node_capacity(), TexFormat::R32I)?;
        let patch_of_width = (elements.patch_of.len() as u32).clamp(1, 4096);
        let rows = (elements.patch_of.len() as u32)
            .div_ceil(patch_of_width)
            .max(1);
        let mut ids = elements.patch_of.clone();
        ids.resize((patch_of_width * rows) as usize, -1);
        let patch_of = Texture::from_texels(gpu, patch_of_width, rows, TexFormat::R32I, &ids)?;
        let power = record_texture(gpu, elements.capacity as usize, TexFormat::Rgba32F)?;
        let power_target = Target::new(gpu, &[&power])?;
        let pick = Texture::new(gpu, 1, 1, TexFormat::Rgba32F)?;
        let pick_target = Target::with_stencil(gpu, &[&pick])?;
        let items = Texture::new(gpu, items_side, items_side, TexFormat::Rgba32F)?;
        let items_target = Target::with_stencil(gpu, &[&items])?;
        let sub = options.substructure;
        // A shot's shooter records, a row each: the first 3 texels drawn by
        // `shooters`, read back, moved onto the surface and uploaded again
        // with their outlines for `shoot`; as many rows as item buffers
        // (point lights use 6).
        let shooters = Texture::new(gpu, SHOOTER_TEXELS, sub.max(3).pow(2), TexFormat::Rgba32F)?;
        let shooters_target = Target::new(gpu, &[&shooters])?;
        let vertices = VertexBuffer::from_f32(gpu, &tessellate(scene), &[3, 1])?;
        let indirect = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let r = Self {
            gpu: gpu.clone(),
            options: options.clone(),
            position,
            normal,
            albedo,
            radiosity,
            residual,
            direct,
            deposit,
            atlas_target,
            residual_target,
            shot,
            shot_target,
            nodes,
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
            queries: Vec::new(),
            programs: Programs::new(gpu)?,
            indirect_target: Target::new(gpu, &[&indirect])?,
            indirect,
            elements,
            width,
            height,
            deposited: 0.0,
        };
        r.upload_nodes()?;
        Ok(r)
    }

    fn upload_nodes(&self) -> Result<()> {
        let mut data = self.elements.encoded_nodes();
        data.resize(self.nodes.texel_count(), -1);
        self.nodes.upload(&data)
    }

    /// Solves to convergence or the shot limit, recording the unshot power
    /// after each shot. Adds "radiosity solve" to `timings`.
    pub fn solve(
        &mut self,
        scene: &Scene,
        textures: &SceneTextures,
        timings: &mut Timings,
        on_shot: &mut dyn FnMut(u32, f64),
    ) -> Result<RadiosityReport> {
        self.gpu.finish();
        let t0 = std::time::Instant::now();
        let mut report = RadiosityReport {
            patches: self.elements.patches.len(),
            element_resolution: self.options.resolution,
            ..Default::default()
        };
        let point_power = point_light_power(scene);
        let emitted = self.unshot()? - self.deposited;
        let total = emitted + point_power;
        if total <= 0.0 {
            return Err(Error::InvalidOption(format!(
                "{}: no light reaches a patch; radiosity has nothing to shoot",
                scene.name
            )));
        }
        let floor = SPLIT_FLOOR * (total / self.receiving_area()) as f32;
        report.split_floor = floor;
        // Point lights first, each as six hemispheres about the axes.
        for light in &scene.lights {
            if let Light::Point {
                position,
                intensity,
            } = *light
            {
                let hemisphere = |normal: Vec3| Shooter {
                    position,
                    point: true,
                    normal,
                    area: 0.0,
                    energy: intensity,
                    outline: Vec::new(),
                    block_base: [0; 2],
                };
                let axes = [Vec3::X, -Vec3::X, Vec3::Y, -Vec3::Y, Vec3::Z, -Vec3::Z];
                self.shoot(
                    scene,
                    textures,
                    &axes.map(hemisphere),
                    true,
                    floor,
                    &mut report,
                )?;
            }
        }
        let threshold = (f64::from(self.options.convergence) * total) as f32;
        let occlusion = Query::occlusion(&self.gpu)?;
        let mut unshot = self.unshot()?;
        report.convergence.push(ConvergencePoint {
            shot: 0,
            seconds: t0.elapsed().as_secs_f64(),
            unshot_fraction: unshot / total,
        });
        while report.shots < self.options.max_shots {
            crate::interrupt::check()?;
            let Some(tile) = self.select(threshold, &occlusion)? else {
                report.converged = true;
                break;
            };
            let shooters = self.sub_shooters(scene, tile)?;
            for s in &shooters {
                report.largest_shooter = report.largest_shooter.max(s.width());
            }
            let light = self.elements.patches[self.elements.tiles[tile].patch as usize].emitter;
            // Zeroed before the shot: a curved patch (the inside of a
            // sphere) receives some of its own light.
            self.zero_region(&self.residual_target, tile)?;
            self.shoot(scene, textures, &shooters, light, floor, &mut report)?;
            report.shots += 1;
            unshot = self.unshot()?;
            self.gpu.finish();
            report.convergence.push(ConvergencePoint {
                shot: report.shots,
                seconds: t0.elapsed().as_secs_f64(),
                unshot_fraction: unshot / total,
            });
            on_shot(report.shots, unshot / total);
        }
        self.gpu.finish();
        self.gpu.check("radiosity solve")?;
        report.unshot_fraction = unshot / total;
        report.caustic_shot_fraction = (self.deposited > 0.0).then(|| self.deposited / total);
        report.seconds = t0.elapsed().as_secs_f64();
        report.elements = self.elements.elements;
        report.tiles = self.elements.tiles.iter().filter(|t| t.alive).count();
        timings.add_both(
            "radiosity solve",
            0.0,
            report.seconds,
            report.shots as usize * 5,
        );
        Ok(report)
    }

    /// The area of every live receiving element (diffuse, either side).
    fn receiving_area(&self) -> f64 {
        let e = &self.elements;
        e.position
            .iter()
            .zip(&e.albedo)
            .filter(|(p, a)| p[3] > 0.0 && a[..3] != [0.0; 3])
            .map(|(p, _)| f64::from(p[3]))
            .sum::<f64>()
            .max(f64::MIN_POSITIVE)
    }

    /// The element atlas as its passes address it: each element's position
    /// (w = area), the elements a tile side and the tiles an atlas row.
    fn bind_atlas(&self, b: &mut Bindings<'_>) {
        b.texture("u_element_position", &self.position)
            .int("u_res", self.elements.res as i32)
            .int("u_tile_columns", self.elements.tile_columns as i32);
    }

    /// Each tile's power (read back): of its residual, its radiosity and
    /// the last shot.
    fn tile_powers(&self) -> Result<Vec<[f32; 3]>> {
        self.gpu.texture_barrier();
        let tiles = self.elements.tiles.len();
        let mut b = self.programs.power.bind();
        self.bind_atlas(&mut b);
        b.texture("u_residual", &self.residual)
            .texture("u_radiosity", &self.radiosity)
            .texture("u_shot", &self.shot)
            .int("u_tiles", tiles as i32)
            .draw_fullscreen(&self.power_target, &DrawState::PLAIN)?;
        let all = self.power.read_f32();
        Ok((0..tiles)
            .map(|p| [all[4 * p], all[4 * p + 1], all[4 * p + 2]])
            .collect())
    }

    /// The unshot power: the sum of the tiles' residual power.
    fn unshot(&self) -> Result<f64> {
        Ok(self.tile_powers()?.iter().map(|p| f64::from(p[0])).sum())
    }

    /// The chapter's z-buffer sort over the tile powers last drawn: the
    /// tile of most power, or None when none reaches `threshold`.
    fn select(&self, threshold: f32, occlusion: &Query) -> Result<Option<usize>> {
        self.pick_target.clear([-1.0; 4]);
        self.pick_target.clear_depth_stencil(1.0, 0);
        occlusion.around(|| {
            self.programs
                .select
                .bind()
                .texture("u_power", &self.power)
                .float("u_threshold", threshold)
                .draw_points(
                    &self.pick_target,
                    &DrawState::Z_BUFFER,
                    0,
                    self.elements.tiles.len() as i32,
                )
        })?;
        if occlusion.count() == 0 {
            return Ok(None);
        }
        let id = self.pick.read_f32()[0];
        Ok((id >= 0.0).then_some(id as usize))
    }

    /// The tile's S x S sub-elements as shooters (read back: their frames
    /// set the item buffers' uniforms), each moved onto the surface, with
    /// its outline.
    fn sub_shooters(&self, scene: &Scene, tile: usize) -> Result<Vec<Shooter>> {
        let t = self.elements.tiles[tile];
        let g = &scene.shapes[self.elements.patches[t.patch as usize].primitive].geometry;
        let (res, sub) = (self.elements.res, self.options.substructure);
        let block = res / sub;
        let base = self.elements.tile_base(tile);
        self.gpu.texture_barrier();
        let mut b = self.programs.shooters.bind();
        self.bind_atlas(&mut b);
        b.texture("u_residual", &self.residual)
            .texture("u_element_normal", &self.normal)
            .int("u_tile", tile as i32)
            .int("u_sub", self.options.substructure as i32)
            .int("u_power_centre", i32::from(!is_curved(g)))
            .draw_region(
                &self.shooters_target,
                &DrawState::PLAIN,
                [0, 0, 3, (self.options.substructure.pow(2)) as i32],
            )?;
        let data = self.shooters.read_f32();
        let rows = self.options.substructure.pow(2) as usize;
        let stride = 4 * SHOOTER_TEXELS as usize;
        Ok(data[..stride * rows]
            .chunks(stride)
            .enumerate()
            .filter(|(_, r)| r[7] > 0.0)
            .map(|(k, r)| {
                let (i0, j0) = (
                    t.origin[0] + (k as u32 % sub) * block,
                    t.origin[1] + (k as u32 / sub) * block,
                );
                Shooter {
                    position: onto_surface(
                        g,
                        Vec3::new(r[0], r[1], r[2]),
                        Vec3::new(r[4], r[5], r[6]),
                    ),
                    point: false,
                    normal: Vec3::new(r[4], r[5], r[6]),
                    area: r[7],
                    energy: Vec3::new(r[8], r[9], r[10]),
                    outline: block_outline(g, [i0, j0, i0 + block, j0 + block], res << t.depth),
                    block_base: [
                        base.0 + (k as u32 % sub) * block,
                        base.1 + (k as u32 / sub) * block,
                    ],
                }
            })
            .collect())
    }

    /// One shot: the shooters' item buffers, their energy at every element
    /// (into `shot`), the tiles it makes uneven split and shot again, then
    /// the shot added into radiosity, residual (and direct, from lights).
    fn shoot(
        &mut self,
        scene: &Scene,
        textures: &SceneTextures,
        shooters: &[Shooter],
        lights: bool,
        floor: f32,
        report: &mut RadiosityReport,
    ) -> Result<()> {
        self.item_buffers(textures, shooters)?;
        let e = &self.elements;
        self.shot_pass(shooters.len(), [0, 0, e.width as i32, e.rows_used() as i32])?;
        if self.options.subdivide > 0 {
            let t0 = std::time::Instant::now();
            self.refine(scene, shooters.len(), floor, report)?;
            self.gpu.finish();
            report.subdivision_seconds += t0.elapsed().as_secs_f64();
        }
        self.gpu.texture_barrier();
        let e = &self.elements;
        self.programs
            .accumulate
            .bind()
            .texture("u_shot", &self.shot)
            .texture("u_element_position", &self.position)
            .int("u_lights", i32::from(lights))
            .draw_region(
                &self.atlas_target,
                &DrawState::ADDITIVE,
                [0, 0, e.width as i32, e.rows_used() as i32],
            )?;
        // Added: the split test (`discontinuities`) reads radiosity + shot.
        self.shot_target.clear([0.0; 4]);
        self.gpu.check("radiosity shot")
    }

    /// Draws each shooter's item buffer and uploads the shooter records.
    fn item_buffers(&self, textures: &SceneTextures, shooters: &[Shooter]) -> Result<()> {
        let n = self.options.item_buffer;
        let columns = self.options.substructure.max(3);
        debug_assert!(shooters.len() as u32 <= columns * columns);
        // -2: no fragment (a rim texel); -1: a blocker that is no patch.
        self.items_target.clear([-2.0, 0.0, 0.0, 1.0]);
        self.items_target.clear_depth_stencil(1.0, 0);
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
                .draw_triangles(
                    &self.items_target,
                    &DrawState::Z_BUFFER,
                    viewport,
                    &self.vertices,
                )?;
        }
        let row = 4 * SHOOTER_TEXELS as usize;
        let mut data = vec![0f32; row * (columns * columns) as usize];
        for (k, s) in shooters.iter().enumerate() {
            data[row * k..row * k + 12].copy_from_slice(&[
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
                s.outline.len() as f32,
            ]);
            debug_assert!(s.outline.len() <= SHOOTER_OUTLINE as usize);
            for (v, p) in s.outline.iter().enumerate() {
                let at = row * k + 12 + 4 * v;
                let w = match v {
                    0 => s.block_base[0] as f32,
                    1 => s.block_base[1] as f32,
                    _ => 0.0,
                };
                data[at..at + 4].copy_from_slice(&[p.x, p.y, p.z, w]);
            }
        }
        self.shooters.upload_f32(&data)
    }

    /// The shot of the shooters last uploaded, at the elements of `region`.
    fn shot_pass(&self, shooters: usize, region: [i32; 4]) -> Result<()> {
        self.programs
            .shoot
            .bind()
            .texture("u_element_position", &self.position)
            .texture("u_element_normal", &self.normal)
            .texture("u_element_albedo", &self.albedo)
            .texture("u_shooters", &self.shooters)
            .int("u_shooter_count", shooters as i32)
            .texture("u_item_buffers", &self.items)
            .int("u_item_size", self.options.item_buffer as i32)
            .int("u_item_columns", self.options.substructure.max(3) as i32)
            .int(
                "u_polygon",
                i32::from(self.options.form_factor == FormFactor::Polygon),
            )
            .int(
                "u_block",
                (self.options.resolution / self.options.substructure) as i32,
            )
            .draw_region(&self.shot_target, &DrawState::PLAIN, region)
    }

    /// The indirect light at `direct`'s first hits, left in `indirect`: the
    /// solution read at each hit, or with `gather` the solution read where
    /// its rays land. `seed` draws the gather rays.
    pub fn run(
        &self,
        textures: &SceneTextures,
        direct: &DirectLight,
        gather: Option<&SolutionGather>,
        seed: u32,
        timings: &mut Timings,
        on_batch: &mut dyn FnMut(u32, u32),
    ) -> Result<()> {
        if let Some(g) = gather {
            return g.run(self, textures, direct, seed, timings, on_batch);
        }
        self.gpu.finish();
        let t0 = std::time::Instant::now();
        self.lookup(
            textures,
            LookupAt {
                position: &direct.diffuse_position,
                normal: &direct.diffuse_normal,
                throughput: &direct.diffuse_throughput,
            },
            None,
            &self.indirect_target,
        )?;
        self.gpu.finish();
        timings.add_since("radiosity lookup", 0.0, t0, 1);
        self.gpu.check("radiosity lookup")
    }

    /// `lookup.frag` at the points `at` into `target` (their size): at the
    /// first hits (`gather` None) each one's radiance from the solution less
    /// its direct part; at a batch of gather hits, the radiance each sends
    /// back, its direct part from a shadow ray a light.
    fn lookup(
        &self,
        textures: &SceneTextures,
        at: LookupAt<'_>,
        gather: Option<GatherBatch>,
        target: &Target,
    ) -> Result<()> {
        let mut b = self.programs.lookup.bind();
        textures.bind(&mut b);
        self.bind_atlas(&mut b);
        b.texture("u_diffuse_position", at.position)
            .texture("u_diffuse_normal", at.normal)
            .texture("u_diffuse_throughput", at.throughput)
            .int("u_gather", gather.is_some() as i32)
            .uint("u_seed", gather.map_or(0, |g| g.seed))
            .int("u_first_ray", gather.map_or(0, |g| g.first_ray) as i32)
            .int(
                "u_image_height",
                gather.map_or(0, |g| g.image_height) as i32,
            )
            .texture("u_radiosity", &self.radiosity)
            .texture("u_direct", &self.direct)
            .texture("u_deposited", &self.deposit)
            .texture("u_patch_of", &self.patch_of)
            .int("u_patch_of_width", self.patch_of_width as i32)
            .texture("u_nodes", &self.nodes)
            .draw_fullscreen(target, &DrawState::PLAIN)
    }

    /// Deposits the caustic trace's stored records into the elements they
    /// landed on (`deposit.vert`), before `solve`: the power added, as
    /// luminance.
    pub fn deposit(&mut self, textures: &SceneTextures, records: &PhotonFrames) -> Result<()> {
        let before = self.unshot()?;
        let e = &self.elements;
        let mut b = self.programs.deposit.bind();
        textures.bind(&mut b);
        self.bind_atlas(&mut b);
        records.bind_record_textures(&mut b);
        b.int("u_record_width", records.width as i32)
            .int("u_frame_height", records.frame_height as i32)
            .int("u_photons_used", records.photons_used as i32)
            .float("u_power_scale", records.power_scale)
            .texture("u_albedo", &self.albedo)
            .texture("u_patch_of", &self.patch_of)
            .int("u_patch_of_width", self.patch_of_width as i32)
            .texture("u_nodes", &self.nodes)
            .ivec2("u_atlas_size", [e.width as i32, e.height as i32])
            .draw_points(
                &self.atlas_target,
                &DrawState::ADDITIVE,
                0,
                records.record_count() as i32,
            )?;
        drop(b);
        self.gpu.check("radiosity caustic deposit")?;
        self.deposited += self.unshot()? - before;
        Ok(())
    }

    pub fn read_indirect(&self) -> Image {
        Image::from_gl_rgba(self.width, self.height, &self.indirect.read_f32())
    }
}

/// Points where the solution is read: a hit each texel (w of `position` > 0),
/// its normal facing the ray that found it and its throughput, w = the
/// primitive hit.
#[derive(Clone, Copy)]
struct LookupAt<'a> {
    position: &'a Texture,
    normal: &'a Texture,
    throughput: &'a Texture,
}

/// A batch of gather hits: the eye sample's seed, the index of the batch's
/// first ray among each pixel's, and the image's height (ray j of the batch
/// is row y + j x height).
#[derive(Clone, Copy)]
struct GatherBatch {
    seed: u32,
    first_ray: u32,
    image_height: u32,
}

/// The power of the scene's point lights, 4 pi I (luminance).
fn point_light_power(scene: &Scene) -> f64 {
    scene
        .lights
        .iter()
        .filter(|l| matches!(l, Light::Point { .. }))
        .map(|l| {
            f64::from(
                l.power(&scene.shapes)
                    .dot(Vec3::from(crate::layout::LUMINANCE)),
            )
        })
        .sum()
}
