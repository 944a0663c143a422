//! Instant global illumination (Keller's instant radiosity as Wald et al.
//! made it interactive; Marques and Santos's OptiX version with its three
//! accelerations), as a second method beside photon mapping on the same
//! passes:
//!
//! 1. **VPLs.** Light paths are traced by the photon passes with quasi-random
//!    (Halton) numbers; every diffuse hit, the first included, is a virtual
//!    point light with the power that arrived there. The bitonic build's
//!    HistoPyramid compacts the stored records and `igi_vpls` turns each into
//!    a VPL texel (position, normal, intensity), in a random order.
//! 2. **Gather.** At each pixel's first diffuse hit, `igi_gather` sums the
//!    VPLs with the bounded geometry term and a shadow ray each, in batches
//!    of `VPL_BATCH` VPLs a pass (additive), as incident light.
//! 3. **Accelerations** (each a switch): imperfect visibility (shadow rays
//!    against primitive bounding boxes, `PRIMITIVE_BOXES` in
//!    glsl/common/scene.glsl); interleaved sampling over n x n VPL subsets
//!    with the discontinuity buffer (`igi_interleave`); downsampling by a
//!    factor with joint bilateral upsampling (`igi_upsample`).
//! 4. **The image**: direct light and specular paths from the ray tracer,
//!    throughput x albedo / pi x the incident light, and from a caustic photon
//!    map the light that reaches x from a mirror or glass, which VPL shadow
//!    rays cannot carry (they stop at mirrors and glass as every shadow ray
//!    does). By default that map holds every such path, L (S|D)* S D, traced
//!    on through diffuse hits and stored after specular bounces only, so light
//!    a diffuse surface sends through mirrors and glass (L D+ S+ D) is in it;
//!    `CausticPaths::FromLights` keeps Jensen's map of paths straight from an
//!    emitter (L S+ D), as Marques and Santos's IGI does, with that gap.

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::layout::{PRIMITIVE_BOX_ROW, VPL_BATCH};
use crate::photon::{BitonicBuild, Grid, PhotonTracer, RandomSource, TraceConfig};
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;

use super::bias_compensation::BiasCompensation;
use super::direct::DirectLight;
use super::observer::{Progress, RenderObserver};
use super::photon_map::MapEstimate;
use super::photon_options::{CausticMap, CausticPaths, WithCausticMap, MAX_K};
use super::sample::{FrameMethod, Prepare, SampleFrame};
use super::{Image, Timings};

/// How IGI runs.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct IgiOptions {
    /// Light paths traced; each leaves a VPL at every diffuse hit.
    pub vpl_paths: u32,
    /// Bounces of a light path at most (Russian roulette ends most far
    /// sooner); SPPM's default, so that the truncated tail is negligible.
    pub vpl_bounces: u32,
    /// Marques and Santos's bounding distance m of the geometry term (VPLs
    /// nearer than 0.8 m give nothing, beyond 1.2 m all); 0: unbounded.
    /// None: the scene's photon_map.max_radius.
    pub min_distance: Option<f32>,
    /// VPL shadow rays against primitive bounding boxes.
    pub imperfect_visibility: bool,
    /// n: n x n VPL subsets over pixel blocks (1: every pixel sees every VPL).
    pub interleave: u32,
    /// The gather at one pixel per f x f block, upsampled (1: full resolution).
    pub downsample: u32,
    /// The caustic map's paths: all light onto x from a mirror or glass, or
    /// only light straight from an emitter (the paper's).
    pub caustic_paths: CausticPaths,
    /// k of the caustic map's estimate; None: the scene's, at most
    /// `CAUSTIC_K`.
    pub caustic_k: Option<u32>,
    /// The caustic map on the scene's grid, not the refined one
    /// (`CausticMap::grid_resolution`).
    pub caustic_scene_grid: bool,
    /// Gather rays a pixel of the bias compensation, which adds the light
    /// the bound leaves out (`bias_compensation`); 0: off.
    pub bias_compensation: u32,
}

