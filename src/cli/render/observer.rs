//! The observers `render` supplies: the progress bar, snapshots of the
//! running estimate, and fly-through frames.

use std::path::PathBuf;

use anyhow::Result;

use photonmap::image::write_atomically;
use photonmap::render::{EstimatePass, Image, Progress, RenderObserver, StopReason};
use photonmap::scene::Scene;

use super::args::{Outputs, RenderArgs, SnapshotEvery};
use crate::cli::progress::{ProgressReport, Work};

/// A snapshot written during the estimate.
#[derive(Clone, Debug, serde::Serialize)]
pub struct SnapshotRecord {
    pub file: String,
    pub pass: u32,
    /// Seconds of radiance estimate so far (writing snapshots not counted).
    pub seconds: f64,
    pub searching_pixels: u64,
    /// A progressive render's last snapshot: what ended it.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped_by: Option<StopReason>,
}

/// Writes the running estimate of a render's first estimate as numbered PNGs
/// into a folder, the final image last, with snapshots.json listing them.
pub struct SnapshotWriter {
    dir: PathBuf,
    every: SnapshotEvery,
    pub written: Vec<SnapshotRecord>,
    last: (u32, f64),
}

impl SnapshotWriter {
    pub fn new(dir: PathBuf, every: SnapshotEvery) -> Self {
        Self {
            dir,
            every,
            written: Vec::new(),
            last: (0, 0.0),
        }
    }
}

impl RenderObserver for SnapshotWriter {
    fn estimate_pass(&mut self, pass: &EstimatePass<'_>) -> photonmap::Result<()> {
        // Snapshots follow the first estimate only.
        if pass.at.view != 0 || pass.at.sample != 0 {
            return Ok(());
        }
        let due = pass.finished
            || pass.pass == 0
            || match self.every {
                SnapshotEvery::Passes(n) => pass.pass >= self.last.0 + n,
                SnapshotEvery::Seconds(s) => pass.seconds >= self.last.1 + s,
            };
        if !due {
            return Ok(());
        }
        let file = format!("snapshot_{:04}.png", self.written.len());
        write_atomically(&self.dir.join(&file), &pass.image()?.png_bytes()?)?;
        self.written.push(SnapshotRecord {
            file,
            pass: pass.pass,
            seconds: pass.seconds,
            searching_pixels: pass.searching,
            stopped_by: pass.stopped_by,
        });
        self.last = (pass.pass, pass.seconds);
        if pass.finished {
            let index = serde_json::to_string_pretty(&self.written).unwrap_or_default();
            write_atomically(&self.dir.join("snapshots.json"), index.as_bytes())?;
        }
        Ok(())
    }
}

/// The CLI's observer: the progress report, snapshots of the first estimate,
/// and the frames of a fly-through.
pub(super) struct CliObserver {
    progress: ProgressReport,
    snapshots: Option<SnapshotWriter>,
    frames: Option<PathBuf>,
    frame_times: Vec<f64>,
    clock: std::time::Instant,
}

impl CliObserver {
    pub(super) fn new(args: &RenderArgs, scene: &Scene, outputs: &Outputs, work: Work) -> Self {
        Self {
            progress: ProgressReport::new(args.quiet, &scene.name, work),
            snapshots: args
                .snapshots
                .clone()
                .map(|d| SnapshotWriter::new(d, args.every)),
            frames: match outputs {
                Outputs::Frames(dir, _) => Some(dir.clone()),
                Outputs::Images(_) => None,
            },
            frame_times: Vec::new(),
            clock: std::time::Instant::now(),
        }
    }

    /// Writes the index of a fly-through's frames.
    pub(super) fn finish(&mut self) -> Result<()> {
        self.progress.finish();
        if let Some(dir) = &self.frames {
            let index = serde_json::json!({ "frames": self.frame_times.len(), "seconds_since_start": self.frame_times });
            write_atomically(&dir.join("frames.json"), index.to_string().as_bytes())?;
        }
        Ok(())
    }
}

impl RenderObserver for CliObserver {
    fn progress(&mut self, p: &Progress<'_>) {
        self.progress.update(p);
    }

    fn estimate_pass(&mut self, pass: &EstimatePass<'_>) -> photonmap::Result<()> {
        match &mut self.snapshots {
            Some(s) => s.estimate_pass(pass),
            None => Ok(()),
        }
    }

    fn frame(&mut self, view: usize, image: &Image) -> photonmap::Result<()> {
        if let Some(dir) = &self.frames {
            write_atomically(
                &dir.join(format!("frame_{view:04}.png")),
                &image.png_bytes()?,
            )?;
            self.frame_times.push(self.clock.elapsed().as_secs_f64());
        }
        Ok(())
    }
}
