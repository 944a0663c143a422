//! Mitsuba 3 XML scenes (Mitsuba 0.6's camelCase names accepted too):
//! properties and transforms (`values.rs`, a leaf), the document with its
//! defaults, includes and ids (`document.rs`), and what each object
//! becomes (`objects.rs`).

mod document;
mod objects;
mod state;
mod values;

pub use document::read;