impl Default for IgiOptions {
    /// 2048 paths interleaved over 3 x 3 subsets (each pixel gathers about
    /// 228 paths' VPLs, and the discontinuity buffer merges a window's
    /// subsets), plus 16 rays of bias compensation. A region's energy
    /// scatters with the VPLs of all subsets while a pixel pays for one:
    /// against independent references (docs' regions tables), this beat 512
    /// paths without subsets, in no more time, in CORNELL BOX (relative RMSE
    /// 0.058 against 0.061), in the measured Cornell box (0.058 against
    /// 0.081), whose blocks' faces, lit by the floor a few centimetres
    /// away, see few VPLs, each near and bright, and on MESH STAGE's curved
    /// ball, which it was not chosen on (0.095 against 0.098). 64 paths (the
    /// paper's) scatter each region's energy by up to 5% from seed to seed;
    /// the bound takes 8% of the light under the balls and the compensation
    /// puts it back.
    fn default() -> Self {
        Self {
            vpl_paths: 2048,
            vpl_bounces: 32,
            min_distance: None,
            imperfect_visibility: false,
            interleave: 3,
            downsample: 1,
            caustic_paths: CausticPaths::All,
            caustic_k: None,
            caustic_scene_grid: false,
            bias_compensation: 16,
        }
    }
}

impl IgiOptions {
    /// The caustic map's paths and k.
    pub fn caustic_map(&self) -> CausticMap {
        CausticMap {
            paths: self.caustic_paths,
            k: self.caustic_k,
            scene_grid: self.caustic_scene_grid,
        }
    }

    /// The bounding distance in use for `scene`.
    pub fn min_distance_for(&self, scene: &Scene) -> f32 {
        self.min_distance.unwrap_or(scene.photon_map.max_radius)
    }

    pub fn check(&self) -> Result<()> {
        Error::check_range("igi.vpl_paths", self.vpl_paths, 1..=1 << 20)?;
        Error::check_range("igi.vpl_bounces", self.vpl_bounces, 1..=64)?;
        if !(1..=8).contains(&self.interleave) {
            return Err(Error::out_of_range(
                "igi.interleave",
                self.interleave,
                "the allowed range is 1..=8 (n x n subsets)",
            ));
        }
        Error::check_range("igi.downsample", self.downsample, 1..=16)?;
        if let Some(k) = self.caustic_k {
            Error::check_range("igi.caustic_k", k, 1..=MAX_K)?;
        }
        Error::check_range("igi.bias_compensation", self.bias_compensation, 0..=1024)?;
        if let Some(m) = self.min_distance {
            if !(m >= 0.0 && m.is_finite()) {
                return Err(Error::out_of_range(
                    "igi.min_distance",
                    m,
                    "give a distance of 0 (unbounded) or more",
                ));
            }
        }
        Ok(())
    }
}

/// The VPLs of a render.
pub struct Vpls {
    /// xyz, w = 1 where a VPL; normal; intensity (power x albedo / pi).
    pub position: Texture,
    pub normal: Texture,
    pub intensity: Texture,
    pub count: u32,
    pub paths: u32,
    /// Bounce passes the paths took before every one had ended.
    pub frames_traced: u32,
}

/// What the VPL stage did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct VplReport {
    pub paths: u32,
    pub vpls: u32,
    pub frames_traced: u32,
    pub min_distance: f32,
    /// No VPL traced, gathered or compensated: every diffuse surface lies
    /// in one plane, so a VPL could light no diffuse point
    /// (`Scene::has_diffuse_interreflection`).
    pub skipped: bool,
}

impl Vpls {
    /// Traces `paths` light paths of up to `bounces` bounces through `scene`
    /// (every diffuse hit stored) and makes their VPLs.
    pub fn trace(
        gpu: &Gpu,
        scene: &Scene,
        textures: &SceneTextures,
        (paths, bounces): (u32, u32),
        seed: u32,
        timings: &mut Timings,
    ) -> Result<Self> {
        let mut s = scene.with_max_bounces(bounces);
        s.photon_map.caustics_only = false;
        s.photon_map.store_direct = true;
        let wall = std::time::Instant::now();
        let tracer = PhotonTracer::with_config(
            gpu,
            TraceConfig {
                random: RandomSource::Halton,
                stop_when_dead: true,
                projection_maps: false,
                fused: false,
            },
        )?;
        let frames = tracer.trace(&s, textures, seed, paths)?;
        gpu.finish();
        timings.add_both(
            "VPL paths",
            frames.gpu_seconds,
            wall.elapsed().as_secs_f64(),
            frames.frames as usize,
        );
        let wall = std::time::Instant::now();
        // One cell: the compaction only needs the stored records' indices.
        let grid = Grid::over_scene(&s, f32::INFINITY, 1);
        let (pairs, count) = BitonicBuild::new(gpu)?.compacted_pairs(&frames, &grid)?;
        if count == 0 {
            return Err(Error::InvalidOption(format!(
                "{paths} VPL paths left no VPL in {} (no light reached a diffuse surface): trace more with --vpl-paths",
                scene.name
            )));
        }
        // VPLs in a random order: interleaving's subsets (k mod n^2) must
        // not follow the paths' Halton index, whose leading digits fix a
        // subset's directions or lights.
        let mut order: Vec<i32> = (0..count as i32).collect();
        let mut state = crate::random::rng_init(seed, [count, 0], crate::layout::VPL_STREAM);
        crate::random::shuffle(&mut order, &mut state);
        order.resize((pairs.width * pairs.height) as usize, -1);
        let order = Texture::from_texels(gpu, pairs.width, pairs.height, TexFormat::R32I, &order)?;
        let t = || Texture::new(gpu, pairs.width, pairs.height, TexFormat::Rgba32F);
        let (position, normal, intensity) = (t()?, t()?, t()?);
        let target = Target::new(gpu, &[&position, &normal, &intensity])?;
        let program = Program::fullscreen(gpu, "render/igi_vpls.frag")?;
        let mut b = program.bind();
        textures.bind(&mut b);
        b.texture("u_pairs", &pairs)
            .texture("u_order", &order)
            .int("u_count", count as i32);
        frames.bind_record_textures(&mut b);
        b.int("u_record_width", frames.width as i32)
            .draw_fullscreen(&target, &DrawState::PLAIN)?;
        drop(b);
        gpu.finish();
        timings.add_both("VPLs", 0.0, wall.elapsed().as_secs_f64(), 1);
        gpu.check("VPLs")?;
        Ok(Self {
            position,
            normal,
            intensity,
            count,
            paths,
            frames_traced: frames.frames,
        })
    }

