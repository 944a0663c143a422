//! Stochastic progressive photon mapping (Hachisuka and Jensen 2009) on the
//! paper's passes: each iteration re-jitters every pixel's eye path (the
//! existing ray tracer, so antialiasing and the random glass choice average
//! out), traces a fresh photon batch (the existing photon passes), builds a map
//! (bitonic or stencil, unchanged) and gathers at each pixel's visible point
//! with the pixel's own radius, updating its radius, photon count and flux in
//! place (`glsl/render/sppm_update.frag`). It converges to the exact image:
//! the radius shrinks to zero while the photons gathered grow without bound.
//!
//! Direct light comes from shadow rays at the visible point, as in the paper's
//! split; photons are stored from their second hit on, so nothing is counted
//! twice: light -> visible point by shadow rays (point lights exactly, with
//! sharp shadows), light -> (specular or diffuse)+ -> visible point by photons
//! (caustics through glass, which blocks shadow rays, included), emitters seen
//! along the eye path by the ray tracer. `DirectLighting::Photons` stores first
//! hits instead (a test of the photon half alone).

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::photon::{
    BitonicBuild, BuildMethod, CountingBuild, Grid, GridKind, PhotonBatch, PhotonMap, PhotonTracer,
    StencilRouting, TraceConfig,
};
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;
use crate::timing::Timings;

pub mod options;
mod run;

pub use options::{
    DirectLighting, SppmOptions, SppmStart, DEFAULT_SPPM_LEAK, DEFAULT_START_PHOTONS,
    DEFAULT_START_PIXELS,
};
pub use run::{render_sppm, SppmOutput};

use crate::image::Image;
use crate::render::adaptive::AdaptiveStats;
use crate::render::direct::DirectLight;
use crate::render::eye_paths::{trace_eye_paths, EyeSample};
use crate::render::observer::{At, RenderObserver};
use crate::render::options::RenderOptions;
use crate::render::plan::PassPlan;
use crate::render::radiance_estimate::LeakTest;
use crate::render::ray_trace::RayTracer;
pub use crate::render::sppm_adaptive::SppmState;
use crate::render::sppm_adaptive::{default_pilot, SppmAdaptive};

/// Cells per grid at most, by build: the sorted map's cell table, and stencil
/// routing's m x m slots a cell.
const MAX_CELLS_SORTED: u64 = 1 << 22;
const MAX_CELLS_ROUTED: u64 = 1 << 18;

/// Iterations after which the largest radius is read back to size the grid:
/// powers of two, then every 64th (a 4-byte read; radii only shrink, so a
/// stale maximum is still an upper bound).
fn reads_radius(iteration: u32) -> bool {
    iteration.is_power_of_two() || iteration.is_multiple_of(64)
}

enum Builder {
    Counting(Box<CountingBuild>),
    Bitonic(Box<BitonicBuild>),
    Stencil(Box<StencilRouting>, u32),
}

/// A progressive render in progress: call `iterate` as often as wanted.
pub struct Sppm {
    gpu: Gpu,
    /// Each iteration's grid storage (`--grid`): uniform, or hashed (§4.4).
    storage: crate::photon::GridStorage,
    /// The scene as SPPM traces it (bounces, shadow rays, first-hit storage).
    scene: Scene,
    options: SppmOptions,
    seed: u32,
    plan: PassPlan,
    textures: SceneTextures,
    tracer: RayTracer,
    pub direct: DirectLight,
    photons: PhotonTracer,
    batch: PhotonBatch,
    builder: Builder,
    pub state: SppmState,
    update: Program,
    compose: Program,
    radius: Program,
    reduce: Program,
    image: Texture,
    image_target: Target,
    pub iteration: u32,
    pub initial_radius: f32,
    /// The grid cell size in use: at least the largest radius of a pixel that
    /// has gathered photons, and no less than a quarter of the first radius.
    pub cell: f32,
    /// The last iteration's photon map and grid (for tests and `--explain`).
    pub map: Option<PhotonMap>,
    pub grid: Option<Grid>,
    /// The leak tests the gather applies.
    pub leak: LeakTest,
    /// Adaptive sampling's plan and packed state (`--adaptive`).
    pub adaptive: Option<SppmAdaptive>,
    /// The start of each pixel's radius, until the first iteration has used it.
    pending_start: Option<SppmStart>,
    start: Program,
}

