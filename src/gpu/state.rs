//! The fixed-function state of one draw, given in full with every draw (after
//! three-d's `RenderStates`): nothing a pass switches on can leak into the
//! next, whatever path an error took out of the pass before.

/// A depth or stencil comparison.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Compare {
    Always,
    Equal,
    Less,
}

/// What the stencil does with a fragment (the same op for fail, depth-fail
/// and pass unless the test says otherwise).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StencilOp {
    Keep,
    Replace,
    Incr,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Blend {
    /// Fragments replace what is there.
    Off,
    /// ONE, ONE on every draw buffer: accumulating passes.
    Additive,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DepthTest {
    Off,
    /// Test with `compare`; `write` keeps the fragment's depth.
    On {
        compare: Compare,
        write: bool,
    },
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StencilTest {
    Off,
    /// glStencilFunc(compare, reference, 0xff), glStencilOp(fail, depth_fail,
    /// pass), with every stencil bit writable.
    On {
        compare: Compare,
        reference: i32,
        fail: StencilOp,
        depth_fail: StencilOp,
        pass: StencilOp,
    },
}

/// Everything a draw's fixed function does, applied in full before each draw.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawState {
    pub color_writes: bool,
    pub blend: Blend,
    pub depth: DepthTest,
    pub stencil: StencilTest,
}

impl Default for DrawState {
    fn default() -> Self {
        Self::PLAIN
    }
}

impl DrawState {
    /// Colour written, nothing tested, nothing blended: most passes.
    pub const PLAIN: DrawState = DrawState {
        color_writes: true,
        blend: Blend::Off,
        depth: DepthTest::Off,
        stencil: StencilTest::Off,
    };

    /// Colour added onto what is there.
    pub const ADDITIVE: DrawState = DrawState {
        blend: Blend::Additive,
        ..Self::PLAIN
    };

    /// A z-buffer: colour written where the fragment is nearer (LESS) than
    /// what the depth buffer holds, which it then replaces.
    pub const Z_BUFFER: DrawState = DrawState {
        depth: DepthTest::On {
            compare: Compare::Less,
            write: true,
        },
        ..Self::PLAIN
    };

    /// Counting only (occlusion queries): no colour written.
    pub const NO_COLOR: DrawState = DrawState {
        color_writes: false,
        ..Self::PLAIN
    };

    /// Stencil only: colour untouched, depth always passes unwritten, and the
    /// stencil set to `reference` (by the test) or by the shader's export.
    pub fn stencil_replace(reference: i32) -> DrawState {
        DrawState {
            color_writes: false,
            blend: Blend::Off,
            depth: DepthTest::On {
                compare: Compare::Always,
                write: false,
            },
            stencil: StencilTest::On {
                compare: Compare::Always,
                reference,
                fail: StencilOp::Keep,
                depth_fail: StencilOp::Keep,
                pass: StencilOp::Replace,
            },
        }
    }

    /// Colour written where the stencil equals `reference`, which stays; depth
    /// always passes unwritten (the computation mask).
    pub fn where_stencil_equals(reference: i32) -> DrawState {
        DrawState {
            color_writes: true,
            blend: Blend::Off,
            depth: DepthTest::On {
                compare: Compare::Always,
                write: false,
            },
            stencil: StencilTest::On {
                compare: Compare::Equal,
                reference,
                fail: StencilOp::Keep,
                depth_fail: StencilOp::Keep,
                pass: StencilOp::Keep,
            },
        }
    }
}
