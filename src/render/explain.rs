//! `--explain`: every pass a render ran or skipped, and why, written after the
//! render from its plan and the stages' reports.

use crate::photon::differentials::FootprintShape;
use crate::scene::Scene;

use super::adaptive;
use super::options::{Method, RenderOptions};
use super::output::RenderOutput;
use super::photon_options::CausticPaths;
use super::radiance_estimate::EstimateMode;

/// One line of `--explain`: a stage's passes, run or skipped, and why.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ExplainLine {
    pub stage: String,
    pub passes: usize,
    pub ran: bool,
    pub why: String,
}

fn line(stage: &str, passes: usize, ran: bool, why: String) -> ExplainLine {
    ExplainLine {
        stage: stage.into(),
        passes,
        ran,
        why,
    }
}

impl std::fmt::Display for EstimateMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            EstimateMode::Tiled { tile } => {
                write!(f, "{tile} x {tile} tiles stopped by occlusion query")
            }
            EstimateMode::FullScreen => write!(f, "full screen"),
            EstimateMode::Masked { every } => write!(
                f,
                "full screen behind a stencil mask refreshed every {every} passes"
            ),
        }
    }
}

fn xyz(v: glam::Vec3) -> String {
    format!("({}, {}, {})", v.x, v.y, v.z)
}

impl RenderOutput {
    /// The passes this render ran and skipped, with why.
    pub fn explain(&self, scene: &Scene, options: &RenderOptions) -> Vec<ExplainLine> {
        let mut lines = self.ray_tracing_lines(scene);
        if let Some(b) = options.pixel_bounds {
            let how = match self.method.crop_margin() {
                Some(0) => "the eye passes draw only these (GL scissor); photons are the frame's".to_string(),
                Some(m) => format!("the eye passes draw these and {m} pixels around them (GL scissor), which this method's pixels read; photons are the frame's"),
                None => "the eye passes draw the whole frame and the crop is cut from it (this method's pixels read one another's)".to_string(),
            };
            lines.push(line(
                "crop",
                0,
                true,
                format!(
                    "pixels {}..{} x {}..{} of the {} x {} frame: {how}",
                    b.x0, b.x1, b.y0, b.y1, options.width, options.height
                ),
            ));
        }
        // Final gather's maps are made from two views of the scene.
        let method = &options.method;
        let views = method
            .photon_map()
            .filter(|o| o.final_gather.is_some())
            .and_then(|_| super::final_gather::map_scenes(scene).ok());
        match (method.estimate(), self.photons()) {
            (Some(estimate), Some(p)) => {
                let caustic = views.as_ref().map_or(scene, |v| &v.0);
                lines.extend(self.photon_lines(caustic, p));
                let k = method.first_hit_k(scene.photon_map.k);
                let r = scene.photon_map.max_radius;
                let pixels = options.width as u64 * options.height as u64;
                let many = self.estimates().len() > 1;
                for (i, s) in self.estimates().iter().enumerate() {
                    lines.push(line(
                        "radiance estimate",
                        s.passes as usize,
                        true,
                        format!(
                            "kNN-grid, k = {k}, max radius {r}, {} steps per pixel per pass, {}; {} of {pixels} pixels have a diffuse hit, {} tile draws{}",
                            estimate.budget,
                            estimate.mode,
                            s.query_pixels,
                            s.tile_draws,
                            if many { format!(" (run {} of {})", i + 1, self.estimates().len()) } else { String::new() }
                        ),
                    ));
                }
            }
            (_, None) if matches!(method, Method::Differentials(_)) => {
                lines.push(line(
                    "photons, kNN map, kNN estimate",
                    0,
                    false,
                    "skipped: photon differentials give every photon a footprint and sum the footprints at a hit (below)".into(),
                ));
            }
            (_, None) if matches!(method, Method::Radiosity(_)) => lines.push(line(
                "caustic map, estimate",
                0,
                false,
                "skipped: radiosity takes caustics from a caustic photon map, and the scene has no mirror or glass to make them".into(),
            )),
            (_, None) if matches!(method, Method::Igi(_)) => lines.push(line(
                "caustic map, estimate",
                0,
                false,
                "skipped: IGI takes caustics from a caustic photon map, and the scene has no mirror or glass to make them".into(),
            )),
            (_, None) if method.photon_map().is_some_and(|o| o.final_gather.is_some()) => lines.push(line(
                "caustic map, estimate",
                0,
                false,
                "skipped: final gather's caustic map needs a mirror or glass, and the scene has none".into(),
            )),
            _ => lines.push(line(
                "photons, map, estimate",
                0,
                false,
                "skipped: direct light only".into(),
            )),
        }
        let global = views.as_ref().map_or(scene, |v| &v.1);
        lines.extend(self.section_4_5_lines(global, options));
        lines
    }

