//! Photon differentials and the footprint BVH (Fabianowski and Dingliana
//! 2009, sections 4 and 5) on the photon frames, in fragment passes:
//!
//! 1. **Differentials** (`differentials.frag`): one pass per frame, beside
//!    the photon records, two positional and two directional differentials
//!    a photon (in units of the spacing Delta = 2 sqrt(pi / n)).
//! 2. **Morton codes** (`footprint_keys.frag`) of the stored records, after
//!    the HistoPyramid compaction, sorted by the bitonic passes.
//! 3. **Footprints** (`footprints.frag`) in Morton order: the ellipses,
//!    their areas and powers (which points each holds: `FootprintShape`).
//! 4. **The BVH**: leaves of T consecutive footprints (`footprint_leaves`)
//!    and their boxes, then the inner boxes one level a pass
//!    (`footprint_reduce`). The tree is the complete binary tree over the
//!    leaves in Morton order (node i's children 2i, 2i + 1): the paper's
//!    linear BVH splits where the Morton code's leading bit changes; this one
//!    splits at the middle leaf, which makes it implicit and its walk
//!    stackless. T is the paper's automatic threshold (the footprints' total
//!    area over the scene's surface area) or given.

use glam::Vec3;

use crate::error::Error;
use crate::gpu::{DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture};
use crate::scene::pack::{light_probabilities, SceneTextures};
use crate::scene::{Light, Scene};
use crate::timing::Timings;

use super::bitonic::BitonicBuild;
use super::{Grid, PhotonFrames, StageClock};

/// Width of the BVH's box textures (node i at texel (i mod width, i / width)).
pub const BOX_ROW_TEXELS: u32 = 4096;

/// The differentials of every photon record, in textures shaped as the frames.
pub struct DifferentialFrames {
    /// dp at the hit (xyz); axis1.w = 1 if reflected diffusely before the hit,
    /// axis2.w = the same as it leaves.
    pub axis1: Texture,
    pub axis2: Texture,
    /// dp and dd as the photon leaves (dp1, dd1.x), (dp2, dd1.y), (dd2, dd1.z).
    pub state: [Texture; 3],
}

/// Each light's measures per photon (`differentials.frag`), in units of the
/// spacing Delta = 2 sqrt(pi / n): [directional, positional]. The
/// directional one, kept fraction / pick probability, scales the emitted
/// directional differentials' area (a light picked with probability p sends
/// n p photons, into the kept fraction of its directions). The positional
/// one, area / (4 pi p), is the squared length of an area light's positional
/// differentials, so that its footprint at emission is pi times the area of
/// the light per photon (A / (n p)), as a point light's is pi times the area
/// per photon at any distance; 0 for a point light.
pub fn light_measures(scene: &Scene, frames: &PhotonFrames) -> Vec<[f32; 2]> {
    let picks = light_probabilities(scene);
    let texels = frames.projection.as_ref().map(|p| p.texels(scene));
    scene
        .lights
        .iter()
        .enumerate()
        .map(|(l, light)| {
            let (probability, kept) = match &texels {
                Some(t) => (t.texel(l, 0).y, t.texel(l, 0).z),
                None => (picks[l], 1.0),
            };
            if probability <= 0.0 {
                return [0.0, 0.0];
            }
            let positional = match light {
                Light::Point { .. } => 0.0,
                _ => light.area(&scene.shapes) / (4.0 * std::f32::consts::PI * probability),
            };
            [kept / probability, positional]
        })
        .collect()
}

/// Runs the differentials pass over every traced frame.
pub fn trace_differentials(
    gpu: &Gpu,
    scene: &Scene,
    textures: &SceneTextures,
    frames: &PhotonFrames,
) -> Result<DifferentialFrames> {
    let (w, h) = (frames.width, frames.frame_height * frames.frames);
    let t = || Texture::new(gpu, w, h, TexFormat::Rgba32F);
    let out = DifferentialFrames {
        axis1: t()?,
        axis2: t()?,
        state: [t()?, t()?, t()?],
    };
    let target = Target::new(
        gpu,
        &[
            &out.axis1,
            &out.axis2,
            &out.state[0],
            &out.state[1],
            &out.state[2],
        ],
    )?;
    let measures = light_measures(scene, frames);
    let mut data = vec![0f32; measures.len().max(1) * 4];
    for (l, m) in measures.iter().enumerate() {
        data[4 * l..4 * l + 2].copy_from_slice(m);
    }
    let measure = Texture::from_texels(
        gpu,
        measures.len().max(1) as u32,
        1,
        TexFormat::Rgba32F,
        &data,
    )?;
    let program = Program::fullscreen(gpu, "photon/differentials.frag")?;
    let fh = frames.frame_height as i32;
    for frame in 0..frames.frames {
        // The previous frame was drawn into these very textures.
        gpu.texture_barrier();
        let mut b = program.bind();
        textures.bind(&mut b);
        frames.bind_record_textures(&mut b);
        b.texture("u_axis1", &out.axis1)
            .texture("u_axis2", &out.axis2)
            .texture("u_state0", &out.state[0])
            .texture("u_state1", &out.state[1])
            .texture("u_state2", &out.state[2])
            .texture("u_light_measure", &measure)
            .int("u_frame", frame as i32)
            .int("u_frame_height", fh)
            .draw_region(
                &target,
                &DrawState::PLAIN,
                [0, frame as i32 * fh, w as i32, fh],
            )?;
    }
    gpu.check("photon differentials")?;
    Ok(out)
}

