//! Vertex connection and merging (Georgiev, Křivánek, Davidovič and
//! Slusallek 2012; the recurrences of their SmallVCM) on the fragment passes.
//! Each iteration:
//!
//! 1. **Light subpaths**: N photons traced as photons are (the existing
//!    photon passes, breadth-first records in frames), every diffuse hit
//!    stored: these are the light vertices.
//! 2. **Their MIS partials** (`glsl/vcm/light_partials.frag`): one fragment
//!    a light path walks its frames and writes dVCM, dVC, dVM and the path's
//!    length beside each record, a fifth attachment of the photon frames.
//! 3. **The map** of the light vertices (the counting build), over a grid
//!    sized by this iteration's radius r_i = r_1 i^((alpha - 1) / 2). Its
//!    compacted vertices are also the light vertex cache that connections
//!    draw from and light tracing walks.
//! 4. **Light tracing** (`glsl/vcm/light_connect.frag`): a fragment a map
//!    texel connects its vertex to the camera, shadow ray and weight, then
//!    `glsl/vcm/light_splat.vert` draws each as a point where it projects,
//!    added into the light image (blending).
//! 5. **Camera paths** (`glsl/vcm/camera_path.frag`): one fragment a pixel,
//!    the whole path, taking next-event estimation, connections to light
//!    vertices drawn from the cache and merging at every diffuse vertex,
//!    each weighted; added into the camera image.
//!
//! The image is the two sums over the iterations run. `VcmMode` keeps
//! a subset of the techniques, each unweighted where alone.

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::image::Image;
use crate::photon::{CountingBuild, Grid, PhotonBatch, PhotonTracer, SortedPhotonMap, TraceConfig};
use crate::render::options::RenderOptions;
use crate::render::plan::PassPlan;
use crate::render::ray_trace::bind_camera;
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;
use crate::timing::Timings;

pub mod options;
mod run;

pub use options::{VcmMode, VcmOptions};
pub use run::{render_vcm, VcmOutput};

/// The techniques `Vcm::technique_images` separates, in its order.
pub const TECHNIQUES: [&str; 5] = [
    "lights hit",
    "next-event estimation",
    "connections",
    "merging",
    "light tracing",
];

/// Cells of the light vertices' grid at most: about one a light path (a
/// power of two in 2^12..=2^22). The counting build's histogram, its prefix
/// sums and the cell table cost a texel a cell each iteration, and past
/// this the cells grow beyond 2 r instead; a merge then scans more vertices,
/// but few more (iterations at 2^14 cells ran as fast as at 2^16 in the paper
/// scenes, and 10-45% faster than at 2^18).
fn max_cells(light_paths: u32) -> u64 {
    u64::from(light_paths)
        .next_power_of_two()
        .clamp(1 << 12, 1 << 22)
}

pub struct Vcm {
    gpu: Gpu,
    scene: Scene,
    pub options: VcmOptions,
    seed: u32,
    plan: PassPlan,
    textures: SceneTextures,
    photons: PhotonTracer,
    batch: Option<PhotonBatch>,
    /// The light vertices' MIS partials, beside the photon records.
    partials: Option<Texture>,
    partials_target: Option<(Texture, Target)>,
    builder: CountingBuild,
    /// This iteration's map of the light vertices (None: path tracing).
    map: Option<SortedPhotonMap>,
    partials_program: Program,
    camera_program: Program,
    connect_program: Program,
    splat_program: Program,
    /// Light tracing's per-vertex results (contribution, landing), sized as
    /// the map's texture; reallocated when that size changes.
    connected: Option<(Texture, Texture, Target)>,
    /// Sums over the iterations: the camera paths' and light tracing's; and
    /// the camera paths' by technique (lights hit, next-event estimation,
    /// connections, merging), whose sum the camera image is.
    camera_image: Texture,
    techniques: [Texture; 4],
    camera_target: Target,
    light_image: Texture,
    light_target: Target,
    pub iteration: u32,
    /// The merging radius of iteration 1.
    pub initial_radius: f32,
    /// Stored light vertices of the last iteration (for reports).
    pub light_vertices: u64,
    /// What a sampler reads when its input is not made this iteration (path
    /// tracing has no light vertices and builds no map).
    none_f32: Texture,
    none_i32: Texture,
}

