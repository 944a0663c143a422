//! `render`'s output files: by extension, several at once, with provenance;
//! written all or nothing, so an output that cannot be written, or a full
//! disk, leaves no partial file and the previous output intact; and every
//! command's outputs take the mode the umask gives a new file.

use std::process::Command;

use crate::common::{assert_output_modes, root, Printed, Run, TempDir};

use photonmap::render::Image;

/// Outputs by extension, several at once; the EXR carries the provenance.
#[test]
fn outputs_by_extension_all_at_once_with_provenance() {
    let d = TempDir::new("outputs");
    let (png, exr, pfm) = (d.join("a.png"), d.join("a.exr"), d.join("a.pfm"));
    let out = Run::new(["render", "ring", "--quiet", "--json", "--width", "32"])
        .args(["--height", "24", "--set", "photon_map.k=8"])
        .output_to(&png)
        .output_to(&exr)
        .output_to(&pfm)
        .succeeds();
    let linear = Image::read_exr(&exr).unwrap();
    assert_eq!((linear.width, linear.height), (32, 24));
    assert!(image::open(&png).is_ok());
    let pfm_bytes = std::fs::read(&pfm).unwrap();
    assert!(pfm_bytes.starts_with(b"PF\n32 24\n-1.0\n"));
    assert_eq!(pfm_bytes.len(), "PF\n32 24\n-1.0\n".len() + 32 * 24 * 12);
    let header = Image::exr_attributes(&exr).unwrap();
    assert_eq!(header.len(), 1, "{header:?}");
    assert_eq!(header[0].0, "photonmap.provenance");
    let h: serde_json::Value = serde_json::from_str(&header[0].1).unwrap();
    assert_eq!(h["scene"], "ring");
    assert_eq!(h["overrides"][0], "photon_map.k=8");
    // The photons behind the map (RING traces to its stored count).
    assert!(h["photons_emitted"].as_u64().unwrap() > 0, "{h}");
    assert!(h["renderer"].as_str().unwrap().contains("llvmpipe"));
    let v = out.json();
    assert_eq!(v["provenance"]["overrides"][0], "photon_map.k=8");
    assert_eq!(v["provenance"]["seed"], 1);
    assert_eq!(v["outputs"].as_array().unwrap().len(), 3);
    assert!(v["provenance"]["scene_hash"].as_str().unwrap().len() == 16);
    // `-o x.exr` alone works, and --set changes the image.
    let plain = d.join("plain.exr");
    Run::new([
        "render", "ring", "--quiet", "--width", "32", "--height", "24",
    ])
    .output_to(&plain)
    .succeeds();
    assert_ne!(
        Image::read_exr(&plain).unwrap(),
        linear,
        "--set photon_map.k=8 changed nothing"
    );
    // A bad override is refused like a bad file, naming the override.
    let err = Run::new(["render", "ring", "--set", "photon_map.k=0"])
        .output_to(d.join("bad.png"))
        .refused_with("--set photon_map.k");
    assert!(err.contains("1..=4096"), "{err}");
}

/// The leftover-file cases: an output that cannot be written is found before
/// rendering and nothing at all is written (not even the other outputs).
#[test]
fn an_output_that_cannot_be_written_leaves_nothing() {
    let d = TempDir::new("leftover");
    std::fs::create_dir_all(d.join("isdir.exr")).unwrap();
    Run::new([
        "render", "ring", "--quiet", "--width", "16", "--height", "12",
    ])
    .output_to(d.join("ok.png"))
    .writing("--exr", d.join("isdir.exr"))
    .refused_with("isdir.exr");
    assert!(!d.join("ok.png").exists(), "ok.png was left behind");
    // A folder that takes no new file: refused before any rendering.
    let ro = d.join("read-only");
    std::fs::create_dir_all(&ro).unwrap();
    let mut perms = std::fs::metadata(&ro).unwrap().permissions();
    perms.set_readonly(true);
    std::fs::set_permissions(&ro, perms).unwrap();
    let root = std::fs::File::create(ro.join("probe")).is_ok(); // root ignores the mode
    if !root {
        let out = Run::new(["render", "ring", "--quiet"])
            .output_to(ro.join("x.png"))
            .output_to(d.join("y.png"))
            .run();
        assert!(!out.status.success());
        assert!(!d.join("y.png").exists());
    }
    let entries: Vec<_> = std::fs::read_dir(&d)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    assert_eq!(entries.len(), 2, "only the two folders: {entries:?}");
}

