//! One progress report per render: a bar with the stage, the eye sample (or
//! SPPM iteration) and an ETA on a terminal; plain lines (each stage, and
//! every tenth of the work) when stderr is a file or a pipe.

use std::io::IsTerminal;

use photonmap::render::Progress;

/// Units of work: the photon stage, then per view and eye sample its
/// ray-tracing passes and a hundred for the estimate (by pixels finished).
pub struct ProgressReport {
    bar: Option<indicatif::ProgressBar>,
    plain: bool,
    name: String,
    photon_units: u64,
    passes_per_sample: u64,
    estimate_units: u64,
    total: u64,
    last_stage: String,
    last_tenth: u64,
    /// A progressive render's time limit: the report follows the clock
    /// when that comes before the iterations.
    seconds: Option<f64>,
    clock: std::time::Instant,
}

impl ProgressReport {
    /// `samples` eye samples of `views` views with `passes` ray-tracing passes
    /// each (and an estimate unless `direct_only`), or `iterations` of SPPM.
    pub fn new(quiet: bool, name: &str, work: Work) -> Self {
        let (photon_units, passes, estimate, runs) = match work {
            Work::Paper {
                passes,
                samples,
                views,
                direct_only,
            } => (
                if direct_only { 0 } else { 10 },
                passes as u64,
                if direct_only { 0 } else { 100 },
                (samples as u64) * (views as u64),
            ),
            Work::Iterations { iterations, .. } => (0, 0, 1, iterations as u64),
        };
        let seconds = match work {
            Work::Iterations { seconds, .. } => seconds,
            Work::Paper { .. } => None,
        };
        let total = photon_units + runs * (passes + estimate);
        let terminal = std::io::stderr().is_terminal();
        let bar = (!quiet && terminal).then(|| {
            let b = indicatif::ProgressBar::new(total.max(1));
            b.set_style(
                indicatif::ProgressStyle::with_template(
                    "{prefix} [{bar:30}] {percent:>3}% {msg} ({elapsed}, ETA {eta})",
                )
                .expect("valid template")
                .progress_chars("=> "),
            );
            b.set_prefix(name.to_string());
            b
        });
        Self {
            bar,
            plain: !quiet && !terminal,
            name: name.into(),
            photon_units,
            passes_per_sample: passes,
            estimate_units: estimate,
            total,
            last_stage: String::new(),
            last_tenth: 0,
            seconds,
            clock: std::time::Instant::now(),
        }
    }

    pub fn update(&mut self, p: &Progress<'_>) {
        let per_run = self.passes_per_sample + self.estimate_units;
        let (position, what) = match p.at {
            None if p.stage == photonmap::render::progressive::ITERATIONS_STAGE => {
                match self.seconds {
                    // Whichever of the clock and the iterations is further on.
                    Some(s) => {
                        let elapsed = self.clock.elapsed().as_secs_f64();
                        let by_time = (elapsed / s * self.total as f64) as u64;
                        let what = if p.total >= super::args::MAX_SPPM_ITERATIONS as u64 {
                            format!("iteration {}, {elapsed:.0} of {s} s", p.done)
                        } else {
                            format!("iteration {}/{}, {elapsed:.0} of {s} s", p.done, p.total)
                        };
                        (p.done.max(by_time), what)
                    }
                    None => (p.done, format!("iteration {}/{}", p.done, p.total)),
                }
            }
            None => (0, p.stage.to_string()),
            Some(at) => {
                let run = (at.view as u64) * at.samples as u64 + at.sample as u64;
                let within = match p.stage {
                    "radiance estimate" => {
                        self.passes_per_sample + p.done * self.estimate_units / p.total.max(1)
                    }
                    _ => p.done.min(self.passes_per_sample),
                };
                let mut what = format!("sample {}/{}, {}", at.sample + 1, at.samples, p.stage);
                if at.views > 1 {
                    what = format!("view {}/{}, {what}", at.view + 1, at.views);
                }
                (self.photon_units + run * per_run + within, what)
            }
        };
        let position = position.min(self.total);
        if let Some(bar) = &self.bar {
            bar.set_position(position);
            bar.set_message(what.clone());
        }
        if self.plain {
            let tenth = position * 10 / self.total.max(1);
            if what.split(", ").last() != self.last_stage.split(", ").last()
                || tenth > self.last_tenth
            {
                eprintln!(
                    "[{:>3}%] {}: {what}",
                    position * 100 / self.total.max(1),
                    self.name
                );
                self.last_tenth = tenth;
            }
        }
        self.last_stage = what;
    }

    pub fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

/// What a render will do, for the report's units.
pub enum Work {
    Paper {
        passes: u32,
        samples: u32,
        views: usize,
        direct_only: bool,
    },
    /// SPPM: iterations at most, and seconds at most when given.
    Iterations {
        iterations: u32,
        seconds: Option<f64>,
    },
}
