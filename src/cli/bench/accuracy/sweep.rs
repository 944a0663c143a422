//! `bench accuracy`'s sweep: one parameter at a time around the scene's
//! defaults, and every other method at its defaults and a few variants.

use photonmap::photon::differentials::FootprintShape;
use photonmap::photon::{BuildMethod, GridKind};
use photonmap::render::radiance_estimate::LeakTest;
use photonmap::render::{CausticPaths, DifferentialsOptions, IgiOptions, Kernel, RadiosityOptions};
use photonmap::scene::{Light, Scene};

use super::report::{AccuracyRun, RunMethod};

/// SPPM at `iterations`.
fn sppm(iterations: u32) -> RunMethod {
    RunMethod::Sppm {
        sppm_iterations: iterations,
    }
}

#[derive(Clone)]
pub(super) struct Config {
    pub(super) run: AccuracyRun,
}

impl Config {
    fn paper(scene: &Scene) -> Self {
        Self {
            run: AccuracyRun {
                label: "scene defaults".into(),
                method: RunMethod::Paper,
                photons_stored: scene.photon_map.photons_stored,
                k: scene.photon_map.k,
                max_radius: scene.photon_map.max_radius,
                leak: LeakTest::Visibility,
                shadow_rays: scene.render.shadow_rays,
                build: BuildMethod::Bitonic,
                tile: 16,
                spp: 1,
                adaptive: false,
                grid: GridKind::Uniform,
                seconds: 0.0,
                rmse: 0.0,
                bias_rmse: 0.0,
                noise_rmse: 0.0,
                rel_mse: 0.0,
                ssim: 0.0,
                rel_rmse: 0.0,
                energy: 0.0,
                regions: Vec::new(),
                on_pareto_front: false,
            },
        }
    }

    fn with(&self, label: String, f: impl FnOnce(&mut AccuracyRun)) -> Self {
        let mut c = self.clone();
        c.run.label = label;
        f(&mut c.run);
        c
    }

    /// This run by another method, at `spp` eye samples.
    fn by(&self, label: &str, method: RunMethod, spp: u32) -> Self {
        self.with(label.into(), |r| {
            r.method = method;
            r.spp = spp;
        })
    }

    /// This run by the method `method` makes of its default options
    /// changed by `tweak`, at `spp` eye samples.
    fn by_tweaked<O: Default>(
        &self,
        label: &str,
        method: fn(O) -> RunMethod,
        spp: u32,
        tweak: impl FnOnce(&mut O),
    ) -> Self {
        let mut o = O::default();
        tweak(&mut o);
        self.by(label, method(o), spp)
    }
}