    /// Final gather and adaptive sampling (section 4.5), when chosen.
    fn section_4_5_lines(&self, scene: &Scene, options: &RenderOptions) -> Vec<ExplainLine> {
        let mut lines = Vec::new();
        let photon_map = options.method.photon_map();
        let final_gather = photon_map.and_then(|o| o.final_gather.as_ref());
        if let (Some(fg), Some(p)) = (final_gather, self.gather_photons()) {
            lines.extend(self.photon_lines(scene, p));
            let passes: u32 = self.gathers().iter().map(|g| g.estimate_passes).sum();
            let queries: u64 = self.gathers().iter().map(|g| g.queries).sum();
            lines.push(line(
                "final gather",
                passes as usize,
                true,
                format!(
                    "the photon map above the gather is the caustic map (specular paths only), visualised at the first hits; the one here is the global map (every diffuse hit), estimated only where {} gather rays a pixel land (k = {}, leak test {:?}): {queries} gather hits in all",
                    fg.rays, fg.k, fg.leak
                ),
            ));
        }
        match (&options.method, self.vpls()) {
            (Method::Igi(_), Some(v)) if v.skipped => lines.push(line(
                "IGI VPLs, gather",
                0,
                false,
                "skipped: every diffuse surface lies in one plane, whose points see each other only edge-on, so a VPL could light nothing; the image is direct light and the caustic map".into(),
            )),
            (Method::Igi(o), Some(v)) => {
                let o = &o.method;
                let passes: u32 = self.igi().iter().map(|s| s.passes).sum();
                lines.push(line(
                    "IGI VPLs",
                    0,
                    true,
                    format!(
                        "{} VPLs at the diffuse hits of {} Halton light paths (traced by the photon passes, compacted by the HistoPyramid); VPLs reach the first hit only straight from a diffuse surface, so {}",
                        v.vpls, v.paths, caustic_map(o.caustic_paths)
                    ),
                ));
                lines.push(line(
                    "IGI gather",
                    passes as usize,
                    true,
                    format!(
                        "every shading point sums {} with the geometry term bounded at {} and a shadow ray each ({}), {} VPLs a pass; {}",
                        if o.interleave > 1 {
                            format!("1 of {} VPL subsets (interleaved sampling, merged by the discontinuity buffer)", o.interleave * o.interleave)
                        } else {
                            "every VPL".to_string()
                        },
                        v.min_distance,
                        if o.imperfect_visibility { "against primitive bounding boxes: imperfect visibility" } else { "exact visibility" },
                        crate::layout::VPL_BATCH,
                        if o.downsample > 1 {
                            format!("shading points at one pixel per {0} x {0} block, joint-bilateral upsampled", o.downsample)
                        } else {
                            "at every pixel".to_string()
                        }
                    ),
                ));
            }
            _ => {}
        }
        if let (Method::Igi(o), Some(run)) = (&options.method, self.igi_run()) {
            let m = o.method.min_distance_for(scene);
            lines.push(match &run.compensation {
                None if run.report.skipped => line(
                    "IGI bias compensation",
                    0,
                    false,
                    "skipped: its gather rays would meet no diffuse surface (every one lies in one plane)".into(),
                ),
                Some(c) => {
                    let passes: u32 = c.stats.iter().map(|s| s.batches + s.estimate_passes).sum();
                    let hits: u64 = c.stats.iter().map(|s| s.queries).sum();
                    line(
                        "IGI bias compensation",
                        passes as usize,
                        true,
                        format!(
                            "the bound leaves out 1 - f(d) of each connection nearer than {:.4}; {} gather rays a pixel add it back from the diffuse surface each meets straight from the first hit ({hits} met one that near), estimated there by a global map of {} photons at k = {}",
                            1.2 * m,
                            c.rays(),
                            c.photons_stored,
                            c.k()
                        ),
                    )
                }
                None => line(
                    "IGI bias compensation",
                    0,
                    false,
                    if m > 0.0 {
                        format!("off (--bias-compensation 0): the light between diffuse surfaces nearer than {:.4} is darkened by the bound, and below {:.4} missing", 1.2 * m, 0.8 * m)
                    } else {
                        "not needed: the geometry term is unbounded".to_string()
                    },
                ),
            });
        }
        lines.extend(self.method_lines(&options.method));
        if let Some(a) = photon_map.and_then(|o| o.adaptive.as_ref()) {
            let computed: u64 = self.adaptive().iter().map(|s| s.computed).sum();
            let all: u64 = self.adaptive().iter().map(|s| s.pixels_with_hits).sum();
            lines.push(line(
                "adaptive sampling",
                3 * adaptive::STRIDES.len() * self.adaptive().len(),
                true,
                format!(
                    "global light computed at {computed} of {all} pixels with a diffuse hit, interpolated at the rest (strides 8, 4, 2, 1, each a plan, pack and store pass; threshold {}); each level's estimate above runs on its packed pixels",
                    a.threshold
                ),
            ));
        }
        lines
    }

