//! The `photonmap` command: parse, then hand each subcommand to its module in cli/.

mod cli;
use clap::{Parser, Subcommand};
use photonmap::gpu::Platform;

#[derive(Parser)]
#[command(
    name = "photonmap",
    version,
    about = "Headless GPU photon mapping after Purcell et al. 2003, on OpenGL fragment passes"
)]
struct Cli {
    /// Headless GL platform: auto (a GPU's EGL device, else EGL surfaceless, else OSMesa).
    #[arg(long, value_enum, default_value_t = Platform::Auto, global = true)]
    platform: Platform,
    /// llvmpipe's rendering threads (LP_NUM_THREADS; default: one per core;
    /// ignored, with a note, on a GPU).
    #[arg(long, global = true, value_parser = cli::args::in_range(1, 1024))]
    threads: Option<u32>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    Render(Box<cli::render::RenderArgs>),
    Photons(cli::photons::PhotonsArgs),
    Compare(cli::compare::CompareArgs),
    Merge(cli::merge::MergeArgs),
    Convert(cli::convert::ConvertArgs),
    ConvertScene(cli::convert_scene::ConvertSceneArgs),
    Reference(cli::reference::ReferenceArgs),
    Regress(cli::regress::RegressArgs),
    Tables(cli::tables::TablesArgs),
    #[command(subcommand, about = cli::bench::ABOUT)]
    Bench(cli::bench::BenchCommand),
    Info(cli::info::InfoArgs),
    Scenes(cli::scenes::ScenesArgs),
}

fn main() -> std::process::ExitCode {
    let cli = Cli::parse();
    cli::prepare(cli.threads);
    let result = match cli.command {
        Command::Render(a) => cli::render::run(&a, cli.platform),
        Command::Photons(a) => cli::photons::run(&a, cli.platform),
        Command::Compare(a) => cli::compare::run(&a),
        Command::Merge(a) => cli::merge::run(&a),
        Command::Convert(a) => cli::convert::run(&a),
        Command::ConvertScene(a) => cli::convert_scene::run(&a),
        Command::Reference(a) => cli::reference::run(&a, cli.platform),
        Command::Regress(a) => cli::regress::run(&a, cli.platform),
        Command::Tables(a) => cli::tables::run(&a, cli.platform),
        Command::Bench(b) => cli::bench::run(b, cli.platform),
        Command::Info(a) => cli::info::run(&a, cli.platform),
        Command::Scenes(a) => cli::scenes::run(&a),
    };
    result.map_or_else(cli::fail, |()| std::process::ExitCode::SUCCESS)
}