    /// Every VPL read back: (position, normal, intensity) (for tests).
    pub fn read(&self) -> Vec<([f32; 3], [f32; 3], [f32; 3])> {
        let (p, n, i) = (
            self.position.read_f32(),
            self.normal.read_f32(),
            self.intensity.read_f32(),
        );
        (0..self.count as usize)
            .map(|k| {
                let v = |a: &[f32]| [a[4 * k], a[4 * k + 1], a[4 * k + 2]];
                (v(&p), v(&n), v(&i))
            })
            .collect()
    }
}

/// What one eye sample's gather did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct IgiStats {
    pub vpls: u32,
    pub passes: u32,
    /// Shading points (pixels, or downsampled blocks) with a diffuse hit.
    pub shading_points: u64,
    /// VPL shadow rays per shading point: VPLs / subsets.
    pub vpls_per_point: f64,
}

/// IGI's textures and programs at one image size.
pub struct Igi {
    gpu: Gpu,
    options: IgiOptions,
    min_distance: f32,
    /// The gather's incident light, and after the discontinuity buffer.
    pub incident: Texture,
    incident_target: Target,
    filtered: Texture,
    filtered_target: Target,
    /// Reflected indirect light at full resolution.
    pub indirect: Texture,
    indirect_target: Target,
    gather: Program,
    interleave: Program,
    upsample: Program,
    boxes: Option<Texture>,
    width: u32,
    height: u32,
}

impl Igi {
    pub fn new(
        gpu: &Gpu,
        scene: &Scene,
        width: u32,
        height: u32,
        options: &IgiOptions,
    ) -> Result<Self> {
        options.check()?;
        let f = options.downsample;
        let (lw, lh) = (width.div_ceil(f), height.div_ceil(f));
        let low = || Texture::new(gpu, lw, lh, TexFormat::Rgba32F);
        let (incident, filtered) = (low()?, low()?);
        let indirect = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let defines: Vec<(&str, String)> = if options.imperfect_visibility {
            vec![("PRIMITIVE_BOXES", "1".into())]
        } else {
            vec![]
        };
        let boxes = options
            .imperfect_visibility
            .then(|| primitive_boxes(gpu, scene))
            .transpose()?;
        Ok(Self {
            gpu: gpu.clone(),
            options: options.clone(),
            min_distance: options.min_distance_for(scene),
            incident_target: Target::new(gpu, &[&incident])?,
            filtered_target: Target::new(gpu, &[&filtered])?,
            indirect_target: Target::new(gpu, &[&indirect])?,
            incident,
            filtered,
            indirect,
            gather: Program::fullscreen_with(gpu, "render/igi_gather.frag", &defines)?,
            interleave: Program::fullscreen(gpu, "render/igi_interleave.frag")?,
            upsample: Program::fullscreen(gpu, "render/igi_upsample.frag")?,
            boxes,
            width,
            height,
        })
    }

