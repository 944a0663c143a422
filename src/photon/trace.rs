//! Breadth-first photon tracing (section 2.1): emission into frame 0, then one
//! pass per bounce, each writing its own frame (a band of rows) of four RGBA32F
//! textures. Photon i sits at texel (i % width, i / width) of every frame.
//! `TraceConfig::fused` traces every bounce of a photon in one pass instead,
//! storing the same records through images (glsl/photon/trace_fused.frag).

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture};
use crate::scene::pack::SceneTextures;
use crate::scene::Scene;

use super::halton::{halton_dimension, RandomSource, ScrambledHalton};
use super::projection::ProjectionMaps;

/// The photon textures after tracing.
pub struct PhotonFrames {
    /// xyz, w = material of the hit (-1: on the light)
    pub position: Texture,
    /// rgb arriving, w = 1 where the photon is stored
    pub power: Texture,
    /// direction of arrival, w = 1 if the photon goes on
    pub incoming: Texture,
    /// direction it leaves by, w = primitive hit (-1: none)
    pub outgoing: Texture,
    target: Target,
    pub width: u32,
    pub frame_height: u32,
    pub frames: u32,
    /// Photons traced.
    pub emitted: u32,
    /// Photons whose records count: indices below this (see `PhotonTracer::trace_to_stored`).
    pub photons_used: u32,
    /// emitted / photons_used: the power each used photon must carry.
    pub power_scale: f32,
    /// GPU time of the emission and bounce passes (timer query).
    pub gpu_seconds: f64,
    /// Tracing passes drawn: emission and each bounce's, or emission and
    /// the fused pass.
    pub passes: u32,
    /// The projection maps photons were aimed by (scenes that store caustics only).
    pub projection: Option<ProjectionMaps>,
}

impl PhotonFrames {
    /// Frames of `frames` bands of `width` x `frame_height` texels, made
    /// from the four record textures (each `width` x `frame_height * frames`).
    fn assemble(
        gpu: &Gpu,
        [position, power, incoming, outgoing]: [Texture; 4],
        frame_height: u32,
        frames: u32,
    ) -> Result<Self> {
        let target = Target::new(gpu, &[&position, &power, &incoming, &outgoing])?;
        let width = position.width;
        Ok(Self {
            position,
            power,
            incoming,
            outgoing,
            target,
            width,
            frame_height,
            frames,
            emitted: width * frame_height,
            photons_used: width * frame_height,
            power_scale: 1.0,
            gpu_seconds: 0.0,
            passes: 0,
            projection: None,
        })
    }

    /// The records as a build pass reads them: position and power textures,
    /// their layout, and how many photons count.
    pub fn bind_records(&self, b: &mut crate::gpu::Bindings<'_>) {
        b.texture("u_position", &self.position)
            .texture("u_power", &self.power)
            .int("u_record_width", self.width as i32)
            .int("u_record_count", self.record_count() as i32)
            .int("u_frame_height", self.frame_height as i32)
            .int("u_photons_used", self.photons_used as i32);
    }

    /// Texels in all frames: the records a photon-map build reads.
    pub fn record_count(&self) -> u32 {
        self.width * self.frame_height * self.frames
    }

    /// Stored records per photon index, from a read-back of every frame's power
    /// (the CPU twin of `PhotonTracer::stored_per_photon`).
    pub fn stored_per_photon(&self) -> Vec<u32> {
        let power = self.power.read_f32();
        let per_frame = (self.width * self.frame_height) as usize;
        let mut counts = vec![0u32; self.emitted as usize];
        for (texel, p) in power.chunks(4).enumerate() {
            let photon = texel % per_frame;
            if p[3] != 0.0 && photon < counts.len() {
                counts[photon] += 1;
            }
        }
        counts
    }

    /// Stored records among the photons in use.
    pub fn stored(&self) -> u32 {
        self.stored_per_photon()[..self.photons_used as usize]
            .iter()
            .sum()
    }

