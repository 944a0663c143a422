//! Faults injected into real runs: a signal mid-render and mid-`tables`, a GL
//! allocation the driver refuses partway through a render, and a scene file
//! rewritten while it is loaded. (A full disk is tested in the outputs module
//! and src/image.rs.) Each must end with a clear error, the conventional exit
//! code, and no partial or changed files.

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common::{self, Printed, Run, TempDir};

/// Every file under `dir`, relative, with its bytes.
fn files(dir: &Path) -> Vec<(PathBuf, Vec<u8>)> {
    let mut out = Vec::new();
    let mut pending = vec![dir.to_path_buf()];
    while let Some(d) = pending.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                pending.push(p);
            } else {
                out.push((
                    p.strip_prefix(dir).unwrap().to_path_buf(),
                    std::fs::read(&p).unwrap(),
                ));
            }
        }
    }
    out.sort();
    out
}

/// Runs photonmap with `args`, sends `signal` once stderr has shown `started`
/// (and `delay` more), and returns the exit code and stderr.
fn interrupted(args: &[&str], started: &str, delay_ms: u64, signal: &str) -> (Option<i32>, String) {
    let mut child = Run::new(args).spawn();
    let mut lines = BufReader::new(child.stderr.take().unwrap()).lines();
    let mut seen = String::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        seen += &line;
        seen.push('\n');
        if line.contains(started) {
            break;
        }
    }
    std::thread::sleep(std::time::Duration::from_millis(delay_ms));
    let killed = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    for line in lines {
        seen += &line.unwrap();
        seen.push('\n');
    }
    let status = child.wait().unwrap();
    (status.code(), seen)
}

#[test]
fn sigint_and_sigterm_stop_a_render_with_130_and_143_and_no_output() {
    for (signal, code, name) in [("-INT", 130, "SIGINT"), ("-TERM", 143, "SIGTERM")] {
        let d = TempDir::new(&format!("render{code}"));
        let png = d.join("out.png");
        let exr = d.join("out.exr");
        let args = [
            "render",
            "ring",
            "--method",
            "sppm",
            "--iterations",
            "1000000",
            "--width",
            "64",
            "--height",
            "48",
            "-o",
            png.to_str().unwrap(),
            "-o",
            exr.to_str().unwrap(),
        ];
        let (status, stderr) = interrupted(&args, "iteration", 300, signal);
        assert_eq!(status, Some(code), "{stderr}");
        assert!(
            stderr.contains(&format!("interrupted by {name}")),
            "{stderr}"
        );
        assert!(
            files(&d).is_empty(),
            "left behind: {:?}",
            files(&d).iter().map(|f| &f.0).collect::<Vec<_>>()
        );
    }
}

#[test]
fn an_interrupted_tables_run_leaves_the_previous_results_as_they_were() {
    let d = TempDir::new("tables");
    // The previous results: the files a run writes, with known contents.
    std::fs::create_dir_all(d.join("figure7")).unwrap();
    std::fs::create_dir_all(d.join("figure8")).unwrap();
    for (file, text) in [
        ("results.json", "{\"previous\": true}"),
        ("tables.md", "previous tables"),
        ("table1.csv", "previous,csv"),
        ("figure7.png", "previous figure"),
        ("figure7/glass_ball_bitonic.png", "previous image"),
        ("figure8/snapshot_0000.png", "previous snapshot"),
    ] {
        std::fs::write(d.join(file), text).unwrap();
    }
    let before = files(&d);
    let args = ["tables", "--quick", "--out", d.to_str().unwrap()];
    // Well into Table 1, after its first images were made.
    let (status, stderr) = interrupted(&args, "Table 1", 1500, "-TERM");
    assert_eq!(status, Some(143), "{stderr}");
    assert_eq!(files(&d), before, "the previous results changed");
}

#[test]
fn a_texture_the_driver_refuses_partway_through_a_render_is_a_clear_error_and_no_output() {
    let d = TempDir::new("oom");
    // 512^3 grid cells need a 2 GiB cell texture, made after the photons are traced.
    let out = Run::new(["render", "glass_ball"])
        .args(["--set", "photon_map.grid_resolution=[512,512,512]"])
        .output_to(d.join("out.png"))
        .run();
    let stderr = out.stderr_text();
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    // Partway: the photon stage had begun.
    assert!(stderr.contains("photons"), "{stderr}");
    // The resource and its size are named.
    let error = stderr.lines().find(|l| l.starts_with("error:")).unwrap();
    assert!(
        error.contains("texture")
            && error.contains(" x ")
            && (error.contains("GiB") || error.contains("must be")),
        "{error}"
    );
    assert!(files(&d).is_empty());
}

/// A writer rewrites the scene file in place, alternating two versions of
/// the same length and pausing 2 ms between the halves of each write (so a
/// plain read often gets half of each); every load must be one version or a
/// clear error, never a mixture.
#[test]
fn a_scene_file_rewritten_while_it_loads_loads_as_one_version() {
    let d = TempDir::new("changing");
    let file = d.join("scene.toml");
    let original = std::fs::read_to_string(common::scene_file("glass_ball")).unwrap();
    // Two versions of the same length that differ at both ends of the file.
    let a = original.replace("name = \"GLASS BALL\"", "name = \"VERSION A\"");
    let b = original
        .replace("name = \"GLASS BALL\"", "name = \"VERSION B\"")
        .replace(
            "radiance = [60.0, 60.0, 60.0]",
            "radiance = [30.0, 30.0, 30.0]",
        );
    assert_eq!(a.len(), b.len());
    std::fs::write(&file, &a).unwrap();
    let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let writer = {
        let (file, stop, a, b) = (file.clone(), stop.clone(), a.clone(), b.clone());
        std::thread::spawn(move || {
            use std::io::Write;
            let mut i = 0u64;
            while !stop.load(std::sync::atomic::Ordering::Relaxed) {
                let text = if i.is_multiple_of(2) { &b } else { &a };
                // In place over the same length (an editor saving without a rename).
                let mut f = std::fs::OpenOptions::new().write(true).open(&file).unwrap();
                let half = text.len() / 2;
                f.write_all(&text.as_bytes()[..half]).unwrap();
                std::thread::sleep(std::time::Duration::from_millis(2));
                f.write_all(&text.as_bytes()[half..]).unwrap();
                drop(f);
                // Quiet spells, alternating with bursts of writes.
                let pause = if i % 8 == 7 { 120 } else { 1 };
                std::thread::sleep(std::time::Duration::from_millis(pause));
                i += 1;
            }
        })
    };
    let (mut ok, mut refused) = (0, 0);
    let began = std::time::Instant::now();
    while began.elapsed() < std::time::Duration::from_secs(3) {
        match photonmap::scene::load_scene(&file) {
            Ok(s) => {
                ok += 1;
                let radiance = match s.lights[0] {
                    photonmap::scene::Light::Area { radiance, .. } => radiance.x,
                    _ => unreachable!(),
                };
                let consistent = (s.name == "VERSION A" && radiance == 60.0)
                    || (s.name == "VERSION B" && radiance == 30.0);
                assert!(consistent, "a mixture: {} with radiance {radiance}", s.name);
            }
            Err(e) => {
                refused += 1;
                assert!(e.to_string().contains("scene.toml"), "{e}");
            }
        }
    }
    stop.store(true, std::sync::atomic::Ordering::Relaxed);
    writer.join().unwrap();
    eprintln!("{ok} loads, {refused} refused while the file changed");
    assert!(ok > 0, "no load succeeded");
}