    /// The indirect light of one eye sample at `direct`'s first hits, left in
    /// `indirect`. Adds "VPL gather", "discontinuity buffer" and "upsample"
    /// to `timings`.
    pub fn run(
        &self,
        textures: &SceneTextures,
        direct: &DirectLight,
        vpls: &Vpls,
        eye: glam::Vec3,
        timings: &mut Timings,
        on_batch: &mut dyn FnMut(u32, u32),
    ) -> Result<IgiStats> {
        let o = &self.options;
        self.incident_target.clear([0.0; 4]);
        let mut stats = IgiStats {
            vpls: vpls.count,
            vpls_per_point: vpls.count as f64 / (o.interleave * o.interleave) as f64,
            ..Default::default()
        };
        // Each batch holds VPL_BATCH VPLs of every subset: a pixel's share
        // per pass stays VPL_BATCH whatever the interleave.
        let per_pass = VPL_BATCH * o.interleave * o.interleave;
        let mut first = 0;
        // The first pass's fragments are the shading points with a hit
        // (igi_gather discards the others).
        let points = crate::gpu::Query::occlusion(&self.gpu)?;
        self.gpu.finish();
        let t0 = std::time::Instant::now();
        while first < vpls.count {
            crate::interrupt::check()?;
            let end = (first + per_pass).min(vpls.count);
            let mut b = self.gather.bind();
            textures.bind(&mut b);
            if let Some(boxes) = &self.boxes {
                b.texture("u_primitive_boxes", boxes);
            }
            b.texture("u_diffuse_position", &direct.diffuse_position)
                .texture("u_diffuse_normal", &direct.diffuse_normal)
                .texture("u_vpl_position", &vpls.position)
                .texture("u_vpl_normal", &vpls.normal)
                .texture("u_vpl_intensity", &vpls.intensity)
                .int("u_vpl_width", vpls.position.width as i32)
                .int("u_first", first as i32)
                .int("u_end", end as i32)
                .int("u_scale", o.downsample as i32)
                .int("u_interleave", o.interleave as i32)
                .float("u_min_distance", self.min_distance);
            if first == 0 {
                points.begin();
            }
            let drawn = b.draw_fullscreen(&self.incident_target, &DrawState::ADDITIVE);
            if first == 0 {
                points.end();
            }
            drawn?;
            drop(b);
            // Bounded work per submission (llvmpipe runs a pass at once).
            self.gpu.finish();
            stats.passes += 1;
            first = end;
            on_batch(first, vpls.count);
        }
        timings.add_both(
            "VPL gather",
            0.0,
            t0.elapsed().as_secs_f64(),
            stats.passes as usize,
        );
        stats.shading_points = points.count();
        let mut incident = &self.incident;
        if o.interleave > 1 {
            let t0 = std::time::Instant::now();
            self.interleave
                .bind()
                .texture("u_incident", &self.incident)
                .texture("u_diffuse_position", &direct.diffuse_position)
                .texture("u_diffuse_normal", &direct.diffuse_normal)
                .vec3("u_eye", eye.to_array())
                .int("u_scale", o.downsample as i32)
                .int("u_interleave", o.interleave as i32)
                .draw_fullscreen(&self.filtered_target, &DrawState::PLAIN)?;
            self.gpu.finish();
            timings.add_both("discontinuity buffer", 0.0, t0.elapsed().as_secs_f64(), 1);
            incident = &self.filtered;
        }
        let t0 = std::time::Instant::now();
        let mut b = self.upsample.bind();
        textures.bind(&mut b);
        b.texture("u_incident", incident)
            .texture("u_diffuse_position", &direct.diffuse_position)
            .texture("u_diffuse_normal", &direct.diffuse_normal)
            .texture("u_diffuse_throughput", &direct.diffuse_throughput)
            .vec3("u_eye", eye.to_array())
            .int("u_scale", o.downsample as i32)
            .draw_fullscreen(&self.indirect_target, &DrawState::PLAIN)?;
        drop(b);
        self.gpu.finish();
        timings.add_both(
            if o.downsample > 1 {
                "upsample"
            } else {
                "VPL compose"
            },
            0.0,
            t0.elapsed().as_secs_f64(),
            1,
        );
        self.gpu.check("IGI")?;
        Ok(stats)
    }

    /// How many pixels away a pixel's light reads other pixels' first hits,
    /// at most: the discontinuity buffer's window (n / 2 shading points) and
    /// the upsampling's 4 x 4 low-resolution neighbours, each shading point
    /// a pixel of its f x f block; 0 with neither.
    pub fn neighbour_reach(&self) -> u32 {
        let (n, f) = (self.options.interleave, self.options.downsample);
        if n == 1 && f == 1 {
            0
        } else {
            f * (n / 2 + 3) + f
        }
    }

    pub fn read_indirect(&self) -> Image {
        Image::from_gl_rgba(self.width, self.height, &self.indirect.read_f32())
    }

