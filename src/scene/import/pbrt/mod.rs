//! pbrt-v4 scene files: the tokenizer (`lexer.rs`), typed parameters
//! (`params.rs`), the directives and graphics state (here), and what the
//! scene's objects become (`objects.rs`: cameras, shapes, materials,
//! lights). Transforms compose as in pbrt (each directive post-multiplies
//! the current transform); `ReverseOrientation` and transforms that swap
//! handedness flip which side a one-sided emitter lights; object instances
//! are flattened.

mod lexer;
mod objects;
mod params;
mod reader;
mod state;

pub use reader::read;
