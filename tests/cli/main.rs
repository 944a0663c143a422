//! The `photonmap` command as a user runs it, one binary: a module per
//! command, each spawning the built binary. `cargo test --release --test cli`
//! runs it all; a module alone is `cargo test --release --test cli render::`.

#[path = "../common/mod.rs"]
mod common;

mod faults;
mod render;