/// Which query points a footprint holds (glsl/common/footprint.glsl).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum FootprintShape {
    /// The ellipse on the surface, holding a query point whose projection
    /// lies in it and which lies as near the ellipse's plane as a surface
    /// through its centre, curving to the query's normal (tilted by up to
    /// 60 degrees), would: a ball's points stay in it, the other wall at a
    /// corner does not.
    #[default]
    Curved,
    /// The paper's thin ellipsoid, which on a curved surface lets the points
    /// near its rim out and loses their share of the power.
    Ellipsoid,
}

impl FootprintShape {
    /// The shaders' `u_curved`.
    pub fn curved(self) -> bool {
        self == FootprintShape::Curved
    }
}

/// How footprints are made from differentials.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct FootprintOptions {
    /// s: the smoothing factor of photons reflected diffusely before.
    pub smoothing: f32,
    /// The factor of photons that have been only specular (the paper: 5).
    pub caustic_smoothing: f32,
    /// r_max: every semi-axis is clamped to it.
    pub max_radius: f32,
    /// T: footprints a leaf (None: the automatic threshold).
    pub leaf_size: Option<u32>,
    /// Probes a footprint for its share on its own surface (0: none, the
    /// whole ellipse counts); weighted by the Epanechnikov kernel if asked.
    pub coverage_samples: u32,
    pub coverage_epanechnikov: bool,
    /// Leave out the footprints of photons that have been only specular: a
    /// caustic footprint map of photons aimed by projection maps carries
    /// that light instead.
    pub drop_caustics: bool,
    /// Which query points a footprint holds.
    pub shape: FootprintShape,
}

/// The footprints in Morton order and their BVH.
pub struct FootprintMap {
    /// footprint 0..3 (glsl/common/footprint.glsl), `width` texels a row.
    pub footprints: [Texture; 4],
    pub width: u32,
    /// Footprints (stored photon records).
    pub count: u32,
    /// (Morton code, record) pairs in order.
    pub sorted: Texture,
    /// Node boxes (min, max) of the implicit tree, BOX_ROW_TEXELS a row.
    pub box_min: Texture,
    pub box_max: Texture,
    pub box_width: u32,
    /// P: leaves (a power of two), and T: footprints a leaf.
    pub leaves: u32,
    pub leaf_size: u32,
    /// The automatic T, whether used or not.
    pub auto_leaf_size: u32,
    /// Footprints whose photon had been reflected diffusely.
    pub diffuse: u32,
    /// Caustic footprints left out (`FootprintOptions::drop_caustics`).
    pub dropped_caustics: u32,
    /// Footprints with no area (skipped), and the share of the stored power
    /// they carry.
    pub degenerate: u32,
    pub degenerate_power_fraction: f64,
    /// Sum of the footprints' areas, and the scene's surface area.
    pub total_area: f64,
    pub surface_area: f64,
    pub delta: f32,
    pub options: FootprintOptions,
    /// The scene box the Morton codes are over, and its scale (1024 / extent).
    pub morton_lo: Vec3,
    pub morton_scale: Vec3,
}

impl FootprintMap {
    /// The nodes [start, 2 start) of one level as a viewport of the box textures.
    pub fn level_region(&self, start: u32) -> [i32; 4] {
        level_region(start, self.box_width)
    }
}

fn level_region(start: u32, box_width: u32) -> [i32; 4] {
    if start >= box_width {
        [
            0,
            (start / box_width) as i32,
            box_width as i32,
            (start / box_width) as i32,
        ]
    } else {
        [start as i32, 0, start as i32, 1]
    }
}

/// The Morton box of a scene: its bounds, and 1024 / extent per axis.
pub fn morton_frame(scene: &Scene) -> (Vec3, Vec3) {
    let (lo, hi) = scene.bounds();
    let extent = (hi - lo).max(Vec3::splat(1e-20));
    (lo, Vec3::splat(1024.0) / extent)
}

