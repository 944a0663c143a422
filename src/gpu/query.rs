//! GL queries: timer queries for per-stage GPU time, occlusion queries for
//! counting fragments (and, later, stopping finished tiles).

use glow::HasContext;

use super::{Gpu, GpuError};

/// GL_TIME_ELAPSED around a span of GL commands.
pub struct TimerQuery {
    gpu: Gpu,
    raw: glow::Query,
}

impl TimerQuery {
    pub fn new(gpu: &Gpu) -> Result<Self, GpuError> {
        let raw = unsafe { gpu.gl().create_query() }.map_err(GpuError::Gl)?;
        Ok(Self {
            gpu: gpu.clone(),
            raw,
        })
    }
    pub fn begin(&self) {
        unsafe { self.gpu.gl().begin_query(glow::TIME_ELAPSED, self.raw) }
    }
    pub fn end(&self) {
        unsafe { self.gpu.gl().end_query(glow::TIME_ELAPSED) }
    }
    /// Elapsed GPU seconds; waits for the result.
    pub fn seconds(&self) -> f64 {
        let ns = unsafe {
            self.gpu
                .gl()
                .get_query_parameter_u64(self.raw, glow::QUERY_RESULT)
        };
        ns as f64 * 1e-9
    }
}

impl Drop for TimerQuery {
    fn drop(&mut self) {
        unsafe { self.gpu.gl().delete_query(self.raw) }
    }
}

/// GL_SAMPLES_PASSED: how many fragments passed every test during a span.
pub struct OcclusionQuery {
    gpu: Gpu,
    raw: glow::Query,
}

impl OcclusionQuery {
    pub fn new(gpu: &Gpu) -> Result<Self, GpuError> {
        let raw = unsafe { gpu.gl().create_query() }.map_err(GpuError::Gl)?;
        Ok(Self {
            gpu: gpu.clone(),
            raw,
        })
    }
    pub fn begin(&self) {
        unsafe { self.gpu.gl().begin_query(glow::SAMPLES_PASSED, self.raw) }
    }
    pub fn end(&self) {
        unsafe { self.gpu.gl().end_query(glow::SAMPLES_PASSED) }
    }
    pub fn samples(&self) -> u64 {
        unsafe {
            self.gpu
                .gl()
                .get_query_parameter_u64(self.raw, glow::QUERY_RESULT)
        }
    }
}

impl Drop for OcclusionQuery {
    fn drop(&mut self) {
        unsafe { self.gpu.gl().delete_query(self.raw) }
    }
}