/// A full disk while writing: on a tiny tmpfs (where root may mount one) the
/// write fails with a clear error, leaves no partial file, and the previous
/// output stays intact.
#[test]
fn a_full_disk_leaves_no_partial_file_and_keeps_the_previous_output() {
    let d = TempDir::new("fulldisk");
    let mnt = d.join("tiny");
    std::fs::create_dir_all(&mnt).unwrap();
    let mounted = Command::new("mount")
        .args(["-t", "tmpfs", "-o", "size=48k", "tmpfs"])
        .arg(&mnt)
        .status()
        .is_ok_and(|s| s.success());
    if !mounted {
        // The failing-writer unit test (photonmap::image) covers the same path.
        eprintln!("no tmpfs could be mounted here: the full-disk case is the unit test's");
        return;
    }
    let previous = b"previous output";
    std::fs::write(mnt.join("big.exr"), previous).unwrap();
    let out = Run::new([
        "render", "ring", "--quiet", "--width", "160", "--height", "120",
    ])
    .output_to(mnt.join("big.exr"))
    .run();
    let err = out.stderr_text();
    let left: Vec<_> = std::fs::read_dir(&mnt)
        .unwrap()
        .flatten()
        .map(|e| e.file_name())
        .collect();
    let kept = std::fs::read(mnt.join("big.exr")).unwrap();
    let _ = Command::new("umount").arg(&mnt).status();
    assert!(
        !out.status.success(),
        "a 160 x 120 float image fit in 48 KiB?"
    );
    assert!(err.contains("No space left"), "{err}");
    assert_eq!(left.len(), 1, "{left:?}");
    assert_eq!(kept, previous);
}

/// Under umask 022 every output is 0644, under 077 it is 0600, as
/// `File::create` makes them, though each is written through a temporary
/// file (made 0600) and renamed: `render` (PNG, EXR, PFM, a replaced output
/// made 0600 before), `convert`, `compare` (difference image, JUnit, HTML),
/// `merge --passes` and `convert-scene`. The other commands' tests check
/// theirs (`tables`, `bench`, `reference`, `regress`).
#[test]
fn outputs_take_the_mode_the_umask_gives() {
    for umask in [0o022, 0o077] {
        let d = TempDir::new(&format!("umask{umask:03o}"));
        let out = |name: &str| d.join(format!("out/{name}"));
        std::fs::create_dir_all(d.join("out")).unwrap();
        // An output there before, private: the new one takes the umask's mode.
        std::fs::write(out("a.png"), b"before").unwrap();
        {
            use std::os::unix::fs::PermissionsExt;
            let private = std::fs::Permissions::from_mode(0o600);
            std::fs::set_permissions(out("a.png"), private).unwrap();
        }
        for (seed, name) in [("1", "a"), ("2", "b")] {
            Run::new([
                "render", "ring", "--quiet", "--width", "16", "--height", "12",
            ])
            .args(["--seed", seed])
            .output_to(out(&format!("{name}.png")))
            .output_to(out(&format!("{name}.exr")))
            .output_to(out(&format!("{name}.pfm")))
            .umask(umask)
            .succeeds();
        }
        Run::new(["convert"])
            .arg(out("a.exr"))
            .writing_arg(out("converted.png"))
            .umask(umask)
            .succeeds();
        Run::new(["compare"])
            .arg(out("a.exr"))
            .arg(out("b.exr"))
            .writing("--diff", out("diff.png"))
            .writing("--junit", out("compare.xml"))
            .writing("--html", out("compare.html"))
            .umask(umask)
            .succeeds();
        Run::new(["merge", "--passes"])
            .writing_arg(out("merged.exr"))
            .arg(out("a.exr"))
            .arg(out("b.exr"))
            .umask(umask)
            .succeeds();
        Run::new(["convert-scene"])
            .arg(root().join("scenes/tests/import/cornell_box.pbrt"))
            .writing_arg(out("cornell.toml"))
            .umask(umask)
            .succeeds();
        let files = assert_output_modes(&d.join("out"), umask);
        assert!(files >= 12, "{files} files checked");
    }
}
