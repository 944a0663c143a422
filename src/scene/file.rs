//! Reading a scene's text files consistently. A file being rewritten in place
//! (an editor saving without a rename, a script) is a mixture of two versions
//! while the write is under way, and nothing in the file says so. So a file
//! is read only once it has stood still for `QUIET` (by its modification
//! time), and read again if it changed during the read: the text loaded is
//! one version, unless a writer pauses longer than `QUIET` mid-file.

use std::path::Path;
use std::time::{Duration, SystemTime};

/// How long a file must have been unchanged before it is read.
pub const QUIET: Duration = Duration::from_millis(50);
/// How long to wait for a file that keeps changing.
const PATIENCE: Duration = Duration::from_secs(5);

fn stamp(path: &Path) -> std::io::Result<(u64, Option<SystemTime>)> {
    let m = std::fs::metadata(path)?;
    Ok((m.len(), m.modified().ok()))
}

/// The file's text, read while it stood still.
pub fn read_stable(path: &Path) -> std::io::Result<String> {
    let start = std::time::Instant::now();
    loop {
        let before = stamp(path)?;
        let age = before
            .1
            .and_then(|t| SystemTime::now().duration_since(t).ok())
            .unwrap_or(QUIET);
        if age >= QUIET {
            let text = std::fs::read_to_string(path)?;
            if stamp(path)? == before && text.len() as u64 == before.0 {
                return Ok(text);
            }
        }
        if start.elapsed() > PATIENCE {
            return Err(std::io::Error::other(format!(
                "the file kept changing for {} s while it was being read",
                PATIENCE.as_secs()
            )));
        }
        std::thread::sleep(QUIET.saturating_sub(age).max(Duration::from_millis(2)));
    }
}
