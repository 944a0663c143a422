//! `tables`' files, kept until the run has finished and then written all or
//! nothing.

use std::path::{Path, PathBuf};

use anyhow::Result;

use photonmap::render::Image;

/// Every file of a `tables` run, kept until the run has finished and then
/// written all or nothing, so an interrupted or failed run leaves the
/// previous results as they were.
#[derive(Default)]
pub(super) struct Staged(std::cell::RefCell<Vec<(PathBuf, Vec<u8>)>>);

impl Staged {
    pub(super) fn add(&self, path: PathBuf, bytes: Vec<u8>) {
        self.0.borrow_mut().push((path, bytes));
    }

    pub(super) fn png(&self, path: PathBuf, img: &Image) -> Result<()> {
        self.add(path, img.png_bytes()?);
        Ok(())
    }

    /// Writes every file; then removes older snapshots in `figure8/` that this run did not make.
    pub(super) fn publish(self, out: &Path) -> Result<()> {
        let files = self.0.into_inner();
        let refs: Vec<(&Path, &[u8])> = files
            .iter()
            .map(|(p, b)| (p.as_path(), b.as_slice()))
            .collect();
        photonmap::image::write_all_atomically(&refs)?;
        let made: std::collections::HashSet<&Path> = refs.iter().map(|(p, _)| *p).collect();
        if let Ok(entries) = std::fs::read_dir(out.join("figure8")) {
            for e in entries.flatten() {
                if !made.contains(e.path().as_path()) {
                    let _ = std::fs::remove_file(e.path());
                }
            }
        }
        Ok(())
    }
}
