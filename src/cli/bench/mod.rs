//! `photonmap bench`: benchmarks and the stress suite, commands rather than
//! tests, each with `--json` so anyone can rerun them; and beside them the
//! two commands that measure against references, `reference` (SPPM
//! reference images) and `tables` (the paper's tables and figures). What
//! they share: the output options (`output`) and the scene a method
//! benchmark renders with its reference (`scene`).

pub mod accuracy;
pub mod build;
pub mod differentials;
pub mod estimate;
pub mod igi;
pub mod mask;
pub mod meshes;
pub mod mitsuba;
pub mod output;
pub mod plot;
pub mod reference;
pub mod scene;
pub mod stress;
pub mod tables;
pub mod throughput;

use anyhow::Result;
use clap::Subcommand;

use photonmap::gpu::Platform;

/// `bench`'s line in `photonmap --help`.
pub const ABOUT: &str = "Benchmarks with results to commit: stress, accuracy against a reference, \
    meshes, IGI, differentials, against Mitsuba 3, the computation mask, builds, the \
    estimate and each stage's throughput (`bench <name> --help`)";

#[derive(Subcommand)]
pub enum BenchCommand {
    /// The stress suite: scale and place, sizes, crowding, grids, search edges,
    /// difficult paths, the furnace; one JSON object per case with --json.
    Stress(stress::StressArgs),
    /// Run time against error around a scene's defaults (photons, k, maximum
    /// radius, shadow rays, build, tiling, samples) and SPPM, against its SPPM
    /// reference; CSV, JSON, SVG and PNG plots of the Pareto front.
    Accuracy(accuracy::AccuracyArgs),
    /// The BVH at scale: a ball on a floor, analytic and as meshes of growing
    /// size; BVH build, eye/shadow/photon rays per second, render times.
    Meshes(meshes::MeshesArgs),
    /// Instant global illumination with Marques and Santos's accelerations
    /// one at a time, and their remedies: time by component (their figures 4
    /// and 5) and error against the SPPM reference.
    Igi(igi::IgiBenchArgs),
    /// Photon differentials against the kNN-grid at the same photons: time
    /// and error, the BVH's leaf size (their Table 1), and k_PM ~ k_PD.
    Differentials(differentials::DifferentialsBenchArgs),
    /// photonmap at a scene's defaults against Mitsuba 3 (path and light
    /// tracing) at the same wall time, both against the SPPM reference; runs
    /// Mitsuba through --python (not a dependency).
    Mitsuba(mitsuba::MitsubaBenchArgs),
    /// Whether the stencil test skips fragment work on this driver (the
    /// computation mask): an expensive pass with 0%, 50% and 90% of pixels masked.
    Mask(mask::MaskArgs),
    /// Photon-map builds for n = 2^min .. 2^max synthetic photons: bitonic passes,
    /// time per pass against a copy pass, binary search, stencil routing with and
    /// without read-back.
    Build(build::BuildArgs),
    /// Where the kNN-grid radiance estimate's time goes (steps, photons
    /// examined, cells opened, passes, lane use) for each variant of the
    /// search, each checked to give the paper search's image bit for bit.
    Estimate(estimate::EstimateBenchArgs),
    /// Each stage's rate (eye paths, photon paths, photons built, gather
    /// queries per second), its floor (a copy pass over as many texels) and
    /// Mitsuba 3's direct-light and light-tracing rates on the same cores.
    Throughput(throughput::ThroughputArgs),
}

pub fn run(command: BenchCommand, platform: Platform) -> Result<()> {
    match command {
        BenchCommand::Stress(a) => stress::run(&a, platform),
        BenchCommand::Accuracy(a) => accuracy::run_bench(&a, platform),
        BenchCommand::Mask(a) => mask::run(&a, platform),
        BenchCommand::Meshes(a) => meshes::run(&a, platform),
        BenchCommand::Igi(a) => igi::run(&a, platform),
        BenchCommand::Differentials(a) => differentials::run(&a, platform),
        BenchCommand::Mitsuba(a) => mitsuba::run(&a, platform),
        BenchCommand::Estimate(a) => estimate::run(&a, platform),
        BenchCommand::Build(a) => build::run(&a, platform),
        BenchCommand::Throughput(a) => throughput::run(&a, platform),
    }
}