    /// Radiosity's and photon differentials' lines, when chosen.
    fn method_lines(&self, method: &Method) -> Vec<ExplainLine> {
        let mut lines = Vec::new();
        if let (Method::Radiosity(o), Some(r)) = (method, self.radiosity()) {
            let o = &o.method;
            lines.push(line(
                "radiosity",
                0,
                true,
                format!(
                    "{} patches (each side of a diffuse primitive, and each emitter's emitting side), {} elements ({} x {} a patch, in an atlas); {} shots of {} x {} sub-element shooters, each with a hemispherical item buffer of {} texels a side, the widest {:.3} across: a receiver nearer a shooter than its width, as a face is where it meets the floor, gets the shooter's mean radiosity, not the light beside it (each doubling of --substructure halves the width); {}: {:.3}% of the emitted power unshot; shots stop at mirrors and glass, so {}; {}; {}",
                    r.patches,
                    r.elements,
                    r.element_resolution,
                    r.element_resolution,
                    r.shots,
                    o.substructure,
                    o.substructure,
                    o.item_buffer,
                    r.largest_shooter,
                    if r.converged { "converged" } else { "stopped at --max-shots" },
                    100.0 * r.unshot_fraction,
                    caustic_map(o.caustic_paths),
                    caustic_shots(r.caustic_shot_fraction, o.shoot_caustics),
                    solution_read(o.gather_rays)
                ),
            ));
        }
        if let (Method::Differentials(o), Some(d)) = (method, self.differentials()) {
            let o = &o.method;
            let passes: u32 = self.footprint_estimates().iter().map(|s| s.passes).sum();
            let k: f64 = self
                .footprint_estimates()
                .first()
                .map_or(0.0, |s| s.mean_footprints);
            lines.push(line(
                "photon differentials",
                d.frames_traced as usize,
                true,
                format!(
                    "{} photons of up to {} bounces traced to the scene's stored count, each record given two positional and two directional differentials (one pass a frame); {} footprints ({} after a diffuse bounce: {}; {}), semi-axes at most {}; {}; {}",
                    d.trace.photons_used,
                    o.max_bounces,
                    d.footprints,
                    d.diffuse_footprints,
                    match (d.diffuse_footprints, d.pilot_mean_diffuse_footprints) {
                        (0, _) => "s touches none".to_string(),
                        (_, Some(m)) => format!("s = {:.3}, chosen by a pilot map at s = 1 ({m:.4} diffuse footprints at a hit) to aim k_PD at the scene's k", d.smoothing),
                        (_, None) => format!("s = {:.3} as given", d.smoothing),
                    },
                    match &d.caustic_map {
                        Some(_) => format!("{} caustic, left out: the caustic footprint map below carries that light", d.dropped_caustic_footprints),
                        None => format!("{} caustic: {}", d.footprints - d.diffuse_footprints, d.caustic_smoothing),
                    },
                    d.max_radius,
                    match d.coverage_samples {
                        0 => "each footprint's whole ellipse counts, so the part overhanging an edge, a corner or an occluder is lost".to_string(),
                        n => format!("each footprint's area is its share on its own surface, found by {n} probes, so one overhanging an edge, a corner or an occluder keeps its power"),
                    },
                    match d.footprint_shape {
                        FootprintShape::Curved => "a footprint holds the points whose projection lies in its ellipse and which lie as near its plane as a surface curving to their normal would, so a curved surface stays in it",
                        FootprintShape::Ellipsoid => "a footprint is the paper's thin ellipsoid, so on a curved surface the points near its rim fall outside it and their light is lost",
                    }
                ),
            ));
            lines.push(line(
                "footprint BVH",
                0,
                true,
                format!(
                    "30-bit Morton codes sorted by the bitonic passes; {} leaves of {} footprints ({}: total footprint area {:.4} over surface area {:.4}), boxes by one reduction pass a level",
                    d.leaves,
                    d.leaf_size,
                    if o.leaf_size.is_some() { format!("given; auto would be {}", d.auto_leaf_size) } else { "auto".into() },
                    d.total_footprint_area,
                    d.surface_area
                ),
            ));
            lines.push(line(
                "footprint estimate",
                passes as usize,
                true,
                format!(
                    "a stackless walk of the BVH at every first hit, at most {} nodes a pass, ended by occlusion query; {:?} kernel; {k:.1} footprints hold a hit on average (k_PD)",
                    crate::layout::FOOTPRINT_BUDGET,
                    o.kernel
                ),
            ));
            lines.push(caustic_footprints_line(
                d.caustic_map.as_ref(),
                d.caustic_smoothing,
            ));
        }
        lines
    }