impl Sppm {
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        options: &RenderOptions,
        sppm: &SppmOptions,
    ) -> Result<Self> {
        let mut config = options.method.photons().cloned().unwrap_or_default();
        let leak = sppm.leak.unwrap_or(DEFAULT_SPPM_LEAK);
        // A hash table's size follows the photons, not the cells, so small
        // radii cost no larger cell table.
        config.grid = sppm.grid.unwrap_or(if config.faithful {
            GridKind::Uniform
        } else {
            GridKind::Hash
        });
        let scene = sppm_scene(scene, sppm)?;
        let (w, h) = (options.width, options.height);
        let mut plan = PassPlan::new(&scene, options);
        plan.jitter = true;
        plan.spp = 1;
        plan.light_sampling = sppm.direct == DirectLighting::ShadowRays;
        let textures = SceneTextures::new(gpu, &scene)?;
        let photons = PhotonTracer::with_config(
            gpu,
            TraceConfig {
                stop_when_dead: true,
                // `--faithful` keeps the paper's pass per photon bounce.
                fused: !config.faithful,
                ..config.trace()
            },
        )?;
        let batch = photons.batch(&scene, sppm.photons_per_iteration)?;
        let builder = match config.build_method() {
            BuildMethod::Counting => Builder::Counting(Box::new(CountingBuild::new(gpu)?)),
            BuildMethod::Bitonic => Builder::Bitonic(Box::new(BitonicBuild::with_addressing(
                gpu,
                config.faithful,
            )?)),
            BuildMethod::Stencil => {
                Builder::Stencil(Box::new(StencilRouting::new(gpu)?), config.stencil_block)
            }
        };
        let t = || Texture::new(gpu, w, h, TexFormat::Rgba32F);
        let adaptive = match &sppm.adaptive {
            None => None,
            Some(a) => {
                if sppm.direct == DirectLighting::Photons {
                    return Err(Error::InvalidOption(
                        "adaptive SPPM interpolates the photon half on a plan fixed after its pilot; with --sppm-direct photons that half holds direct light and its hard shadows too: use --sppm-direct shadow-rays".into(),
                    ));
                }
                let pilot = sppm
                    .adaptive_pilot
                    .unwrap_or(default_pilot(sppm.iterations));
                if pilot == 0 || pilot >= sppm.iterations {
                    return Err(Error::InvalidOption(format!(
                        "adaptive SPPM plans after a pilot of {pilot} iteration(s) and needs iterations after it: the pilot's allowed range is 1..={} for --iterations {}",
                        sppm.iterations.saturating_sub(1),
                        sppm.iterations
                    )));
                }
                Some(SppmAdaptive::new(gpu, w, h, a.clone(), pilot)?)
            }
        };
        let initial_radius = sppm.initial_radius.unwrap_or(scene.photon_map.max_radius);
        let mut gather_defines = leak.defines();
        if config.build == BuildMethod::Stencil {
            gather_defines.push(("ROUTED", "1".to_string()));
        }
        let pending_start = pending_start(sppm)?;
        let mut start_defines = gather_defines.clone();
        if sppm.start.photons.is_some() {
            start_defines.push(("START_PHOTONS", "1".to_string()));
        }
        Error::check_positive(
            "sppm.initial_radius",
            initial_radius,
            "the first radius must be a positive number",
        )?;
        let state = SppmState::new(gpu, w, h)?;
        state
            .flux
            .upload(&[0.0, 0.0, 0.0, initial_radius * initial_radius].repeat((w * h) as usize))?;
        state.sums.upload(&vec![0f32; (w * h * 4) as usize])?;
        let image = t()?;
        let image_target = Target::new(gpu, &[&image])?;
        Ok(Self {
            gpu: gpu.clone(),
            options: sppm.clone(),
            seed: options.seed,
            plan,
            tracer: RayTracer::new(gpu, w, h)?,
            direct: DirectLight::new(gpu, w, h)?,
            photons,
            batch,
            builder,
            storage: config.storage(sppm.photons_per_iteration),
            state,
            update: Program::fullscreen_with(gpu, "render/sppm_update.frag", &gather_defines)?,
            compose: Program::fullscreen(gpu, "render/sppm_compose.frag")?,
            radius: Program::fullscreen(gpu, "render/sppm_radius.frag")?,
            reduce: Program::fullscreen(gpu, "common/max_reduce.frag")?,
            image,
            image_target,
            iteration: 0,
            initial_radius,
            cell: initial_radius,
            map: None,
            grid: None,
            leak,
            textures,
            scene,
            adaptive,
            pending_start,
            start: Program::fullscreen_with(gpu, "render/sppm_start.frag", &start_defines)?,
        })
    }

    /// Each pixel's first radius, at this first iteration's visible points
    /// (and map, for `SppmStart::Photons`): `glsl/render/sppm_start.frag`.
    fn start_radii(&self, map: &PhotonMap, start: SppmStart) -> Result<()> {
        let camera = &self.scene.camera;
        let mut b = self.start.bind();
        if let Some(k) = start.photons {
            self.bind_gather(&mut b, map);
            b.int("u_k", k as i32);
        }
        // 0: no bound by footprints.
        b.float("u_pixels", start.pixels.unwrap_or(0.0));
        b.texture("u_state_flux", &self.state.flux)
            .texture("u_state_direct", &self.state.sums)
            .texture("u_diffuse_position", &self.direct.diffuse_position)
            .texture("u_diffuse_normal", &self.direct.diffuse_normal)
            .float("u_first_radius2", self.cell * self.cell)
            .vec3("u_camera_position", camera.position.to_array())
            .float(
                "u_pixel_angle",
                2.0 * (camera.vfov_degrees.to_radians() * 0.5).tan() / self.plan.height as f32,
            )
            .draw_fullscreen(&self.state.target, &DrawState::PLAIN)?;
        self.gpu.texture_barrier();
        Ok(())
    }

    /// The photon map, its grid and the leak tests' inputs, as
    /// `render/sppm_gather.glsl` declares them.
    fn bind_gather(&self, b: &mut crate::gpu::Bindings<'_>, map: &PhotonMap) {
        self.textures.bind(b);
        map.bind(b);
        b.texture("u_map_incoming", map.incoming());
        if matches!(self.leak, LeakTest::Disc | LeakTest::DiscAndVisibility) {
            b.float("u_disc_radius", self.initial_radius);
        }
    }

    /// The scene as SPPM traces it.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// One iteration: eye paths, a photon batch, its map, the gather and update.
    pub fn iterate(
        &mut self,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<()> {
        let i = self.iteration + 1;
        let seed = crate::random::sample_seed(self.seed, i);
        if self
            .adaptive
            .as_ref()
            .is_some_and(|a| a.planned.is_none() && self.iteration == a.pilot)
        {
            // Before this iteration's eye paths replace the pilot's first hits.
            let wall = std::time::Instant::now();
            self.compose(false, true)?;
            let a = self.adaptive.as_mut().expect("adaptive");
            a.plan(&self.direct, &self.image, &self.state)?;
            self.gpu.finish();
            timings.add_since("adaptive plan", 0.0, wall, 12);
        }
        let at = At {
            view: 0,
            views: 1,
            sample: i - 1,
            samples: self.options.iterations,
        };
        let eye = EyeSample {
            camera: &self.scene.camera,
            sample: 0,
            seed,
        };
        trace_eye_paths(
            &self.gpu,
            &self.plan,
            &self.textures,
            &self.tracer,
            &self.direct,
            &eye,
            timings,
            observer,
            at,
        )?;
        let wall = std::time::Instant::now();
        self.photons
            .trace_batch(&self.scene, &self.textures, &mut self.batch, seed)?;
        let frames = &self.batch.frames;
        timings.add_since(
            "trace photons",
            frames.gpu_seconds,
            wall,
            frames.passes as usize,
        );
        let wall = std::time::Instant::now();
        let grid =
            Grid::over_scene(&self.scene, self.cell, self.max_cells()).with_storage(self.storage);
        let mut stages = Timings::default();
        let map = match &self.builder {
            Builder::Counting(b) => PhotonMap::Sorted(b.build(frames, &grid, &mut stages)?),
            Builder::Bitonic(b) => PhotonMap::Sorted(b.build(frames, &grid, &mut stages)?),
            Builder::Stencil(s, m) => PhotonMap::Routed(s.build(
                frames,
                &grid,
                *m,
                crate::photon::VertexFeed::VertexFetch,
                &mut stages,
            )?),
        };
        self.gpu.finish();
        timings.add_folded("build map", &stages, wall);
        if let Some(start) = self.pending_start.take() {
            let wall = std::time::Instant::now();
            self.start_radii(&map, start)?;
            self.gpu.finish();
            timings.add_since("first radii", 0.0, wall, 1);
        }
        let wall = std::time::Instant::now();
        self.gather_and_update(&map)?;
        self.gpu.finish();
        timings.add_since("gather + update", 0.0, wall, 1);
        self.iteration = i;
        if reads_radius(i) {
            let wall = std::time::Instant::now();
            let largest = self.largest_radius()?;
            self.cell = largest.max(0.25 * self.initial_radius).min(self.cell);
            timings.add_since("largest radius", 0.0, wall, 1);
        }
        self.map = Some(map);
        self.grid = Some(grid);
        self.gpu.check("SPPM iteration")
    }

    fn max_cells(&self) -> u64 {
        match self.builder {
            Builder::Counting(_) | Builder::Bitonic(_) => MAX_CELLS_SORTED,
            Builder::Stencil(..) => MAX_CELLS_ROUTED,
        }
    }

    /// The gather at each visible point and the in-place update; adaptive
    /// after the pilot, direct light at every pixel and the gather at the
    /// packed computed pixels.
    fn gather_and_update(&self, map: &PhotonMap) -> Result<()> {
        let planned = self
            .adaptive
            .as_ref()
            .and_then(|a| Some((a, a.planned.as_ref()?)));
        let Some((adaptive, planned)) = planned else {
            return self.update(map, &self.state, &self.direct, true, None);
        };
        self.update(map, &self.state, &self.direct, false, None)?;
        adaptive.pyramid.pack_hits(&self.direct)?;
        let rows = Some(planned.rows as i32);
        self.update(map, &planned.state, &adaptive.pyramid.packed, true, rows)
    }

    /// One update pass over `state` at the visible points `hits`, on its
    /// first `rows` rows (all when None); `gather` false adds direct light only.
    fn update(
        &self,
        map: &PhotonMap,
        state: &SppmState,
        hits: &DirectLight,
        gather: bool,
        rows: Option<i32>,
    ) -> Result<()> {
        let mut b = self.update.bind();
        self.bind_gather(&mut b, map);
        hits.bind_weights(&mut b);
        b.texture("u_state_flux", &state.flux)
            .texture("u_state_direct", &state.sums)
            .texture("u_direct", &hits.radiance)
            .texture("u_diffuse_position", &hits.diffuse_position)
            .float("u_alpha", self.options.alpha)
            .float("u_first_radius2", self.cell * self.cell)
            .int("u_gather", gather as i32);
        match rows {
            None => b.draw_fullscreen(&state.target, &DrawState::PLAIN)?,
            Some(rows) => b.draw_region(
                &state.target,
                &DrawState::PLAIN,
                [0, 0, state.flux.width as i32, rows],
            )?,
        }
        // The next iteration reads what this one wrote.
        self.gpu.texture_barrier();
        Ok(())
    }

    /// The largest radius among pixels that have gathered photons (a max
    /// reduction on the GPU, one float read back); 0 if none has. Adaptive,
    /// after the pilot: among the computed pixels (the others' radii no
    /// longer shrink, and no longer gather).
    pub fn largest_radius(&self) -> Result<f32> {
        let state = match self.adaptive.as_ref().and_then(|a| a.planned.as_ref()) {
            Some(p) => &p.state,
            None => &self.state,
        };
        let (mut w, mut h) = (state.flux.width, state.flux.height);
        let mut level = Texture::new(&self.gpu, w, h, TexFormat::R32F)?;
        self.radius
            .bind()
            .texture("u_state_flux", &state.flux)
            .texture("u_state_direct", &state.sums)
            .draw_fullscreen(&Target::new(&self.gpu, &[&level])?, &DrawState::PLAIN)?;
        while w > 1 || h > 1 {
            (w, h) = (w.div_ceil(2), h.div_ceil(2));
            let next = Texture::new(&self.gpu, w, h, TexFormat::R32F)?;
            self.reduce
                .bind()
                .texture("u_below", &level)
                .draw_fullscreen(&Target::new(&self.gpu, &[&next])?, &DrawState::PLAIN)?;
            level = next;
        }
        Ok(level.read_f32()[0].max(0.0).sqrt())
    }

    /// The image after the iterations so far (direct and photon halves as chosen).
    pub fn image_parts(&self, include_direct: bool, include_indirect: bool) -> Result<Image> {
        self.compose(include_direct, include_indirect)?;
        Ok(Image::from_gl_rgba(
            self.image.width,
            self.image.height,
            &self.image.read_f32(),
        ))
    }

    /// Composes the image into `self.image` (on the GPU only).
    fn compose(&self, include_direct: bool, include_indirect: bool) -> Result<()> {
        let filled = match self.adaptive.as_ref() {
            Some(a) if a.planned.is_some() && include_indirect => Some(a.fill(self.iteration)?),
            _ => None,
        };
        self.compose
            .bind()
            .texture("u_state_flux", &self.state.flux)
            .texture("u_state_direct", &self.state.sums)
            .texture("u_indirect", filled.unwrap_or(&self.state.flux))
            .int("u_adaptive", filled.is_some() as i32)
            .float("u_iterations", self.iteration.max(1) as f32)
            .int("u_include_direct", include_direct as i32)
            .int("u_include_indirect", include_indirect as i32)
            .draw_fullscreen(&self.image_target, &DrawState::PLAIN)
    }

    /// Adaptive sampling's plan counts, once planned.
    pub fn adaptive_stats(&self) -> Option<&AdaptiveStats> {
        Some(&self.adaptive.as_ref()?.planned.as_ref()?.stats)
    }

    pub fn image(&self) -> Result<Image> {
        self.image_parts(true, true)
    }
}

