//! GL queries around a span of commands: GPU time (per-stage timings) or
//! fragments that passed every test (tiles still searching, live photons).

use glow::HasContext;

use super::{Error, Gpu, Result};

pub struct Query {
    gpu: Gpu,
    raw: glow::Query,
    target: u32,
}

impl Query {
    /// GL_TIME_ELAPSED: `seconds` reads the GPU time of the span.
    pub fn timer(gpu: &Gpu) -> Result<Self> {
        Self::new(gpu, glow::TIME_ELAPSED)
    }

    /// GL_SAMPLES_PASSED: `count` reads the fragments that passed.
    pub fn occlusion(gpu: &Gpu) -> Result<Self> {
        Self::new(gpu, glow::SAMPLES_PASSED)
    }

    fn new(gpu: &Gpu, target: u32) -> Result<Self> {
        // SAFETY: gpu module doc.
        let raw = unsafe { gpu.gl().create_query() }.map_err(Error::creating("a query"))?;
        Ok(Self {
            gpu: gpu.clone(),
            raw,
            target,
        })
    }

    pub fn begin(&self) {
        // SAFETY: gpu module doc; the query is this value's own.
        unsafe { self.gpu.gl().begin_query(self.target, self.raw) }
    }

    pub fn end(&self) {
        // SAFETY: gpu module doc.
        unsafe { self.gpu.gl().end_query(self.target) }
    }

    /// Runs `work` as the query's span: begun before it, ended after it
    /// whatever it returns, then its result.
    pub fn around<T>(&self, work: impl FnOnce() -> Result<T>) -> Result<T> {
        self.begin();
        let result = work();
        self.end();
        result
    }

    /// The result of the last span; waits for it.
    pub fn count(&self) -> u64 {
        // SAFETY: gpu module doc; the query is this value's own and has ended.
        unsafe {
            self.gpu
                .gl()
                .get_query_parameter_u64(self.raw, glow::QUERY_RESULT)
        }
    }

    /// A timer query's span in seconds; waits for it.
    pub fn seconds(&self) -> f64 {
        self.count() as f64 * 1e-9
    }
}

impl Drop for Query {
    fn drop(&mut self) {
        // SAFETY: gpu module doc; the query is this value's own.
        unsafe { self.gpu.gl().delete_query(self.raw) }
    }
}