/// The sweep: one parameter at a time around the scene's defaults, the leak
/// tests, and SPPM at several iteration counts.
pub(super) fn sweep(scene: &Scene, quick: bool) -> Vec<Config> {
    let base = Config::paper(scene);
    let mut out = vec![base.clone()];
    let factors: &[f32] = if quick {
        &[0.5, 2.0]
    } else {
        &[0.25, 0.5, 2.0, 4.0]
    };
    for &f in factors {
        out.push(base.with(format!("photons x{f}"), |r| {
            r.photons_stored = ((r.photons_stored as f32 * f) as u32).max(16)
        }));
        out.push(base.with(format!("k x{f}"), |r| {
            r.k = ((r.k as f32 * f) as u32).max(1)
        }));
        out.push(base.with(format!("max radius x{f}"), |r| r.max_radius *= f));
    }
    for leak in [LeakTest::None, LeakTest::Disc, LeakTest::DiscAndVisibility] {
        out.push(
            base.with(format!("leak test {leak:?}").to_lowercase(), |r| {
                r.leak = leak
            }),
        );
    }
    if scene
        .lights
        .iter()
        .any(|l| matches!(l, Light::Area { .. } | Light::Triangles { .. }))
    {
        for s in if quick { vec![1] } else { vec![1, 16] } {
            if s != base.run.shadow_rays {
                out.push(base.with(format!("{s} shadow rays"), |r| r.shadow_rays = s));
            }
        }
    }
    if !quick {
        out.push(base.with("stencil routing".into(), |r| r.build = BuildMethod::Stencil));
        out.push(base.with("full screen".into(), |r| r.tile = 0));
    }
    for spp in if quick { vec![4] } else { vec![4, 16] } {
        out.push(base.with(format!("{spp} spp"), |r| r.spp = spp));
    }
    // Final gather needs diffuse interreflection, which caustics-only scenes leave out.
    if !scene.photon_map.caustics_only {
        // 16 rays already take 15 times the scene defaults in CORNELL BOX.
        for rays in if quick { vec![4] } else { vec![4, 16] } {
            let label = format!("final gather {rays} rays");
            out.push(base.by(&label, RunMethod::FinalGather { gather_rays: rays }, 1));
        }
        let label = "final gather 16 rays, adaptive";
        let mut adaptive = base.by(label, RunMethod::FinalGather { gather_rays: 16 }, 1);
        adaptive.run.adaptive = true;
        out.push(adaptive);
    }
    out.push(base.with("adaptive".into(), |r| r.adaptive = true));
    out.push(base.with("hash grid".into(), |r| r.grid = GridKind::Hash));
    out.push(base.with("4 spp, adaptive".into(), |r| {
        r.spp = 4;
        r.adaptive = true;
    }));
    for it in if quick {
        vec![4, 16]
    } else {
        vec![4, 16, 64, 256]
    } {
        let label = format!("SPPM {it} iterations");
        out.push(base.by(&label, sppm(it), 1));
    }
    out.extend(igi_rows(&base, quick));
    out.extend(differentials_rows(&base, quick));
    // Radiosity solves diffuse interreflection, which caustics-only scenes leave out.
    if !scene.photon_map.caustics_only {
        out.extend(radiosity_rows(&base, quick));
    }
    // Adaptive SPPM (a pilot of an eighth of the iterations, then the
    // gather only where the plan computes), beside the full runs above.
    for it in if quick { vec![16] } else { vec![16, 64] } {
        let label = format!("SPPM {it} iterations, adaptive");
        let mut adaptive = base.by(&label, sppm(it), 1);
        adaptive.run.adaptive = true;
        out.push(adaptive);
    }
    out
}

/// Instant global illumination: the default (interleaved), the paper's
/// canonical 64 paths and 512 paths (about the default's time) without
/// interleaving, 512 paths interleaved, 8192 paths at a 2 x 2 interleave,
/// the default and the paper's without their bias
/// compensation, its caustic map from lights only, at the scene's k, at
/// k = 32 and on the scene's grid, each of Marques and Santos's other
/// accelerations, all three together, the remedy they suggest for the
/// combination's artefacts (a 2 x 2 interleave), and 4 spp (at 1 spp every
/// method's error is mostly aliasing against the antialiased reference).
fn igi_rows(base: &Config, quick: bool) -> Vec<Config> {
    let mut out = Vec::new();
    let igi =
        |label: &str, f: &dyn Fn(&mut IgiOptions)| base.by_tweaked(label, RunMethod::Igi, 1, f);
    let all_three = |o: &mut IgiOptions| {
        o.imperfect_visibility = true;
        o.interleave = 3;
        o.downsample = 4;
    };
    let unleaved = |o: &mut IgiOptions, paths: u32| {
        o.vpl_paths = paths;
        o.interleave = 1;
    };
    out.push(igi("IGI", &|_| {}));
    out.push(igi("IGI, all three accelerations", &all_three));
    if !quick {
        out.push(igi("IGI 64 paths, no interleave", &|o| unleaved(o, 64)));
        out.push(igi("IGI 512 paths, no interleave", &|o| unleaved(o, 512)));
        out.push(igi("IGI 512 paths", &|o| o.vpl_paths = 512));
        // Many VPLs at several times the default's time: what the default's
        // noise hides.
        out.push(igi("IGI 8192 paths, interleave 2", &|o| {
            o.vpl_paths = 8192;
            o.interleave = 2;
        }));
        out.push(igi("IGI, no bias compensation", &|o| {
            o.bias_compensation = 0
        }));
        out.push(igi(
            "IGI 64 paths, no interleave, no bias compensation",
            &|o| {
                unleaved(o, 64);
                o.bias_compensation = 0;
            },
        ));
        out.push(igi("IGI, caustics from lights", &|o| {
            o.caustic_paths = CausticPaths::FromLights
        }));
        let scene_k = base.run.k;
        out.push(igi("IGI, caustic map at the scene's k", &|o| {
            o.caustic_k = Some(scene_k)
        }));
        out.push(igi("IGI, caustic map at k = 32", &|o| {
            o.caustic_k = Some(32)
        }));
        out.push(igi("IGI, caustic map on the scene's grid", &|o| {
            o.caustic_scene_grid = true
        }));
        out.push(igi("IGI, imperfect visibility", &|o| {
            o.imperfect_visibility = true
        }));
        out.push(igi("IGI, downsample 4", &|o| o.downsample = 4));
        out.push(igi("IGI, all three, interleave 2", &|o| {
            all_three(o);
            o.interleave = 2;
        }));
        // At 1 spp every method's error is mostly aliasing against the
        // antialiased reference; 4 spp compares the estimators.
        for (label, f) in [
            (
                "IGI, 4 spp",
                &(|_: &mut IgiOptions| {}) as &dyn Fn(&mut IgiOptions),
            ),
            ("IGI, all three, 4 spp", &all_three),
        ] {
            let mut c = igi(label, f);
            c.run.spp = 4;
            out.push(c);
        }
    }
    out
}