    /// The four record textures, under the names every program reading
    /// whole photon records gives them.
    pub fn bind_record_textures(&self, b: &mut crate::gpu::Bindings<'_>) {
        b.texture("u_position", &self.position)
            .texture("u_power", &self.power)
            .texture("u_incoming", &self.incoming)
            .texture("u_outgoing", &self.outgoing);
    }
}

/// What both bounce programs (per bounce and fused) read: the scene, the
/// random numbers, the records, and `photon/bounce.glsl`'s uniforms.
fn bind_bounce_inputs(
    b: &mut crate::gpu::Bindings<'_>,
    scene: &Scene,
    textures: &SceneTextures,
    batch: &PhotonBatch,
    seed: u32,
) {
    let f = &batch.frames;
    textures.bind(b);
    if let Some((_, r)) = &batch.random {
        b.texture("u_random_numbers", r);
    }
    f.bind_record_textures(b);
    b.uint("u_seed", seed)
        .int("u_frame_height", f.frame_height as i32)
        .int("u_store_direct", scene.photon_map.store_direct as i32)
        .int("u_caustics_only", scene.photon_map.caustics_only as i32)
        .int(
            "u_specular_last_only",
            scene.photon_map.specular_last_only as i32,
        );
}

/// Frame width and height for `emitted` photons and `frames` frames: square-ish
/// frames (width a power of two) stacked within the driver's texture size.
pub fn frame_layout(emitted: u32, frames: u32, max_size: u32) -> Result<(u32, u32)> {
    // Square-ish, but wide enough that all frames fit the driver's height.
    let square = (emitted as f64).sqrt().ceil() as u64;
    let needed = (emitted as u64 * frames as u64).div_ceil(max_size as u64);
    let width = (square.max(needed).next_power_of_two() as u32).clamp(1, max_size);
    let frame_height = emitted.div_ceil(width).max(1);
    if frame_height as u64 * frames as u64 > max_size as u64 {
        return Err(Error::TooLarge(format!(
            "{emitted} photons x {frames} frames need {} x {} texels; this driver allows {max_size} a side: emit fewer photons or allow fewer bounces",
            width,
            frame_height as u64 * frames as u64
        )));
    }
    Ok((width, frame_height))
}

/// What `trace_to_stored` did to reach the stored count.
#[derive(Clone, Debug, serde::Serialize)]
pub struct TraceReport {
    /// Photons traced in each attempt.
    pub attempts: Vec<u32>,
    pub emitted: u32,
    pub photons_used: u32,
    pub stored: u32,
    pub target: u32,
    /// GPU time of the last (kept) trace, and of all attempts together.
    pub gpu_seconds: f64,
    pub gpu_seconds_all_attempts: f64,
    /// With projection maps: kept cells of all lights, cells in all, and the
    /// share of the lights' power that leaves through kept cells.
    pub projection: Option<ProjectionSummary>,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct ProjectionSummary {
    pub resolution: u32,
    pub kept_cells: usize,
    pub cells: usize,
    pub kept_power_fraction: f64,
}

impl ProjectionSummary {
    pub fn new(maps: &ProjectionMaps, scene: &Scene) -> Self {
        Self {
            resolution: maps.resolution,
            kept_cells: maps.maps.iter().map(|m| m.cells.len()).sum(),
            cells: maps.maps.len() * (maps.resolution as usize).pow(2),
            kept_power_fraction: maps.kept_power_fraction(scene),
        }
    }
}

/// How a `PhotonTracer` traces (fixed when it is made).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TraceConfig {
    pub random: RandomSource,
    /// Stop bouncing once an occlusion query finds no live photon (the frames
    /// not traced are left out of every build).
    pub stop_when_dead: bool,
    /// Aim photons by projection maps when the scene stores caustics only
    /// (off: emit everywhere and keep only the caustic paths, to compare).
    pub projection_maps: bool,
    /// Every bounce of a photon in one pass after emission, instead of a
    /// pass per bounce. The records a build reads are the same; frames after
    /// a photon's end keep only power 0 (not stored), not a dead record.
    pub fused: bool,
}

