//! Stopping on SIGINT or SIGTERM. The command line installs the handlers,
//! which only set a flag; the library's long loops (eye samples, estimate
//! passes, photon bounces, SPPM iterations, benchmark runs) call `check`
//! between passes and stop with `Error::Interrupted`. Outputs are written only
//! after the work, all or nothing, so an interrupted command leaves no file,
//! and the temporary files of a write under way are removed as the error
//! returns. A second signal ends the process at once.

use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, LazyLock};

use crate::error::{Error, Result};

pub const SIGINT: i32 = signal_hook::consts::SIGINT;
pub const SIGTERM: i32 = signal_hook::consts::SIGTERM;

/// The signal received (0: none).
static RECEIVED: LazyLock<Arc<AtomicUsize>> = LazyLock::new(|| Arc::new(AtomicUsize::new(0)));

/// Installs the handlers for SIGINT and SIGTERM (the command line calls it once).
pub fn install() -> std::io::Result<()> {
    let seen = Arc::new(AtomicBool::new(false));
    for signal in [SIGINT, SIGTERM] {
        // The first signal sets `seen` (and the flag); a second one exits with 128 + signal.
        signal_hook::flag::register_conditional_shutdown(signal, 128 + signal, seen.clone())?;
        signal_hook::flag::register(signal, seen.clone())?;
        signal_hook::flag::register_usize(signal, RECEIVED.clone(), signal as usize)?;
    }
    Ok(())
}

/// The signal asking the program to stop, if one came.
pub fn requested() -> Option<i32> {
    match RECEIVED.load(Ordering::Relaxed) {
        0 => None,
        s => Some(s as i32),
    }
}

/// `Err(Error::Interrupted)` once a signal has come.
pub fn check() -> Result<()> {
    match requested() {
        Some(signal) => Err(Error::Interrupted { signal }),
        None => Ok(()),
    }
}