impl Vcm {
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        options: &RenderOptions,
        vcm: &VcmOptions,
    ) -> Result<Self> {
        check(vcm)?;
        let scene = vcm_scene(scene, vcm);
        let (w, h) = (options.width, options.height);
        let mut plan = PassPlan::new(&scene, options);
        plan.jitter = true;
        plan.spp = 1;
        let textures = SceneTextures::new(gpu, &scene)?;
        // The mode is compiled in: llvmpipe runs every branch, so the
        // techniques the mode leaves out cost nothing only if absent.
        let mode = [("VCM_MODE", vcm.mode.code().to_string())];
        let photons = PhotonTracer::with_config(
            gpu,
            TraceConfig {
                stop_when_dead: true,
                fused: true,
                ..TraceConfig::default()
            },
        )?;
        let (batch, partials, partials_target) = if vcm.mode.traces_light_paths() {
            let batch = photons.batch(&scene, vcm.light_paths)?;
            let f = &batch.frames;
            let partials =
                Texture::new(gpu, f.width, f.frame_height * f.frames, TexFormat::Rgba32F)?;
            let unused = Texture::new(gpu, f.width, f.frame_height, TexFormat::R32F)?;
            let target = Target::new(gpu, &[&unused])?;
            (Some(batch), Some(partials), Some((unused, target)))
        } else {
            (None, None, None)
        };
        let initial_radius = vcm
            .initial_radius
            .unwrap_or_else(|| footprint_radius(&scene, h, vcm.start_pixels));
        Error::check_positive(
            "vcm.initial_radius",
            initial_radius,
            "the first merging radius must be a positive number",
        )?;
        let image = || Texture::new(gpu, w, h, TexFormat::Rgba32F);
        let (camera_image, light_image) = (image()?, image()?);
        let techniques = [image()?, image()?, image()?, image()?];
        let mut attachments = vec![&camera_image];
        attachments.extend(techniques.iter());
        let camera_target = Target::new(gpu, &attachments)?;
        let light_target = Target::new(gpu, &[&light_image])?;
        camera_target.clear([0.0; 4]);
        light_target.clear([0.0; 4]);
        Ok(Self {
            gpu: gpu.clone(),
            options: vcm.clone(),
            seed: options.seed,
            plan,
            textures,
            photons,
            batch,
            partials,
            partials_target,
            builder: CountingBuild::new(gpu)?,
            map: None,
            partials_program: Program::fullscreen(gpu, "vcm/light_partials.frag")?,
            camera_program: Program::fullscreen_with(gpu, "vcm/camera_path.frag", &mode)?,
            connect_program: Program::fullscreen_with(gpu, "vcm/light_connect.frag", &mode)?,
            splat_program: Program::new(gpu, "vcm/light_splat.vert", "vcm/light_splat.frag", &[])?,
            connected: None,
            camera_image,
            techniques,
            camera_target,
            light_image,
            light_target,
            iteration: 0,
            initial_radius,
            light_vertices: 0,
            none_f32: Texture::new(gpu, 1, 1, TexFormat::Rgba32F)?,
            none_i32: Texture::new(gpu, 1, 1, TexFormat::Rg32I)?,
            scene,
        })
    }

    /// The scene as VCM traces it.
    pub fn scene(&self) -> &Scene {
        &self.scene
    }

    /// Iteration i's merging radius: r_1 i^((alpha - 1) / 2).
    pub fn radius(&self, i: u32) -> f32 {
        self.initial_radius * (i as f32).powf((self.options.alpha - 1.0) * 0.5)
    }

    /// One iteration: light paths, their partials, the map, light tracing,
    /// camera paths.
    pub fn iterate(&mut self, timings: &mut Timings) -> Result<()> {
        let i = self.iteration + 1;
        let seed = crate::random::sample_seed(self.seed, i);
        let radius = self.radius(i);
        let mode = self.options.mode;
        self.map = None;
        if let Some(batch) = self.batch.as_mut() {
            let wall = std::time::Instant::now();
            self.photons
                .trace_batch(&self.scene, &self.textures, batch, seed)?;
            let frames = &batch.frames;
            timings.add_since(
                "light paths",
                frames.gpu_seconds,
                wall,
                frames.passes as usize,
            );
            let wall = std::time::Instant::now();
            self.light_partials()?;
            self.gpu.finish();
            timings.add_since("light vertex partials", 0.0, wall, 1);
            let wall = std::time::Instant::now();
            let frames = &self.batch.as_ref().expect("light paths").frames;
            // Without merging the map is only the light vertex cache, which
            // light tracing and connections walk: one cell.
            let grid = if mode.merges() {
                Grid::over_scene(
                    &self.scene,
                    2.0 * radius,
                    max_cells(self.options.light_paths),
                )
            } else {
                Grid::over_scene(&self.scene, f32::MAX, 1)
            };
            let mut stages = Timings::default();
            let map = self.builder.build(frames, &grid, &mut stages)?;
            self.light_vertices = map.stored.expect("the counting build counts") as u64;
            self.map = Some(map);
            self.gpu.finish();
            timings.add_folded("build map", &stages, wall);
            if mode.splats() {
                let wall = std::time::Instant::now();
                self.light_trace(radius)?;
                self.gpu.finish();
                timings.add_since("light tracing", 0.0, wall, 2);
            }
        }
        let wall = std::time::Instant::now();
        self.camera_paths(seed, radius)?;
        self.gpu.finish();
        timings.add_since("camera paths", 0.0, wall, 1);
        self.iteration = i;
        self.gpu.check("VCM iteration")
    }

    /// `glsl/vcm/light_partials.frag` over one frame of light paths.
    fn light_partials(&self) -> Result<()> {
        let (Some(batch), Some(partials), Some((_, target))) =
            (&self.batch, &self.partials, &self.partials_target)
        else {
            return Ok(());
        };
        let frames = &batch.frames;
        let mut b = self.partials_program.bind();
        self.textures.bind(&mut b);
        frames.bind_record_textures(&mut b);
        self.bind_factors(&mut b, self.radius(self.iteration + 1));
        b.image("u_partials_out", partials)
            .int("u_frame_height", frames.frame_height as i32)
            .int("u_frames", frames.frames as i32)
            .draw_fullscreen(target, &DrawState::PLAIN)?;
        self.gpu.image_barrier();
        Ok(())
    }

    /// The MIS factors of `glsl/vcm/mis.glsl` at merging radius `radius`.
    fn bind_factors(&self, b: &mut crate::gpu::Bindings<'_>, radius: f32) {
        let n = self.options.light_paths as f32;
        let eta = std::f32::consts::PI * radius * radius * n;
        let mode = self.options.mode;
        b.float("u_vm_factor", if mode == VcmMode::Vcm { eta } else { 0.0 })
            .float("u_vc_factor", if mode.connects() { 1.0 / eta } else { 0.0 })
            .float("u_light_paths", n)
            .float(
                "u_camera_continuation",
                self.options.camera_continuation_in_use(),
            );
    }

    /// The light vertices' records and partials, as `glsl/vcm/light_vertex.glsl` reads them.
    fn bind_light_vertices(&self, b: &mut crate::gpu::Bindings<'_>) {
        let (Some(batch), Some(partials)) = (&self.batch, &self.partials) else {
            return;
        };
        let f = &batch.frames;
        b.texture("u_lv_position", &f.position)
            .texture("u_lv_power", &f.power)
            .texture("u_lv_incoming", &f.incoming)
            .texture("u_lv_outgoing", &f.outgoing)
            .texture("u_lv_partials", partials)
            .int("u_lv_width", f.width as i32)
            .int("u_lv_frame_height", f.frame_height as i32)
            .int("u_lv_frames", f.frames as i32)
            .float("u_lv_power_scale", f.power_scale)
            .int("u_light_vertices", self.light_vertices as i32);
    }

    /// Light tracing: every light vertex of the map connected to the camera
    /// (a fragment a map texel), then splatted into the light image.
    fn light_trace(&mut self, radius: f32) -> Result<()> {
        let Some(map) = &self.map else {
            return Ok(());
        };
        let (w, h) = (map.pairs.width, map.pairs.height);
        if self
            .connected
            .as_ref()
            .is_none_or(|(c, _, _)| (c.width, c.height) != (w, h))
        {
            let contribution = Texture::new(&self.gpu, w, h, TexFormat::Rgba32F)?;
            let landing = Texture::new(&self.gpu, w, h, TexFormat::Rgba32F)?;
            let target = Target::new(&self.gpu, &[&contribution, &landing])?;
            self.connected = Some((contribution, landing, target));
        }
        let (contribution, landing, target) = self.connected.as_ref().expect("allocated");
        {
            let mut b = self.connect_program.bind();
            self.textures.bind(&mut b);
            bind_camera(&mut b, &self.scene.camera, &self.plan, 0);
            self.bind_factors(&mut b, radius);
            self.bind_light_vertices(&mut b);
            b.texture("u_map_pairs", &map.pairs)
                .int("u_sorted_width", w as i32)
                .int("u_max_segments", self.options.max_segments as i32)
                .draw_fullscreen(target, &DrawState::PLAIN)?;
        }
        self.splat_program
            .bind()
            .texture("u_contribution", contribution)
            .texture("u_landing", landing)
            .int("u_width", w as i32)
            .draw_points(
                &self.light_target,
                &DrawState::ADDITIVE,
                0,
                self.light_vertices as i32,
            )
    }

    /// Every pixel's camera path, added into the camera image.
    fn camera_paths(&self, seed: u32, radius: f32) -> Result<()> {
        let mut b = self.camera_program.bind();
        self.textures.bind(&mut b);
        bind_camera(&mut b, &self.scene.camera, &self.plan, 0);
        self.bind_factors(&mut b, radius);
        self.bind_light_vertices(&mut b);
        if self.batch.is_none() {
            // Path tracing alone: no light vertices; the uniforms still bind.
            let none = &self.none_f32;
            b.texture("u_lv_position", none)
                .texture("u_lv_power", none)
                .texture("u_lv_incoming", none)
                .texture("u_lv_outgoing", none)
                .texture("u_lv_partials", none)
                .int("u_lv_width", 1)
                .int("u_lv_frame_height", 1)
                .int("u_lv_frames", 0)
                .float("u_lv_power_scale", 1.0)
                .int("u_light_vertices", 0);
        }
        match &self.map {
            Some(m) => {
                b.texture("u_map_position", &m.position)
                    .texture("u_map_power", &m.power)
                    .texture("u_map_incoming", &m.incoming)
                    .texture("u_map_pairs", &m.pairs)
                    .texture("u_grid_first", &m.grid_first)
                    .int("u_grid_width", m.grid_width as i32)
                    .int("u_sorted_width", m.position.width as i32)
                    .int("u_merge", self.options.mode.merges() as i32);
                m.grid.bind(&mut b);
            }
            None => {
                b.texture("u_map_position", &self.none_f32)
                    .texture("u_map_power", &self.none_f32)
                    .texture("u_map_incoming", &self.none_f32)
                    .texture("u_map_pairs", &self.none_i32)
                    .texture("u_grid_first", &self.none_i32)
                    .int("u_grid_width", 1)
                    .int("u_sorted_width", 1)
                    .int("u_merge", 0);
            }
        }
        b.uint("u_seed", seed)
            .int("u_max_segments", self.options.max_segments as i32)
            .float("u_radius2", radius * radius)
            .int("u_connections", self.options.connections as i32)
            .draw_fullscreen(&self.camera_target, &DrawState::ADDITIVE)
    }

    /// The image after the iterations run: the camera paths' and light
    /// tracing's sums over the iterations.
    pub fn image(&self) -> Result<Image> {
        let (w, h) = (self.plan.width, self.plan.height);
        let n = self.iteration.max(1) as f32;
        let camera = self.camera_image.read_f32();
        let light = self.light_image.read_f32();
        let sum: Vec<f32> = camera
            .iter()
            .zip(&light)
            .enumerate()
            .map(|(i, (c, l))| if i % 4 == 3 { 1.0 } else { (c + l) / n })
            .collect();
        Ok(Image::from_gl_rgba(w, h, &sum))
    }

    /// What each technique carried over the iterations run, in the order
    /// of `TECHNIQUES`: lights hit, next-event estimation, connections,
    /// merging (the camera paths'), light tracing. They sum to `image`.
    pub fn technique_images(&self) -> Result<Vec<Image>> {
        let (w, h) = (self.plan.width, self.plan.height);
        let n = self.iteration.max(1) as f32;
        let scaled = |t: &Texture| -> Image {
            let v: Vec<f32> = t.read_f32().iter().map(|v| v / n).collect();
            Image::from_gl_rgba(w, h, &v)
        };
        let mut out: Vec<Image> = self.techniques.iter().map(scaled).collect();
        out.push(scaled(&self.light_image));
        Ok(out)
    }
}

