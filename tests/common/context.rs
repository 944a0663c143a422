//! The tests' GL contexts. A `Gpu` is not `Send`: its context is current on
//! the thread that made it, and a thread has one current context at a time
//! (making a second one current, or destroying any, changes what the
//! first's objects are read through). libtest runs each test on a thread of
//! its own, so [`gpu`] gives each test one context, made on first use,
//! shared by everything the test renders and destroyed when its thread ends.
//! A test that must have a context of its own (another platform, on a
//! thread it spawns) makes one with [`OwnGpu::new`], holding
//! [`rendering_turn`] meanwhile. Tests render one at a time (`RENDERING`).
//!
//! Contexts are made and destroyed one at a time in the whole process.
//! Mesa's EGL and OSMesa lock their own state, and src/gpu/context.rs opens
//! each EGL display once per process and never terminates it nor unloads
//! libEGL, so this is a belt to those braces: a test binary runs tests on
//! several threads at once, and making and destroying contexts costs a few
//! milliseconds, against seconds of rendering.

use std::cell::OnceCell;
use std::ops::Deref;
use std::sync::{Mutex, MutexGuard};

use photonmap::gpu::{Gpu, Platform};

static MAKING_OR_DESTROYING: Mutex<()> = Mutex::new(());

fn one_at_a_time() -> MutexGuard<'static, ()> {
    MAKING_OR_DESTROYING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A context of its own, current on the thread that made it; made and, when
/// dropped, destroyed while no other context is being made or destroyed.
pub struct OwnGpu(Option<Gpu>);

impl OwnGpu {
    pub fn new(platform: Platform) -> photonmap::gpu::Result<Self> {
        let _one = one_at_a_time();
        Gpu::new(platform).map(|gpu| Self(Some(gpu)))
    }
}

impl Deref for OwnGpu {
    type Target = Gpu;

    fn deref(&self) -> &Gpu {
        self.0.as_ref().expect("the context lives until dropped")
    }
}

impl Drop for OwnGpu {
    fn drop(&mut self) {
        let _one = one_at_a_time();
        drop(self.0.take());
    }
}

/// One test at a time renders. Mesa 22's llvmpipe crashes now and then
/// (SIGSEGV) with two test threads rendering on contexts of their own at
/// once: a core dump showed one thread uploading a texture
/// (`tex_sub_image_2d`) inside swrast_dri while the other, in its first
/// fused eye-path draw, waited on a lock of the driver's. Tests that do
/// not render still run beside them.
static RENDERING: Mutex<()> = Mutex::new(());

/// This thread's turn to render, held until it is dropped: for a test that
/// renders on contexts of its own (`OwnGpu`, on threads it spawns) rather
/// than through [`gpu`].
pub fn rendering_turn() -> MutexGuard<'static, ()> {
    RENDERING
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner())
}

/// A test's context and its turn to render, dropped in that order when the
/// test's thread ends.
struct TestGpu {
    gpu: OwnGpu,
    _turn: MutexGuard<'static, ()>,
}

thread_local! {
    static THIS_TESTS_GPU: OnceCell<TestGpu> = const { OnceCell::new() };
}

/// This test's context (the thread's): made on the first call, after
/// waiting for the test's turn to render (`RENDERING`), the same context on
/// every later one.
pub fn gpu() -> Gpu {
    THIS_TESTS_GPU.with(|cell| {
        let test = cell.get_or_init(|| {
            let turn = rendering_turn();
            let gpu = OwnGpu::new(Platform::Auto)
                .expect("a GL 4 context (install libegl1 libegl-mesa0 libgl1-mesa-dri)");
            TestGpu { gpu, _turn: turn }
        });
        Gpu::clone(&test.gpu)
    })
}
