//! `photonmap bench stress`: the stress suite (src/bench/stress.rs), a line
//! or a JSON object per case, then their sum; fails if any case failed.

use anyhow::{bail, Result};
use clap::Args;

use photonmap::bench::stress::Outcome;
use photonmap::gpu::Platform;

use super::output::BenchOutput;

#[derive(Args)]
pub struct StressArgs {
    /// Only the cases that take seconds.
    #[arg(long)]
    pub quick: bool,
    #[command(flatten)]
    pub output: BenchOutput,
}

pub fn run(a: &StressArgs, platform: Platform) -> Result<()> {
    let gpu = crate::cli::gpu(platform)?;
    let json = a.output.json;
    let cases = photonmap::bench::stress::run(&gpu, a.quick, &a.output.progress());
    for c in &cases {
        if json {
            println!("{}", serde_json::to_string(c)?);
        } else {
            println!(
                "{:<8} {:<70} {:>12.5} {:>7.2} s  {}",
                format!("{:?}", c.outcome).to_lowercase(),
                c.name,
                c.value,
                c.seconds,
                c.message
            );
        }
    }
    let count = |o: Outcome| cases.iter().filter(|c| c.outcome == o).count();
    let (pass, fail, refused) = (
        count(Outcome::Pass),
        count(Outcome::Fail),
        count(Outcome::Refused),
    );
    let seconds: f64 = cases.iter().map(|c| c.seconds).sum();
    if json {
        let summary = serde_json::json!({ "summary": {
            "cases": cases.len(), "pass": pass, "fail": fail, "refused": refused, "seconds": seconds } });
        println!("{summary}");
    } else {
        println!(
            "{} cases: {pass} pass, {fail} fail, {refused} refused ({seconds:.1} s)",
            cases.len()
        );
    }
    if fail > 0 {
        bail!("{fail} stress cases failed");
    }
    Ok(())
}