/// Refuses options that cannot run.
fn check(o: &VcmOptions) -> Result<()> {
    if o.light_paths == 0 {
        return Err(Error::out_of_range(
            "vcm.light_paths",
            0.0,
            "trace at least one light path an iteration",
        ));
    }
    if !(1..=16).contains(&o.connections) {
        return Err(Error::out_of_range(
            "vcm.connections",
            o.connections as f32,
            "the allowed range is 1..=16",
        ));
    }
    if !(o.camera_continuation > 0.0 && o.camera_continuation <= 1.0) {
        return Err(Error::out_of_range(
            "vcm.camera_continuation",
            o.camera_continuation,
            "the allowed range is (0, 1]",
        ));
    }
    if !(2..=64).contains(&o.max_segments) {
        return Err(Error::out_of_range(
            "vcm.max_segments",
            o.max_segments as f32,
            "the allowed range is 2..=64",
        ));
    }
    if !(0.0 < o.alpha && o.alpha < 1.0) {
        return Err(Error::out_of_range(
            "vcm.alpha",
            o.alpha,
            "the allowed range is (0, 1)",
        ));
    }
    Ok(())
}

/// The scene as VCM traces its light paths: every diffuse hit stored, every
/// path (no projection maps), up to max_segments - 1 bounces.
fn vcm_scene(scene: &Scene, o: &VcmOptions) -> Scene {
    let mut s = scene.with_max_bounces(o.max_segments - 1);
    s.photon_map.store_direct = true;
    s.photon_map.caustics_only = false;
    s
}

/// `pixels` pixel footprints at the camera's look-at distance: the width of
/// that many pixels' cones there.
fn footprint_radius(scene: &Scene, height: u32, pixels: f32) -> f32 {
    let c = &scene.camera;
    let angle = 2.0 * (c.vfov_degrees.to_radians() * 0.5).tan() / height as f32;
    pixels * angle * (c.look_at - c.position).length()
}