    /// The incident light at the gather's resolution as the upsampling
    /// reads it: after the discontinuity buffer when interleaving.
    pub fn filtered_incident(&self) -> &Texture {
        if self.options.interleave > 1 {
            &self.filtered
        } else {
            &self.incident
        }
    }
}

/// Each primitive's bounding box, two texels (min, max) a primitive, in rows
/// of `PRIMITIVE_BOX_ROW` texels.
fn primitive_boxes(gpu: &Gpu, scene: &Scene) -> Result<Texture> {
    let n = scene.shapes.len().max(1);
    let height = (2 * n).div_ceil(PRIMITIVE_BOX_ROW as usize) as u32;
    let mut data = vec![0f32; PRIMITIVE_BOX_ROW as usize * height as usize * 4];
    for (i, s) in scene.shapes.iter().enumerate() {
        let (lo, hi) = crate::scene::bvh::bounds(&s.geometry);
        data[8 * i..8 * i + 3].copy_from_slice(&lo.to_array());
        data[8 * i + 4..8 * i + 7].copy_from_slice(&hi.to_array());
    }
    Texture::from_texels(gpu, PRIMITIVE_BOX_ROW, height, TexFormat::Rgba32F, &data)
}

/// The VPLs and the gather's textures and programs.
pub struct VplGather {
    pub vpls: Vpls,
    pub igi: Igi,
}

/// IGI through a render: the caustic map, the VPLs, the gather's textures
/// and each eye sample's gather.
pub struct IgiRun {
    pub caustics: Option<MapEstimate>,
    /// None where a VPL could light nothing (`VplReport::skipped`).
    pub gather: Option<VplGather>,
    pub report: VplReport,
    pub stats: Vec<IgiStats>,
    /// The light the bound leaves out, where compensated.
    pub compensation: Option<BiasCompensation>,
}

impl IgiRun {
    /// The caustic map, then the VPLs, then the compensation's global map;
    /// neither VPLs nor compensation where no two diffuse surfaces face
    /// each other.
    pub fn prepare(
        p: &Prepare<'_>,
        with: &WithCausticMap<IgiOptions>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Self> {
        let (o, scene) = (&with.method, p.scene);
        let caustics = MapEstimate::caustics(p, with, o.caustic_map(), timings, observer)?;
        observer.progress(&Progress::stage("VPLs", 0, 1));
        let interreflects = scene.has_diffuse_interreflection();
        let gather = if interreflects {
            let vpl_seed = crate::random::pcg_hash(p.seed ^ crate::layout::VPL_STREAM);
            let bounds = (o.vpl_paths, o.vpl_bounces);
            Some(VplGather {
                vpls: Vpls::trace(p.gpu, scene, p.textures, bounds, vpl_seed, timings)?,
                igi: Igi::new(p.gpu, scene, p.width, p.height, o)?,
            })
        } else {
            o.check()?;
            None
        };
        let vpls = gather.as_ref().map(|g| &g.vpls);
        let report = VplReport {
            paths: vpls.map_or(0, |v| v.paths),
            vpls: vpls.map_or(0, |v| v.count),
            frames_traced: vpls.map_or(0, |v| v.frames_traced),
            min_distance: o.min_distance_for(scene),
            skipped: gather.is_none(),
        };
        // Its gather rays would meet no diffuse surface either.
        let compensation = if interreflects {
            BiasCompensation::prepare(
                p,
                (&with.photons, &with.estimate),
                o.bias_compensation,
                o.min_distance_for(scene),
                timings,
                observer,
            )?
        } else {
            None
        };
        Ok(Self {
            caustics,
            gather,
            report,
            stats: Vec::new(),
            compensation,
        })
    }
}

impl FrameMethod for IgiRun {
    /// The caustic estimate with the direct light, plus the VPLs' light and
    /// what the bound left out of it where compensated.
    fn sample(
        &mut self,
        f: &SampleFrame<'_>,
        timings: &mut Timings,
        observer: &mut dyn RenderObserver,
    ) -> Result<Image> {
        let mut image = MapEstimate::image_or_direct(self.caustics.as_mut(), f, timings, observer)?;
        let Some(VplGather { vpls, igi }) = &self.gather else {
            return Ok(image);
        };
        let at = f.at;
        let stats = igi.run(
            f.textures,
            f.direct,
            vpls,
            f.camera_position,
            timings,
            &mut |done, total| {
                observer.progress(&Progress::at("VPL gather", done as u64, total as u64, at))
            },
        )?;
        self.stats.push(stats);
        image.add(&igi.read_indirect());
        if let Some(c) = &mut self.compensation {
            image.add(&c.sample(f, timings, observer)?);
        }
        Ok(image)
    }
}