/// Photon differentials: automatic smoothing (k_PD = the scene's k), no
/// coverage probes, the paper's ellipsoid footprints, the paper's one map
/// (no caustic footprint map), the paper scenes' 8 bounces, four times the
/// photons, the Epanechnikov kernel, and 4 spp.
fn differentials_rows(base: &Config, quick: bool) -> Vec<Config> {
    let pd = |label: &str, spp: u32, f: &dyn Fn(&mut DifferentialsOptions)| {
        base.by_tweaked(label, RunMethod::Differentials, spp, f)
    };
    let mut out = vec![pd("differentials", 1, &|_| {})];
    if !quick {
        // The estimate is cheap: more photons at about the kNN-grid's time.
        let mut more = pd("differentials, photons x4", 1, &|_| {});
        more.run.photons_stored *= 4;
        out.push(more);
        out.push(pd("differentials, no coverage probes", 1, &|o| {
            o.coverage_samples = 0
        }));
        out.push(pd("differentials, ellipsoid footprints", 1, &|o| {
            o.footprint_shape = FootprintShape::Ellipsoid
        }));
        out.push(pd("differentials, one map", 1, &|o| {
            o.caustic_photons = Some(0)
        }));
        out.push(pd("differentials, 8 bounces", 1, &|o| o.max_bounces = 8));
        out.push(pd("differentials, Epanechnikov", 1, &|o| {
            o.kernel = Kernel::Epanechnikov
        }));
        out.push(pd("differentials, 4 spp", 4, &|_| {}));
    }
    out
}

/// Progressive radiosity: its defaults, its caustic map from lights only,
/// not shot on, at the scene's k, at k = 32 and on the scene's grid, the chapter's ~10,000 elements of
/// CORNELL BOX (32 x 32 a patch side), shooters of 2 x 2 elements, a finer
/// item buffer, final gather over the solution at 16, 64 and 256 rays a
/// pixel, and 4 spp.
fn radiosity_rows(base: &Config, quick: bool) -> Vec<Config> {
    let rad = |label: &str, spp: u32, f: &dyn Fn(&mut RadiosityOptions)| {
        base.by_tweaked(label, RunMethod::Radiosity, spp, f)
    };
    let mut out = vec![rad("radiosity", 1, &|_| {})];
    if !quick {
        out.push(rad("radiosity, caustics from lights", 1, &|o| {
            o.caustic_paths = CausticPaths::FromLights
        }));
        out.push(rad("radiosity, caustics not shot", 1, &|o| {
            o.shoot_caustics = false
        }));
        let scene_k = base.run.k;
        out.push(rad("radiosity, caustic map at the scene's k", 1, &|o| {
            o.caustic_k = Some(scene_k)
        }));
        out.push(rad("radiosity, caustic map at k = 32", 1, &|o| {
            o.caustic_k = Some(32)
        }));
        out.push(rad("radiosity, caustic map on the scene's grid", 1, &|o| {
            o.caustic_scene_grid = true
        }));
        out.push(rad("radiosity, 32 elements", 1, &|o| o.resolution = 32));
        out.push(rad("radiosity, substructure 8", 1, &|o| o.substructure = 8));
        out.push(rad("radiosity, item buffer 1024", 1, &|o| {
            o.item_buffer = 1024
        }));
        for rays in [16, 64, 256] {
            out.push(rad(&format!("radiosity, final gather {rays}"), 1, &|o| {
                o.gather_rays = rays
            }));
        }
        out.push(rad("radiosity, 4 spp", 4, &|_| {}));
    }
    out
}
