//! The observers `render` supplies: the progress bar, snapshots of the
//! running estimate, fly-through frames, and the live image (the tev
//! display server, `--write-partial`).

use std::path::PathBuf;
use std::time::{Duration, Instant};

use anyhow::Result;

use std::path::Path;

use anyhow::bail;
use photonmap::image::{write_all_atomically, write_atomically};
use photonmap::provenance::Provenance;
use photonmap::render::{EstimatePass, Image, Progress, RenderObserver, StopReason};
use photonmap::scene::Scene;

use super::args::{Format, OnSignal, Outputs, RenderArgs, SnapshotEvery};
use super::display::{image_name, DisplayServer, Placement};
use crate::cli::progress::{ProgressReport, Work};

/// The shortest time between two live images of a render in progress.
const LIVE_INTERVAL: Duration = Duration::from_millis(250);

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

/// The image in progress, to a tev viewer and to a partial EXR: at most
/// every `LIVE_INTERVAL` while the render runs, and each finished image.
struct Live {
    display: Option<DisplayServer>,
    partial: Option<(PathBuf, Vec<(String, String)>)>,
    /// Where the image sits in the frame (a crop), and the frame's size.
    placement: ((u32, u32), (u32, u32)),
    last: Option<Instant>,
}

impl Live {
    fn new(args: &RenderArgs, scene: &Scene, provenance: &Provenance) -> Option<Self> {
        let display = args.display_server.as_deref().map(|a| {
            let placement = provenance.pixel_bounds.map(|_| Placement {
                origin: provenance.origin(),
                frame: (provenance.width, provenance.height),
            });
            DisplayServer::start(a, image_name(&scene.name), placement)
        });
        let partial = args.write_partial.clone().map(|p| (p, provenance.pairs()));
        (display.is_some() || partial.is_some()).then_some(Self {
            display,
            partial,
            placement: (provenance.origin(), (provenance.width, provenance.height)),
            last: None,
        })
    }

    fn due(&self) -> bool {
        self.last.is_none_or(|t| t.elapsed() >= LIVE_INTERVAL)
    }

    /// Shows `image`; `finished`: a finished image, not a partial one.
    fn show(&mut self, image: &Image, finished: bool) -> photonmap::Result<()> {
        self.last = Some(Instant::now());
        if let Some(d) = &self.display {
            d.show(image);
        }
        let failed = match &self.partial {
            Some((path, pairs)) if !image.has_non_finite() => {
                let mut pairs = pairs.clone();
                if !finished {
                    pairs.push(("partial".into(), "true".into()));
                }
                let (origin, frame) = self.placement;
                let written = image
                    .exr_bytes_placed(&pairs, origin, frame)
                    .and_then(|bytes| write_atomically(path, &bytes));
                written
                    .err()
                    .map(|e| format!("--write-partial {}: {e}", path.display()))
            }
            _ => None,
        };
        // A preview that cannot be written must not cost the render.
        if let Some(why) = failed {
            eprintln!("warning: {why}; no more partial images are written");
            self.partial = None;
        }
        Ok(())
    }
}

/// The work done so far, kept for `--on-signal write-partial`: the mean of
/// the eye samples done, or the image after SPPM's iterations done.
pub(super) struct Done {
    pub(super) image: Image,
    pub(super) count: u32,
}

/// The CLI's observer: the progress report, snapshots of the first estimate,
/// the frames of a fly-through, the live image, and the work done so far.
pub(super) struct CliObserver {
    /// Kept only with `--on-signal write-partial`.
    pub(super) done: Option<Done>,
    keep_done: bool,
    sppm: bool,
    progress: ProgressReport,
    snapshots: Option<SnapshotWriter>,
    frames: Option<PathBuf>,
    frame_times: Vec<f64>,
    clock: std::time::Instant,
    live: Option<Live>,
}

