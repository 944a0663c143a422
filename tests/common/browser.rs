//! Headless Chromium (Debian's `chromium`, which .ci/run installs) opening a
//! report page: the page's own script marks `<html>` with
//! `data-images-loaded="N/M"` once loaded, and the dumped DOM is read back.

use std::path::Path;
use std::process::Command;

pub const CHROMIUM: &str = "/usr/bin/chromium";

/// (pictures that decoded, pictures) of the HTML page at `html`, as headless
/// Chromium loads it. Panics when Chromium is missing or the page never set
/// its mark.
pub fn images_loaded(html: &Path) -> (usize, usize) {
    assert!(
        Path::new(CHROMIUM).is_file(),
        "{CHROMIUM} is missing: install Debian's package chromium (.ci/run does)"
    );
    let profile = super::TempDir::new("chromium-profile");
    let url = format!("file://{}", html.canonicalize().unwrap().display());
    let out = Command::new("timeout")
        .args([
            "60",
            CHROMIUM,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(["--dump-dom", &url])
        .output()
        .unwrap_or_else(|e| panic!("{CHROMIUM}: {e}"));
    let dom = String::from_utf8_lossy(&out.stdout);
    let mark = "data-images-loaded=\"";
    let at = dom.find(mark).unwrap_or_else(|| {
        panic!(
            "{}: no {mark}...\" in Chromium's DOM ({}); stderr: {}",
            html.display(),
            out.status,
            String::from_utf8_lossy(&out.stderr)
        )
    });
    let rest = &dom[at + mark.len()..];
    let value = &rest[..rest.find('"').unwrap()];
    let (n, m) = value.split_once('/').unwrap();
    (n.parse().unwrap(), m.parse().unwrap())
}