impl Default for TraceConfig {
    fn default() -> Self {
        Self {
            random: RandomSource::Hash,
            stop_when_dead: true,
            projection_maps: true,
            fused: false,
        }
    }
}

pub struct PhotonTracer {
    gpu: Gpu,
    config: TraceConfig,
    emit: Program,
    bounce: Program,
    count: Program,
    probe: Program,
    /// The fused path (`TraceConfig::fused`).
    fused: Option<Program>,
    /// Emission through projection maps, compiled on first use.
    emit_projected: std::cell::OnceCell<Program>,
    defines: Vec<(&'static str, String)>,
}

/// Projection maps ready for emission: the maps and their texture.
struct Aim {
    maps: ProjectionMaps,
    texture: Texture,
}

/// A batch of photons traced into frames that are made once and traced into
/// again with a new seed (SPPM's iterations): the frames' textures, the random
/// numbers, the projection maps, and the queries that time passes and probe
/// for live photons.
pub struct PhotonBatch {
    pub frames: PhotonFrames,
    random: Option<(u32, Texture)>,
    aim: Option<std::rc::Rc<Aim>>,
    timer: Query,
    alive: Query,
    probe: Option<(Texture, Target)>,
    /// The fused path's per-photon last live frame, and a target that clears
    /// the power texture alone.
    fused: Option<FusedTargets>,
}

struct FusedTargets {
    last: Texture,
    last_target: Target,
    power: Target,
}

impl PhotonTracer {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        Self::with_config(gpu, TraceConfig::default())
    }

    pub fn with_config(gpu: &Gpu, config: TraceConfig) -> Result<Self> {
        let defines: Vec<(&'static str, String)> = match config.random {
            RandomSource::Hash => vec![],
            RandomSource::Texture | RandomSource::Halton => {
                vec![("RANDOM_TEXTURE", "1".into())]
            }
        };
        Ok(Self {
            gpu: gpu.clone(),
            config,
            emit: Program::fullscreen_with(gpu, "photon/emit.frag", &defines)?,
            bounce: Program::fullscreen_with(gpu, "photon/trace.frag", &defines)?,
            count: Program::fullscreen(gpu, "photon/stored_count.frag")?,
            probe: Program::fullscreen(gpu, "photon/alive_probe.frag")?,
            fused: match config.fused {
                true => Some(Program::fullscreen_with(
                    gpu,
                    "photon/trace_fused.frag",
                    &defines,
                )?),
                false => None,
            },
            emit_projected: std::cell::OnceCell::new(),
            defines,
        })
    }

    pub fn config(&self) -> TraceConfig {
        self.config
    }

    /// The random-number texture: for frame f and photon texel (x, y), the
    /// first RANDOM_PER_PHOTON_FRAME numbers of the hash stream that frame would use.
    fn random_texture(
        &self,
        seed: u32,
        width: u32,
        frame_height: u32,
        frames: u32,
    ) -> Result<Texture> {
        use crate::layout::RANDOM_PER_PHOTON_FRAME;
        use crate::random::{rng_init, rng_next};
        let mut data = vec![0f32; (width * 2 * frame_height * frames * 4) as usize];
        let halton =
            (self.config.random == RandomSource::Halton).then(|| ScrambledHalton::new(seed));
        for f in 0..frames {
            for y in 0..frame_height {
                for x in 0..width {
                    let mut state = rng_init(seed, [x, y], 0x10000000 + f);
                    let row = (f * frame_height + y) as usize;
                    let base = (row * (width as usize * 2) + x as usize * 2) * 4;
                    for k in 0..RANDOM_PER_PHOTON_FRAME {
                        data[base + k] = rng_next(&mut state);
                        let dim = halton.as_ref().zip(halton_dimension(f as usize, k));
                        if let Some((h, dim)) = dim {
                            data[base + k] = h.number(dim, (y * width + x) as u64);
                        }
                    }
                }
            }
        }
        Texture::from_texels(
            &self.gpu,
            width * 2,
            frame_height * frames,
            TexFormat::Rgba32F,
            &data,
        )
    }