/// The scene's surface area, emitters left out.
pub fn receiving_area(scene: &Scene) -> f64 {
    scene
        .shapes
        .iter()
        .filter(|s| {
            !matches!(
                scene.materials[s.material],
                crate::scene::Material::Emitter { .. }
            )
        })
        .map(|s| f64::from(crate::scene::surface_area(&s.geometry)))
        .sum()
}

/// The paper's automatic leaf size: total footprint area over surface area
/// (the footprints expected to hold a uniformly placed query point), at least 1.
pub fn auto_leaf_size(total_area: f64, surface_area: f64) -> u32 {
    if surface_area > 0.0 {
        (total_area / surface_area).round().clamp(1.0, 1024.0) as u32
    } else {
        1
    }
}

/// Sums over the footprints, read back: their area, the degenerate ones and
/// the power they carry, and those of diffusely reflected photons.
struct FootprintTotals {
    area: f64,
    dropped_caustics: u32,
    degenerate: u32,
    degenerate_power_fraction: f64,
    diffuse: u32,
}

impl FootprintTotals {
    fn read(footprints: &[Texture; 4], count: u32) -> Self {
        let f0 = footprints[0].read_f32();
        let f1 = footprints[1].read_f32();
        let f3 = footprints[3].read_f32();
        let (mut area, mut degenerate, mut diffuse) = (0f64, 0u32, 0u32);
        let (mut power, mut lost, mut dropped_caustics) = (0f64, 0f64, 0u32);
        for i in 0..count as usize {
            let a = f0[4 * i + 3];
            let p: f64 = f3[4 * i..4 * i + 3].iter().map(|&c| f64::from(c)).sum();
            power += p;
            if f3[4 * i + 3] != 0.0 {
                dropped_caustics += 1;
            } else if a > 0.0 {
                area += f64::from(a);
            } else {
                degenerate += 1;
                lost += p;
            }
            diffuse += u32::from(f1[4 * i + 3] != 0.0);
        }
        Self {
            area,
            dropped_caustics,
            degenerate,
            degenerate_power_fraction: if power > 0.0 { lost / power } else { 0.0 },
            diffuse,
        }
    }
}

/// The passes that build a footprint map.
pub struct FootprintBuilder {
    gpu: Gpu,
    keys: Program,
    footprints: Program,
    leaves: Program,
    reduce: Program,
    bitonic: BitonicBuild,
}

impl FootprintBuilder {
    pub fn new(gpu: &Gpu) -> Result<Self> {
        let p = |name: &str| Program::fullscreen(gpu, name);
        Ok(Self {
            gpu: gpu.clone(),
            keys: p("photon/footprint_keys.frag")?,
            footprints: p("photon/footprints.frag")?,
            leaves: p("photon/footprint_leaves.frag")?,
            reduce: p("photon/footprint_reduce.frag")?,
            bitonic: BitonicBuild::new(gpu)?,
        })
    }