/// The start of each pixel's radius (None: the fixed `initial_radius`).
fn pending_start(sppm: &SppmOptions) -> Result<Option<SppmStart>> {
    Ok(match (sppm.initial_radius, sppm.start) {
        (Some(_), _) => None,
        (
            None,
            SppmStart {
                photons: Some(0), ..
            },
        ) => {
            return Err(Error::out_of_range(
                "sppm.start.photons",
                "0",
                "the start's radius must hold at least 1 photon",
            ))
        }
        (
            None,
            SppmStart {
                pixels: Some(p), ..
            },
        ) if !(p > 0.0 && p.is_finite()) => {
            return Err(Error::out_of_range(
                "sppm.start.pixels",
                p,
                "give a positive number of pixel footprints",
            ))
        }
        (None, start) => Some(start),
    })
}

/// The scene as SPPM traces it: its photons bounce up to `max_bounces`, direct
/// light is sampled by `shadow_rays` per iteration, and first hits are stored
/// only when photons carry direct light.
fn sppm_scene(scene: &Scene, o: &SppmOptions) -> Result<Scene> {
    if !(0.0 < o.alpha && o.alpha < 1.0) {
        return Err(Error::out_of_range(
            "sppm.alpha",
            o.alpha,
            "the allowed range is (0, 1)",
        ));
    }
    if o.direct == DirectLighting::Photons && scene.photon_map.caustics_only {
        return Err(Error::InvalidOption(
            "--sppm-direct photons needs every photon path, but the scene stores caustics only (caustics_only = true)".into(),
        ));
    }
    let mut s = scene.with_max_bounces(o.max_bounces.max(1));
    s.render.shadow_rays = o.shadow_rays.max(1);
    s.photon_map.store_direct = o.direct == DirectLighting::Photons;
    Ok(s)
}