    /// Traces `emitted` photons through `max_bounces` bounces; all of them count.
    pub fn trace(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        seed: u32,
        emitted: u32,
    ) -> Result<PhotonFrames> {
        let mut batch = self.batch(scene, emitted)?;
        self.trace_batch(scene, textures, &mut batch, seed)?;
        Ok(batch.frames)
    }

    /// Frames for `emitted` photons (and the scene's projection maps), to be
    /// traced into by `trace_batch` as often as wanted.
    pub fn batch(&self, scene: &Scene, emitted: u32) -> Result<PhotonBatch> {
        let aim = self.aim_for(scene)?.map(std::rc::Rc::new);
        self.batch_aimed(scene, aim, emitted)
    }

    fn batch_aimed(
        &self,
        scene: &Scene,
        aim: Option<std::rc::Rc<Aim>>,
        emitted: u32,
    ) -> Result<PhotonBatch> {
        let frames = scene.photon_map.max_bounces + 1;
        let (width, frame_height) = frame_layout(emitted, frames, self.gpu.max_texture_size())?;
        let height = frame_height * frames;
        let t = || Texture::new(&self.gpu, width, height, TexFormat::Rgba32F);
        // No clear: emission and every bounce write each texel of their frame.
        let mut frames =
            PhotonFrames::assemble(&self.gpu, [t()?, t()?, t()?, t()?], frame_height, frames)?;
        frames.emitted = emitted;
        frames.photons_used = emitted;
        frames.projection = aim.as_ref().map(|a| a.maps.clone());
        Ok(PhotonBatch {
            frames,
            random: None,
            aim,
            timer: Query::timer(&self.gpu)?,
            alive: Query::occlusion(&self.gpu)?,
            probe: None,
            fused: None,
        })
    }

    /// Traces the batch's photons anew with `seed`: emission, then one pass per
    /// bounce (stopping early when no photon is alive, if configured).
    pub fn trace_batch(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        batch: &mut PhotonBatch,
        seed: u32,
    ) -> Result<()> {
        let frames = scene.photon_map.max_bounces + 1;
        if self.config.random != RandomSource::Hash
            && batch.random.as_ref().map(|r| r.0) != Some(seed)
        {
            let f = &batch.frames;
            let texture = self.random_texture(seed, f.width, f.frame_height, frames)?;
            batch.random = Some((seed, texture));
        }
        // Each pass timed alone: a timer query spanning the probes' occlusion
        // read-backs reads nonsense on llvmpipe.
        let mut gpu_seconds = 0.0;
        self.gpu.finish();
        let wall = std::time::Instant::now();
        if self.fused.is_some() {
            self.clear_power(batch)?;
        }
        gpu_seconds += self.emit_pass(scene, textures, batch, seed)?;
        let mut frames_used = frames;
        if self.fused.is_some() {
            let (seconds, last) = self.fused_pass(scene, textures, batch, seed)?;
            gpu_seconds += seconds;
            // As the per-bounce passes stop: the first frame with no live
            // photon is the last one read.
            if self.config.stop_when_dead {
                frames_used = (last.max(0) as u32 + 2).min(frames);
            }
        } else {
            for bounce in 1..frames {
                crate::interrupt::check()?;
                gpu_seconds += self.bounce_pass(scene, textures, batch, seed, bounce)?;
                if self.config.stop_when_dead
                    && bounce + 1 < frames
                    && self.live_photons(batch, bounce)? == 0
                {
                    // No photon of this frame goes on: the rest is dark.
                    frames_used = bounce + 1;
                    break;
                }
            }
        }
        self.gpu.finish();
        // llvmpipe has been seen to return nonsense (hours) for these timer
        // queries once occlusion queries are read between them: a GPU time
        // longer than the wall clock cannot be, so keep the wall clock then.
        let wall = wall.elapsed().as_secs_f64();
        self.gpu.check("photon tracing")?;
        batch.frames.frames = frames_used;
        batch.frames.passes = if self.fused.is_some() { 2 } else { frames_used };
        batch.frames.gpu_seconds = gpu_seconds.min(wall);
        Ok(())
    }