impl CliObserver {
    pub(super) fn new(
        args: &RenderArgs,
        scene: &Scene,
        outputs: &Outputs,
        work: Work,
        provenance: &Provenance,
    ) -> Self {
        Self {
            done: None,
            keep_done: args.on_signal == OnSignal::WritePartial,
            sppm: matches!(work, Work::Iterations { .. }),
            live: Live::new(args, scene, provenance),
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

    /// Finishes the observing of a render that returned `result`; a render
    /// stopped by a signal with `--on-signal write-partial` first has the
    /// work done written to the EXR outputs.
    pub(super) fn finish_with<T>(
        &mut self,
        result: photonmap::Result<T>,
        outputs: &[(PathBuf, Format)],
        provenance: &Provenance,
    ) -> Result<T> {
        let done = self.done.take();
        self.finish()?;
        result.map_err(|e| write_done_on_signal(e, done, outputs, provenance.clone(), self.sppm))
    }

    /// Writes the index of a fly-through's frames.
    fn finish(&mut self) -> Result<()> {
        self.progress.finish();
        if let Some(d) = self.live.as_mut().and_then(|l| l.display.as_mut()) {
            d.finish();
        }
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
        // SPPM reports each iteration done as a pass (`pass` counts from 0).
        if self.keep_done && self.sppm && !pass.finished {
            self.done = Some(Done {
                image: pass.image()?,
                count: pass.pass + 1,
            });
        }
        if let Some(live) = &mut self.live {
            // The first eye sample's estimate, as snapshots show it: a later
            // sample's alone would look like a step back.
            if pass.at.view == 0 && pass.at.sample == 0 && live.due() {
                live.show(&pass.image()?, false)?;
            }
        }
        match &mut self.snapshots {
            Some(s) => s.estimate_pass(pass),
            None => Ok(()),
        }
    }

    fn samples_done(&mut self, view: usize, done: u32, mean: &dyn Fn() -> Image) {
        if self.keep_done && view == 0 {
            self.done = Some(Done {
                image: mean(),
                count: done,
            });
        }
    }

    fn frame(&mut self, view: usize, image: &Image) -> photonmap::Result<()> {
        if let Some(live) = &mut self.live {
            live.show(image, true)?;
        }
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

/// After a render stopped by a signal with `--on-signal write-partial`:
/// writes the work done to the EXR outputs, marked partial with its count of
/// eye samples (SPPM: iterations), and returns the error it stopped with.
fn write_done_on_signal(
    error: photonmap::error::Error,
    done: Option<Done>,
    outputs: &[(PathBuf, Format)],
    mut provenance: Provenance,
    sppm: bool,
) -> anyhow::Error {
    let (photonmap::error::Error::Interrupted { signal }, Some(done)) = (&error, done) else {
        return error.into();
    };
    let what = if sppm {
        provenance.iterations = Some(done.count);
        "iterations"
    } else {
        provenance.spp = done.count;
        "eye samples"
    };
    let mut pairs = provenance.pairs();
    pairs.push(("partial".into(), "true".into()));
    pairs.push(("photonmap.samples_done".into(), done.count.to_string()));
    let exrs: Vec<&Path> = outputs
        .iter()
        .filter(|(_, f)| *f == Format::Exr)
        .map(|(p, _)| p.as_path())
        .collect();
    let written = (|| -> Result<()> {
        if done.image.has_non_finite() {
            bail!("the image done so far has NaN or infinite pixels");
        }
        let bytes = done.image.exr_bytes_placed(
            &pairs,
            provenance.origin(),
            (provenance.width, provenance.height),
        )?;
        let files: Vec<(&Path, &[u8])> = exrs.iter().map(|p| (*p, bytes.as_slice())).collect();
        write_all_atomically(&files)?;
        Ok(())
    })();
    match written {
        Ok(()) => photonmap::error::Error::InterruptedAfterWriting {
            signal: *signal,
            wrote: format!(
                "the {} {what} done were written, marked partial, to {}",
                done.count,
                exrs.iter()
                    .map(|p| p.display().to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
        .into(),
        Err(e) => anyhow::Error::new(error).context(format!(
            "--on-signal write-partial: the work done could not be written: {e:#}"
        )),
    }
}
