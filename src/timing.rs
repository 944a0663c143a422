//! Per-stage times, the rows Table 1 prints: GPU time from GL timer queries and
//! wall clock with glFinish at the stage's ends. Both are kept because llvmpipe's
//! GL_TIME_ELAPSED misses work in some pass patterns (it read 0.2 s of a 7.5 s
//! radiance estimate), so wall clock is the figure to trust on llvmpipe.

use std::time::Instant;

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct StageTiming {
    pub name: String,
    pub gpu_seconds: f64,
    pub wall_seconds: f64,
    pub passes: usize,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Timings {
    pub stages: Vec<StageTiming>,
    /// The whole render, set-up and read-backs included.
    pub wall_seconds: f64,
}

impl Timings {
    /// Adds a pass's GPU time to the stage `name` (created in first-seen order).
    pub fn add(&mut self, name: &str, gpu_seconds: f64, passes: usize) {
        self.add_both(name, gpu_seconds, 0.0, passes);
    }

    /// Adds GPU time, wall time and passes to the stage `name`.
    pub fn add_both(&mut self, name: &str, gpu_seconds: f64, wall_seconds: f64, passes: usize) {
        match self.stages.iter_mut().find(|s| s.name == name) {
            Some(s) => {
                s.gpu_seconds += gpu_seconds;
                s.wall_seconds += wall_seconds;
                s.passes += passes;
            }
            None => self.stages.push(StageTiming {
                name: name.to_string(),
                gpu_seconds,
                wall_seconds,
                passes,
            }),
        }
    }

    /// Adds GPU time, the wall time since `start` and passes to the stage `name`.
    pub fn add_since(&mut self, name: &str, gpu_seconds: f64, start: Instant, passes: usize) {
        self.add_both(name, gpu_seconds, start.elapsed().as_secs_f64(), passes);
    }

    /// Folds `stages` (a sub-task's own timings) into the one stage `name`:
    /// their GPU time and passes, and the wall time since `start`.
    pub fn add_folded(&mut self, name: &str, stages: &Timings, start: Instant) {
        self.add_since(name, stages.gpu_total(), start, stages.passes_total());
    }

    pub fn passes_total(&self) -> usize {
        self.stages.iter().map(|s| s.passes).sum()
    }

    pub fn gpu_total(&self) -> f64 {
        self.stages.iter().map(|s| s.gpu_seconds).sum()
    }

    pub fn wall_total(&self) -> f64 {
        self.stages.iter().map(|s| s.wall_seconds).sum()
    }

    /// Wall seconds summed into `N` components, `component` giving each
    /// stage's (a benchmark's split of a render's time).
    pub fn wall_by_component<const N: usize>(&self, component: impl Fn(&str) -> usize) -> [f64; N] {
        let mut parts = [0.0f64; N];
        for s in &self.stages {
            parts[component(&s.name)] += s.wall_seconds;
        }
        parts
    }

    /// A small table for stderr.
    pub fn table(&self) -> String {
        let mut out = format!(
            "{:<18} {:>7} {:>11} {:>11}\n",
            "stage", "passes", "GPU ms", "wall ms"
        );
        for s in &self.stages {
            out += &format!(
                "{:<18} {:>7} {:>11.2} {:>11.2}\n",
                s.name,
                s.passes,
                s.gpu_seconds * 1e3,
                s.wall_seconds * 1e3
            );
        }
        out += &format!(
            "{:<18} {:>7} {:>11.2} {:>11.2}   (whole render, wall: {:.2} ms)\n",
            "total",
            self.passes_total(),
            self.gpu_total() * 1e3,
            self.wall_total() * 1e3,
            self.wall_seconds * 1e3
        );
        out
    }
}