    /// Emission into frame 0; returns its GPU seconds.
    fn emit_pass(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        pass: &PhotonBatch,
        seed: u32,
    ) -> Result<f64> {
        let f = &pass.frames;
        let emit = match pass.aim {
            None => &self.emit,
            Some(_) => self.emit_projected()?,
        };
        let mut b = emit.bind();
        textures.bind(&mut b);
        if let Some((_, r)) = &pass.random {
            b.texture("u_random_numbers", r);
        }
        if let Some(aim) = &pass.aim {
            b.texture("u_projection", &aim.texture).int(
                "u_projection_resolution",
                scene.photon_map.projection_resolution as i32,
            );
        }
        b.uint("u_seed", seed)
            .int("u_emitted", f.emitted as i32)
            .int("u_width", f.width as i32);
        pass.timer.around(|| {
            b.draw_region(
                &f.target,
                &DrawState::PLAIN,
                [0, 0, f.width as i32, f.frame_height as i32],
            )
        })?;
        Ok(pass.timer.seconds())
    }

    /// Bounce `bounce` from frame bounce - 1 into frame `bounce`; returns its GPU seconds.
    fn bounce_pass(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        pass: &PhotonBatch,
        seed: u32,
        bounce: u32,
    ) -> Result<f64> {
        let f = &pass.frames;
        // The previous frame was drawn into these very textures.
        self.gpu.texture_barrier();
        let mut b = self.bounce.bind();
        bind_bounce_inputs(&mut b, scene, textures, pass, seed);
        let fh = f.frame_height as i32;
        b.int("u_bounce", bounce as i32);
        pass.timer.around(|| {
            b.draw_region(
                &f.target,
                &DrawState::PLAIN,
                [0, bounce as i32 * fh, f.width as i32, fh],
            )
        })?;
        Ok(pass.timer.seconds())
    }

    /// Before emission on the fused path: every frame reads as not stored
    /// until a photon's bounce stores it there.
    fn clear_power(&self, batch: &mut PhotonBatch) -> Result<()> {
        if batch.fused.is_none() {
            let f = &batch.frames;
            let last = Texture::new(&self.gpu, f.width, f.frame_height, TexFormat::R32F)?;
            batch.fused = Some(FusedTargets {
                last_target: Target::new(&self.gpu, &[&last])?,
                last,
                power: Target::new(&self.gpu, &[&f.power])?,
            });
        }
        batch
            .fused
            .as_ref()
            .expect("made above")
            .power
            .clear([0.0; 4]);
        Ok(())
    }

    /// Every bounce after emission in one pass (glsl/photon/trace_fused.frag):
    /// its GPU seconds and the last frame in which any photon goes on (-1:
    /// none was emitted).
    fn fused_pass(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        batch: &mut PhotonBatch,
        seed: u32,
    ) -> Result<(f64, i32)> {
        let program = self
            .fused
            .as_ref()
            .expect("fused_pass needs the fused program");
        let (f, targets) = (
            &batch.frames,
            batch.fused.as_ref().expect("clear_power made them"),
        );
        let mut b = program.bind();
        bind_bounce_inputs(&mut b, scene, textures, batch, seed);
        b.image("u_position_out", &f.position)
            .image("u_power_out", &f.power)
            .image("u_incoming_out", &f.incoming)
            .image("u_outgoing_out", &f.outgoing)
            .int("u_frames", f.frames as i32);
        batch
            .timer
            .around(|| b.draw_fullscreen(&targets.last_target, &DrawState::PLAIN))?;
        self.gpu.image_barrier();
        let last = targets.last.read_f32().into_iter().fold(-1.0f32, f32::max);
        Ok((batch.timer.seconds(), last as i32))
    }