    fn ray_tracing_lines(&self, scene: &Scene) -> Vec<ExplainLine> {
        let p = &self.plan;
        let views = (self.estimates().len() as u32 / p.spp).max(1);
        let runs = (p.spp * views) as usize;
        if p.fused {
            return vec![line(
                "eye paths (fused)",
                runs,
                true,
                format!(
                    "a pixel's whole eye path in one pass a sample: the eye ray, {}, and {} at its first diffuse hit (`--faithful`: a pass per bounce)",
                    if p.specular {
                        format!(
                            "the chain of {} to specular depth {}",
                            surfaces_followed(scene),
                            scene.render.max_specular_depth
                        )
                    } else {
                        "no specular chain (the scene has no mirror or glass)".into()
                    },
                    if p.has_area {
                        format!("{} shadow samples per area light", p.shadow_rays)
                    } else {
                        "one shadow ray per point light".into()
                    }
                ),
            )];
        }
        vec![
            line(
                "eye rays",
                runs,
                true,
                if p.spp == 1 {
                    "one ray per pixel centre".into()
                } else {
                    format!(
                        "{} stratified, jittered samples per pixel, one pass each",
                        p.spp
                    )
                },
            ),
            line(
                "intersect",
                p.depths as usize * runs,
                true,
                if p.specular {
                    format!(
                        "one per specular depth 0..={} per sample",
                        scene.render.max_specular_depth
                    )
                } else {
                    "depth 0 only: the scene has no mirror or glass".into()
                },
            ),
            line(
                "shadow rays",
                (p.depths * p.direct_passes) as usize * runs,
                true,
                if p.has_area {
                    format!(
                        "{} samples per area light in batches of {} at each depth",
                        p.shadow_rays, p.shadow_batch
                    )
                } else {
                    "one ray per point light at each depth".into()
                },
            ),
            line(
                "specular",
                (p.depths - 1) as usize * runs,
                p.specular,
                if p.specular {
                    "reflect or refract at mirror and glass hits".into()
                } else {
                    "skipped: no specular surface".into()
                },
            ),
        ]
    }

    fn photon_lines(&self, scene: &Scene, p: &super::PhotonReport) -> Vec<ExplainLine> {
        let t = &p.trace;
        let bounces = scene.photon_map.max_bounces + 1;
        let mut lines = vec![
            line(
                "trace photons",
                p.frames_traced as usize,
                true,
                format!(
                    "emission + {} bounces{}; {} photons traced ({} attempts), the first {} kept: {} stored",
                    p.frames_traced - 1,
                    if p.frames_traced < bounces {
                        format!(" (stopped: no photon alive; {} more skipped)", bounces - p.frames_traced)
                    } else {
                        String::new()
                    },
                    t.emitted,
                    t.attempts.len(),
                    t.photons_used,
                    t.stored
                ),
            ),
            line(
                "projection maps",
                0,
                t.projection.is_some(),
                match (&t.projection, scene.photon_map.caustics_only) {
                    (Some(m), _) => format!(
                        "caustics only: photons leave through {} of {} emission cells ({}x{} a light) that can reach a mirror or glass shape, {:.2}% of the lights' power",
                        m.kept_cells, m.cells, m.resolution, m.resolution, 100.0 * m.kept_power_fraction
                    ),
                    (None, true) => "skipped: switched off (--no-projection-map); photons leave in every direction and only caustic paths are stored".into(),
                    (None, false) => "skipped: the map stores indirect diffuse light too, which any emitted direction may carry (caustics_only = true aims photons at specular shapes)".into(),
                },
            ),
            line(
                "grid bounds",
                0,
                true,
                format!(
                    "{} x {} x {} cells over {}..{}, {}",
                    p.grid.resolution[0],
                    p.grid.resolution[1],
                    p.grid.resolution[2],
                    xyz(p.grid.min),
                    xyz(p.grid.max),
                    if p.grid_fitted {
                        "fitted to the stored photons"
                    } else {
                        "as the scene fixes them"
                    }
                ),
            ),
        ];
        let build = p.config.build.to_string();
        for st in &p.build_stages.stages {
            lines.push(line(
                &format!("build map: {}", st.name),
                st.passes,
                true,
                build.clone(),
            ));
        }
        lines
    }
}

