//! The `photonmap` command as a user runs it, one binary: a module per
//! command (and one for injected faults), each running the built binary
//! through `common::Run`. `cargo test --release --test cli` runs it all; a
//! module alone is `cargo test --release --test cli render::`.

#[path = "../common/mod.rs"]
mod common;

mod bench;
mod compare;
mod faults;
mod import;
mod live;
mod merge;
mod methods;
mod outputs;
mod photons;
mod reference;
mod regress;
mod render;
mod reports;
mod scenes;
mod tables;
mod tiles;
