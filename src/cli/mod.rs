//! The command line's subcommands beyond `render` and `info`.
pub mod accuracy;
pub mod bench;
pub mod photons;
pub mod tables;