    /// How many photons of frame `bounce` go on (an occlusion query).
    fn live_photons(&self, pass: &mut PhotonBatch, bounce: u32) -> Result<u64> {
        self.gpu.texture_barrier();
        let (width, frame_height) = (pass.frames.width, pass.frames.frame_height);
        if pass.probe.is_none() {
            let t = Texture::new(&self.gpu, width, frame_height, TexFormat::R32F)?;
            let target = Target::new(&self.gpu, &[&t])?;
            pass.probe = Some((t, target));
        }
        let (_, probe) = pass.probe.as_ref().expect("made above");
        let mut b = self.probe.bind();
        b.texture("u_incoming", &pass.frames.incoming)
            .int("u_frame_row", (bounce * frame_height) as i32);
        pass.alive
            .around(|| b.draw_fullscreen(probe, &DrawState::NO_COLOR))?;
        Ok(pass.alive.count())
    }

    /// The projection maps this scene's photons are aimed by, and their
    /// texture, if any: the scene stores caustics only and they are not
    /// switched off.
    fn aim_for(&self, scene: &Scene) -> Result<Option<Aim>> {
        if !(scene.photon_map.caustics_only && self.config.projection_maps) {
            return Ok(None);
        }
        let maps = ProjectionMaps::for_scene(scene);
        if maps.kept_power_fraction(scene) <= 0.0 {
            return Err(Error::NoCausticPath);
        }
        let t = maps.texels(scene);
        let texture =
            Texture::from_texels(&self.gpu, t.width, t.height, TexFormat::Rgba32F, &t.data)?;
        Ok(Some(Aim { maps, texture }))
    }

    fn emit_projected(&self) -> Result<&Program> {
        if let Some(p) = self.emit_projected.get() {
            return Ok(p);
        }
        let mut defines = self.defines.clone();
        defines.push(("PROJECTION_MAPS", "1".into()));
        let p = Program::fullscreen_with(&self.gpu, "photon/emit.frag", &defines)?;
        Ok(self.emit_projected.get_or_init(|| p))
    }

    /// Stored records per photon index, counted on the GPU (one float per
    /// photon read back, not the power texture of every frame).
    pub fn stored_per_photon(&self, frames: &PhotonFrames) -> Result<Vec<u32>> {
        let counts = Texture::new(
            &self.gpu,
            frames.width,
            frames.frame_height,
            TexFormat::R32F,
        )?;
        let target = Target::new(&self.gpu, &[&counts])?;
        self.count
            .bind()
            .texture("u_power", &frames.power)
            .int("u_frame_height", frames.frame_height as i32)
            .int("u_frames", frames.frames as i32)
            .draw_fullscreen(&target, &DrawState::PLAIN)?;
        Ok(counts
            .read_f32()
            .into_iter()
            .take(frames.emitted as usize)
            .map(|c| c as u32)
            .collect())
    }

