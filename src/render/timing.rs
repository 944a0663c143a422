//! Per-stage GPU times (GL timer queries) and wall clock, the rows Table 1 prints.

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct StageTiming {
    pub name: String,
    pub gpu_seconds: f64,
    pub passes: usize,
}

#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Timings {
    pub stages: Vec<StageTiming>,
    pub wall_seconds: f64,
}

impl Timings {
    /// Adds a pass's time to the stage `name` (created in first-seen order).
    pub fn add(&mut self, name: &str, gpu_seconds: f64, passes: usize) {
        match self.stages.iter_mut().find(|s| s.name == name) {
            Some(s) => {
                s.gpu_seconds += gpu_seconds;
                s.passes += passes;
            }
            None => self.stages.push(StageTiming {
                name: name.to_string(),
                gpu_seconds,
                passes,
            }),
        }
    }

    pub fn gpu_total(&self) -> f64 {
        self.stages.iter().map(|s| s.gpu_seconds).sum()
    }

    /// A small table for stderr.
    pub fn table(&self) -> String {
        let mut out = format!("{:<14} {:>7} {:>11}\n", "stage", "passes", "GPU ms");
        for s in &self.stages {
            out += &format!(
                "{:<14} {:>7} {:>11.2}\n",
                s.name,
                s.passes,
                s.gpu_seconds * 1e3
            );
        }
        out += &format!(
            "{:<14} {:>7} {:>11.2}   (wall {:.2} ms)\n",
            "total",
            self.stages.iter().map(|s| s.passes).sum::<usize>(),
            self.gpu_total() * 1e3,
            self.wall_seconds * 1e3
        );
        out
    }
}