    /// The map of `frames`' stored records, with its stages added to `timings`
    /// ("footprint keys", "bitonic sort", "footprints", "footprint BVH").
    pub fn build(
        &self,
        scene: &Scene,
        textures: &SceneTextures,
        frames: &PhotonFrames,
        diffs: &DifferentialFrames,
        options: &FootprintOptions,
        timings: &mut Timings,
    ) -> Result<FootprintMap> {
        let gpu = &self.gpu;
        let query = Query::timer(gpu)?;
        let clock = StageClock::start(gpu, &query);
        // One cell: the compaction only needs the stored records' indices.
        let grid = Grid::over_scene(scene, f32::INFINITY, 1);
        let (pairs, count) = self.bitonic.compacted_pairs(frames, &grid)?;
        if count == 0 {
            return Err(Error::InvalidOption(format!(
                "no photon was stored in {}: nothing to make footprints of",
                scene.name
            )));
        }
        let (lo, scale) = morton_frame(scene);
        let keys = Texture::new(gpu, pairs.width, pairs.height, TexFormat::Rg32I)?;
        self.keys
            .bind()
            .texture("u_pairs", &pairs)
            .texture("u_position", &frames.position)
            .int("u_record_width", frames.width as i32)
            .int("u_count", count as i32)
            .vec3("u_lo", lo.to_array())
            .vec3("u_scale", scale.to_array())
            .draw_fullscreen(&Target::new(gpu, &[&keys])?, &DrawState::PLAIN)?;
        clock.stop(timings, "footprint keys", 2);
        let clock = StageClock::start(gpu, &query);
        let (sorted, passes) = self.bitonic.sort(keys)?;
        clock.stop(timings, "bitonic sort", passes as usize);

        let clock = StageClock::start(gpu, &query);
        let (w, h) = (sorted.width, sorted.height);
        let t = || Texture::new(gpu, w, h, TexFormat::Rgba32F);
        let footprints = [t()?, t()?, t()?, t()?];
        let delta = 2.0 * (std::f32::consts::PI / frames.photons_used as f32).sqrt();
        let mut b = self.footprints.bind();
        textures.bind(&mut b);
        b.texture("u_sorted", &sorted)
            .texture("u_position", &frames.position)
            .texture("u_power", &frames.power)
            .texture("u_incoming", &frames.incoming)
            .texture("u_axis1", &diffs.axis1)
            .texture("u_axis2", &diffs.axis2)
            .int("u_record_width", frames.width as i32)
            .int("u_count", count as i32)
            .float("u_delta", delta)
            .float("u_smoothing", options.smoothing)
            .float("u_caustic_smoothing", options.caustic_smoothing)
            .float("u_max_radius", options.max_radius)
            .float("u_power_scale", frames.power_scale)
            .int("u_coverage_samples", options.coverage_samples as i32)
            .int("u_epanechnikov", i32::from(options.coverage_epanechnikov))
            .int("u_drop_caustics", i32::from(options.drop_caustics))
            .draw_fullscreen(
                &Target::new(gpu, &footprints.each_ref())?,
                &DrawState::PLAIN,
            )?;
        drop(b);
        clock.stop(timings, "footprints", 1);
        // The footprints' total area (the automatic leaf size), by read-back.
        let totals = FootprintTotals::read(&footprints, count);
        let (total_area, degenerate, diffuse) = (totals.area, totals.degenerate, totals.diffuse);
        let surface_area = receiving_area(scene);
        let auto = auto_leaf_size(total_area, surface_area);
        let leaf_size = options.leaf_size.unwrap_or(auto).max(1);

        let clock = StageClock::start(gpu, &query);
        let (box_min, box_max, box_width, leaves, passes) =
            self.boxes(&footprints, w, count, leaf_size, options.shape)?;
        clock.stop(timings, "footprint BVH", passes);
        gpu.check("footprint BVH")?;
        Ok(FootprintMap {
            footprints,
            width: w,
            count,
            sorted,
            box_min,
            box_max,
            box_width,
            leaves,
            leaf_size,
            auto_leaf_size: auto,
            diffuse,
            dropped_caustics: totals.dropped_caustics,
            degenerate,
            degenerate_power_fraction: totals.degenerate_power_fraction,
            total_area,
            surface_area,
            delta,
            options: *options,
            morton_lo: lo,
            morton_scale: scale,
        })
    }

    /// The implicit tree's boxes: the leaves of `leaf_size` footprints, then
    /// one reduction pass a level. Returns (min, max, box width, leaves, passes).
    fn boxes(
        &self,
        footprints: &[Texture; 4],
        w: u32,
        count: u32,
        leaf_size: u32,
        shape: FootprintShape,
    ) -> Result<(Texture, Texture, u32, u32, usize)> {
        let gpu = &self.gpu;
        let leaves = count.div_ceil(leaf_size).next_power_of_two();
        let box_width = (2 * leaves).min(BOX_ROW_TEXELS);
        let box_height = (2 * leaves) / box_width;
        let box_min = Texture::new(gpu, box_width, box_height, TexFormat::Rgba32F)?;
        let box_max = Texture::new(gpu, box_width, box_height, TexFormat::Rgba32F)?;
        let target = Target::new(gpu, &[&box_min, &box_max])?;
        let mut b = self.leaves.bind();
        b.texture("u_footprint0", &footprints[0])
            .texture("u_footprint1", &footprints[1])
            .texture("u_footprint2", &footprints[2])
            .int("u_footprint_width", w as i32)
            .int("u_count", count as i32)
            .int("u_leaves", leaves as i32)
            .int("u_leaf_size", leaf_size as i32)
            .int("u_box_width", box_width as i32)
            .int("u_curved", i32::from(shape.curved()))
            .draw_region(&target, &DrawState::PLAIN, level_region(leaves, box_width))?;
        drop(b);
        let mut passes = 1;
        let mut start = leaves / 2;
        while start >= 1 {
            // The level below was drawn into these very textures.
            gpu.texture_barrier();
            self.reduce
                .bind()
                .texture("u_box_min", &box_min)
                .texture("u_box_max", &box_max)
                .int("u_box_width", box_width as i32)
                .draw_region(&target, &DrawState::PLAIN, level_region(start, box_width))?;
            passes += 1;
            start /= 2;
        }
        drop(target);
        Ok((box_min, box_max, box_width, leaves, passes))
    }
}