    /// Traces until the map can hold exactly `photons_stored` photons: trace N,
    /// count the stored records of each photon (in index order), and if they
    /// fall short, trace again with N scaled by target / stored (x 1.1 + 64).
    /// Then keep the first M photons whose records reach the target, and give
    /// each the power of 1/M of the light (power_scale = N / M). Only the last
    /// kept photon may add records past the target, so stored is the target or
    /// a few above it (its further bounces).
    pub fn trace_to_stored(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        seed: u32,
    ) -> Result<(PhotonFrames, TraceReport)> {
        let target = scene.photon_map.photons_stored;
        let max_emitted = {
            let frames = scene.photon_map.max_bounces + 1;
            let max = self.gpu.max_texture_size() as u64;
            // Whole rows per frame of the widest frame.
            ((max / frames as u64) * max).min(u32::MAX as u64 / 2) as u32
        };
        let aim = self.aim_for(scene)?.map(std::rc::Rc::new);
        // store_direct would store more, but caustics-only scenes cannot have it.
        let remedy = if scene.photon_map.caustics_only {
            ", or store all paths (caustics_only = false)"
        } else {
            ", or set store_direct"
        };
        let mut emitted = target.max(64);
        let mut attempts = Vec::new();
        let mut all_seconds = 0.0;
        loop {
            crate::interrupt::check()?;
            let mut batch = self.batch_aimed(scene, aim.clone(), emitted)?;
            self.trace_batch(scene, textures, &mut batch, seed)?;
            let mut frames = batch.frames;
            attempts.push(emitted);
            all_seconds += frames.gpu_seconds;
            let counts = self.stored_per_photon(&frames)?;
            let total: u64 = counts.iter().map(|&c| c as u64).sum();
            if total >= target as u64 {
                let (used, stored) = photons_reaching(&counts, target);
                frames.photons_used = used;
                frames.power_scale = emitted as f32 / used as f32;
                let report = TraceReport {
                    attempts,
                    emitted,
                    photons_used: used,
                    stored,
                    target,
                    gpu_seconds: frames.gpu_seconds,
                    gpu_seconds_all_attempts: all_seconds,
                    projection: aim.as_ref().map(|a| ProjectionSummary::new(&a.maps, scene)),
                };
                return Ok((frames, report));
            }
            if total == 0 && emitted >= 250_000 {
                return Err(Error::NoPhotonsStored { emitted, remedy });
            }
            if emitted >= max_emitted || attempts.len() >= 8 {
                return Err(Error::TooFewPhotonsStored {
                    emitted,
                    stored: total,
                    target,
                    remedy,
                });
            }
            let grow = if total == 0 {
                16.0
            } else {
                (target as f64 / total as f64) * 1.1
            };
            emitted = ((emitted as f64 * grow) as u64 + 64).min(max_emitted as u64) as u32;
        }
    }
}

/// The first M photons (in index order) whose stored records reach `target`,
/// and how many records they store.
fn photons_reaching(counts: &[u32], target: u32) -> (u32, u32) {
    let mut sum = 0u32;
    for (i, &c) in counts.iter().enumerate() {
        sum += c;
        if sum >= target {
            return (i as u32 + 1, sum);
        }
    }
    (counts.len() as u32, sum)
}

impl PhotonFrames {
    pub fn target(&self) -> &Target {
        &self.target
    }

    /// Photon frames made from given records (RGBA per texel, row 0 first, all
    /// frames stacked): for tests and benchmarks of the builds on chosen inputs.
    #[allow(clippy::too_many_arguments)]
    pub fn from_records(
        gpu: &Gpu,
        width: u32,
        frame_height: u32,
        frames: u32,
        position: &[f32],
        power: &[f32],
        incoming: &[f32],
        photons_used: u32,
    ) -> Result<Self> {
        let height = frame_height * frames;
        let t = |d: &[f32]| Texture::from_texels(gpu, width, height, TexFormat::Rgba32F, d);
        let outgoing = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let mut f = Self::assemble(
            gpu,
            [t(position)?, t(power)?, t(incoming)?, outgoing],
            frame_height,
            frames,
        )?;
        f.photons_used = photons_used;
        Ok(f)
    }

    /// One frame of `n` photons, `width` texels a row, photon i's position,
    /// power and incoming direction (RGBA each) given by `record(i)`; the
    /// rest of the last row holds none.
    pub fn one_frame(
        gpu: &Gpu,
        width: u32,
        n: u32,
        mut record: impl FnMut(usize) -> [[f32; 4]; 3],
    ) -> Result<Self> {
        let frame_height = n.div_ceil(width);
        let texels = (width * frame_height) as usize;
        let mut records = [(); 3].map(|_| vec![0f32; texels * 4]);
        for i in 0..n as usize {
            for (channel, v) in records.iter_mut().zip(record(i)) {
                channel[4 * i..4 * i + 4].copy_from_slice(&v);
            }
        }
        let [position, power, incoming] = &records;
        Self::from_records(gpu, width, frame_height, 1, position, power, incoming, n)
    }
}
