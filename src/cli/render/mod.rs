//! `photonmap render`: one image (any number of PNG, EXR and PFM files), or a
//! fly-through of frames on one photon map; SPPM's iterations, or a frame
//! of one of the other methods.

mod args;
mod display;
mod frame;
mod observer;
mod output;
mod sppm;
mod vcm;

pub use args::{RenderArgs, SnapshotEvery};
pub use observer::SnapshotWriter;

use anyhow::Result;
use photonmap::gpu::Platform;

pub fn run(args: &RenderArgs, platform: Platform) -> Result<()> {
    if args.method == crate::cli::args::Method::Sppm {
        sppm::run(args, platform)
    } else if args.method == crate::cli::args::Method::Vcm {
        vcm::run(args, platform)
    } else {
        frame::run(args, platform)
    }
}