/// Whether radiosity's shots carry the caustic map's light on (L S+ D D+).
fn caustic_shots(fraction: Option<f64>, shoot_caustics: bool) -> String {
    match fraction {
        Some(f) => format!(
            "the caustic map's photons were deposited into the elements first ({:.2}% of the emitted power), so that light bounces on from the diffuse surface it reached (L S+ D D+)",
            100.0 * f
        ),
        None if shoot_caustics => "no caustic map's light was there to deposit into the elements (L S+ D D+ has none)".into(),
        None => "light that leaves a mirror or glass onto a diffuse surface never bounces on from there (L S+ D D+ is missing; --shoot-caustics true carries it)".into(),
    }
}

/// Where the image reads the radiosity solution.
fn solution_read(gather_rays: u32) -> String {
    match gather_rays {
        0 => "the image reads the solution at each pixel's own element, whose mean misses how the light changes across it near a contact or a shadow's edge (--gather-rays N reads it where rays from the pixel land)".to_string(),
        n => format!("final gather: {n} rays a pixel read the solution where they land, with the direct light there from a shadow ray a light, so an element's error enters a pixel only as the share of its hemisphere that element covers"),
    }
}

/// The caustic footprint map of photon differentials, or why there is none.
fn caustic_footprints_line(
    map: Option<&super::differentials::CausticFootprintsReport>,
    caustic_smoothing: f32,
) -> ExplainLine {
    match map {
        Some(c) => line(
            "caustic footprints",
            c.estimate_passes as usize,
            true,
            format!(
                "{} photons emitted only towards mirrors and glass ({}), {} stored at their first diffuse hit after specular bounces only (L S+ D), each a footprint at {caustic_smoothing} (no diffuse footprint among them); their own BVH of {} leaves of {} and walk at every first hit, {:.1} footprints holding a hit on average",
                c.trace.emitted,
                c.trace.projection.as_ref().map_or("no projection map".to_string(), |p| format!("projection maps: {} of {} cells kept", p.kept_cells, p.cells)),
                c.footprints,
                c.leaves,
                c.leaf_size,
                c.mean_footprints
            ),
        ),
        None => line(
            "caustic footprints",
            0,
            false,
            "skipped: the scene's own photons carry the caustics (the scene stores caustics only, has no mirror or glass, or --caustic-photons 0)".into(),
        ),
    }
}

/// What IGI's or radiosity's caustic map carries, and what it leaves out.
fn caustic_map(paths: CausticPaths) -> &'static str {
    match paths {
        CausticPaths::All => "the photon map above, if any, is a caustic map of every path onto a diffuse surface from a mirror or glass (L (S|D)* S D), including light a diffuse surface sends through them (L D+ S+ D)",
        CausticPaths::FromLights => "the photon map above, if any, is Jensen's caustic map, light straight from an emitter through mirrors and glass (L S+ D); light from a diffuse surface through a mirror or glass onto another (L D+ S+ D) is missing (--caustic-paths all carries it)",
    }
}

/// What the fused eye path does at each kind of non-diffuse surface the
/// scene holds (common/bsdf.glsl's lobes).
fn surfaces_followed(scene: &Scene) -> String {
    use crate::scene::Material;
    let has = |f: &dyn Fn(&Material) -> bool| {
        scene.shapes.iter().any(|s| f(&scene.materials[s.material]))
    };
    let mut kinds = vec![];
    if has(&|m| matches!(m, Material::Mirror { .. })) {
        kinds.push("mirrors (reflected)");
    }
    if has(&|m| matches!(m, Material::Glass { .. })) {
        kinds.push("glass (reflected or refracted by Fresnel)");
    }
    if has(&|m| matches!(m, Material::Conductor { .. }) && !m.is_glossy()) {
        kinds.push("smooth metals (reflected, times their Fresnel)");
    }
    if has(&|m| m.is_glossy()) {
        kinds.push(
            "rough metals (shadow rays weighted by the BSDF, then a sample of the lobe, \
             combined by the balance heuristic)",
        );
    }
    kinds.join(", ")
}
