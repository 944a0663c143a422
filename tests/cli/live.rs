//! The image in progress: `--display-server` speaks tev's protocol to a
//! listener on 127.0.0.1 that decodes every packet, and the last image it
//! builds equals the EXR written; `--write-partial` ends as the finished
//! image. A viewer that is not there, or that hangs up, changes nothing.

use std::io::Read;
use std::net::{TcpListener, TcpStream};
use std::path::Path;
use std::time::{Duration, Instant};

use crate::common::{Run, TempDir};

use photonmap::render::Image;

/// What a tev viewer was sent, decoded.
#[derive(Debug, Default)]
struct Received {
    /// CreateImage: name, width, height, channel names.
    created: Vec<(String, i32, i32, Vec<String>)>,
    /// The image as the updates left it, and the updates' tiles.
    image: Vec<[f32; 3]>,
    tiles: usize,
    /// Updates that covered the whole image (a crop's outline, if one was
    /// drawn), one per image sent.
    images: usize,
    /// VectorGraphics: the outline's corners, as drawn.
    outline: Vec<(f32, f32)>,
}

fn take<const N: usize>(b: &mut &[u8]) -> [u8; N] {
    let (head, rest) = b.split_at(N);
    *b = rest;
    head.try_into().unwrap()
}

fn string(b: &mut &[u8]) -> String {
    let end = b
        .iter()
        .position(|&c| c == 0)
        .expect("a string ends in a zero byte");
    let s = String::from_utf8(b[..end].to_vec()).unwrap();
    *b = &b[end + 1..];
    s
}

fn i32_of(b: &mut &[u8]) -> i32 {
    i32::from_le_bytes(take(b))
}

/// Decodes the byte stream packet by packet (tev's `include/tev/Ipc.h`).
fn decode(mut stream: &[u8]) -> Received {
    let mut r = Received::default();
    let mut covered = 0usize;
    while !stream.is_empty() {
        let length = u32::from_le_bytes(take(&mut stream)) as usize;
        let (packet, rest) = stream.split_at(length - 4);
        stream = rest;
        let mut p = packet;
        let [kind] = take(&mut p);
        let [_grab_focus] = take(&mut p);
        let name = string(&mut p);
        match kind {
            4 => {
                let (w, h, n) = (i32_of(&mut p), i32_of(&mut p), i32_of(&mut p));
                let channels = (0..n).map(|_| string(&mut p)).collect();
                r.created.push((name, w, h, channels));
                r.image = vec![[f32::NAN; 3]; (w * h) as usize];
            }
            6 => {
                let n = i32_of(&mut p) as usize;
                let channels: Vec<String> = (0..n).map(|_| string(&mut p)).collect();
                assert_eq!(channels, ["R", "G", "B"]);
                let (x0, y0, w, h) = (
                    i32_of(&mut p),
                    i32_of(&mut p),
                    i32_of(&mut p),
                    i32_of(&mut p),
                );
                let offsets: Vec<i64> = (0..n).map(|_| i64::from_le_bytes(take(&mut p))).collect();
                let strides: Vec<i64> = (0..n).map(|_| i64::from_le_bytes(take(&mut p))).collect();
                let data: Vec<f32> = p
                    .chunks_exact(4)
                    .map(|c| f32::from_le_bytes(c.try_into().unwrap()))
                    .collect();
                assert_eq!(data.len(), (w * h) as usize * n, "the tile's data");
                let width = r.created.last().expect("CreateImage comes first").1;
                for y in 0..h {
                    for x in 0..w {
                        let t = (y * w + x) as i64;
                        let px = &mut r.image[((y0 + y) * width + x0 + x) as usize];
                        for c in 0..n {
                            px[c] = data[(offsets[c] + t * strides[c]) as usize];
                        }
                    }
                }
                r.tiles += 1;
                covered += (w * h) as usize;
                let whole = match r.outline.as_slice() {
                    [(x0, y0), _, (x1, y1), ..] => ((x1 - x0) * (y1 - y0)) as usize,
                    _ => r.image.len(),
                };
                if covered >= whole {
                    r.images += 1;
                    covered = 0;
                }
                p = &[];
            }
            8 => {
                let [append] = take(&mut p);
                assert_eq!(append, 0, "the outline replaces what was drawn");
                let n = i32_of(&mut p);
                let f = |p: &mut &[u8]| f32::from_le_bytes(take(p));
                let mut kinds = Vec::new();
                for _ in 0..n {
                    let [kind] = take(&mut p);
                    kinds.push(kind);
                    match kind {
                        10 | 11 => r.outline.push((f(&mut p), f(&mut p))),
                        4 => {
                            let rgba = [f(&mut p), f(&mut p), f(&mut p), f(&mut p)];
                            assert!(rgba.iter().all(|c| (0.0..=1.0).contains(c)));
                        }
                        5..=7 => {}
                        other => panic!("vector graphics command {other}"),
                    }
                }
                assert_eq!(kinds, [6, 10, 11, 11, 11, 7, 4, 5]);
            }
            other => panic!("packet type {other}: not one photonmap sends"),
        }
        assert!(p.is_empty(), "packet {kind}: {} bytes left over", p.len());
    }
    r
}

/// A listener on 127.0.0.1 that takes one connection and reads it to its
/// end (`hang_up`: reads the first bytes, then closes it and stops listening).
fn listen(hang_up: bool) -> (u16, std::thread::JoinHandle<Vec<u8>>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let port = listener.local_addr().unwrap().port();
    listener.set_nonblocking(true).unwrap();
    let thread = std::thread::spawn(move || {
        let deadline = Instant::now() + Duration::from_secs(300);
        let mut stream: TcpStream = loop {
            match listener.accept() {
                Ok((s, _)) => break s,
                Err(_) if Instant::now() < deadline => {
                    std::thread::sleep(Duration::from_millis(10))
                }
                Err(e) => panic!("no connection came: {e}"),
            }
        };
        stream.set_nonblocking(false).unwrap();
        let mut bytes = Vec::new();
        if hang_up {
            let mut first = [0u8; 16];
            stream.read_exact(&mut first).unwrap();
            bytes.extend(first);
        } else {
            stream.read_to_end(&mut bytes).unwrap();
        }
        bytes
    });
    (port, thread)
}

/// The one-shot estimate and SPPM, each streamed to a listener: the viewer
/// is told the image's name ("scene (pid)") and size once, gets the finished
/// image (and running ones as the sender keeps up), and what it last holds is the
/// EXR written, bit for bit; so is `--write-partial`'s file, whose header no
/// longer says partial.
#[test]
fn a_render_streams_to_a_tev_listener_and_ends_on_the_written_image() {
    let d = TempDir::new("live");
    for method in ["paper", "sppm"] {
        let (port, listener) = listen(false);
        let (exr, partial) = (
            d.join(format!("{method}.exr")),
            d.join(format!("{method}.partial.exr")),
        );
        let mut child = Run::new([
            "render", "ring", "--quiet", "--width", "32", "--height", "24",
        ])
        .args(["--method", method, "--display-server"])
        .arg(format!("127.0.0.1:{port}"))
        .writing("--write-partial", &partial)
        .output_to(&exr)
        .args(if method == "sppm" {
            &["--iterations", "8"][..]
        } else {
            &[][..]
        })
        .spawn();
        let pid = child.id();
        let status = child.wait().unwrap();
        assert!(status.success(), "{method}: {status}");
        let got = decode(&listener.join().unwrap());
        assert_eq!(
            got.created,
            [(
                format!("RING ({pid})"),
                32,
                24,
                vec!["R".into(), "G".into(), "B".into()]
            )],
            "{method}"
        );
        // Running images are sent as the sender keeps up (the slot holds the
        // newest only), so under load the finished image may be the one.
        assert!(got.images >= 1, "{method}: {} images sent", got.images);
        let written = Image::read_exr(&exr).unwrap();
        assert_eq!(
            got.image, written.pixels,
            "{method}: the viewer's last image"
        );
        assert_eq!(Image::read_exr(&partial).unwrap(), written, "{method}");
        let header = Image::exr_attributes(&partial).unwrap();
        assert!(header.iter().all(|(k, _)| k != "partial"), "{header:?}");
        if method == "sppm" {
            // The output's header records the iterations and photons emitted.
            let out = Image::exr_attributes(&exr).unwrap();
            let p: serde_json::Value = serde_json::from_str(&out[0].1).unwrap();
            assert_eq!(p["iterations"], 8, "{p}");
            assert!(p["photons_emitted"].as_u64().unwrap() > 0, "{p}");
        }
        println!("{method}: {} images in {} tiles", got.images, got.tiles);
    }
}

/// A crop is shown in place: the viewer's image is the frame's size, the
/// crop's pixels land where they belong (the written EXR, bit for bit) and
/// an outline marks them; nothing else is sent.
#[test]
fn a_crop_streams_into_its_place_in_the_frame() {
    let d = TempDir::new("live-crop");
    let (port, listener) = listen(false);
    let exr = d.join("crop.exr");
    let status = Run::new([
        "render", "ring", "--quiet", "--width", "32", "--height", "24",
    ])
    .args(["--pixel-bounds", "5", "21", "3", "15", "--display-server"])
    .arg(format!("127.0.0.1:{port}"))
    .output_to(&exr)
    .spawn()
    .wait()
    .unwrap();
    assert!(status.success(), "{status}");
    let got = decode(&listener.join().unwrap());
    assert_eq!((got.created[0].1, got.created[0].2), (32, 24));
    assert_eq!(
        got.outline,
        [(5.0, 3.0), (21.0, 3.0), (21.0, 15.0), (5.0, 15.0)]
    );
    assert!(got.images >= 1, "{} images", got.images);
    let written = Image::read_exr(&exr).unwrap();
    for (i, px) in got.image.iter().enumerate() {
        let (x, y) = (i as u32 % 32, i as u32 / 32);
        if (5..21).contains(&x) && (3..15).contains(&y) {
            assert_eq!(*px, written.get(x - 5, y - 3), "pixel {x}, {y}");
        } else {
            assert!(px.iter().all(|c| c.is_nan()), "pixel {x}, {y} was sent");
        }
    }
}

/// No viewer at the address, and one that hangs up after its first bytes:
/// the render finishes and writes the same image as without the switch.
#[test]
fn a_viewer_that_is_absent_or_hangs_up_changes_nothing() {
    let d = TempDir::new("live-absent");
    let render = |name: &str, extra: &[String]| {
        let out = d.join(name);
        Run::new([
            "render", "ring", "--quiet", "--width", "32", "--height", "24",
        ])
        .args(extra)
        .output_to(&out)
        .succeeds();
        Image::read_exr(&out).unwrap()
    };
    let plain = render("plain.exr", &[]);
    let free = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap()
        .port();
    let absent = render(
        "absent.exr",
        &["--display-server".into(), format!("127.0.0.1:{free}")],
    );
    assert_eq!(absent, plain);
    let (port, listener) = listen(true);
    let hung_up = render(
        "hung-up.exr",
        &["--display-server".into(), format!("127.0.0.1:{port}")],
    );
    assert_eq!(listener.join().unwrap().len(), 16);
    assert_eq!(hung_up, plain);
}

/// Bad addresses and partial files are refused before any work, writing nothing.
#[test]
fn bad_live_outputs_are_refused() {
    let d = TempDir::new("live-bad");
    let refused = |args: &[&str], says: &str| {
        Run::new(["render", "ring", "--quiet", "--width", "8", "--height", "8"])
            .args(args)
            .output_to(d.join("bad.png"))
            .refused_with(says);
    };
    refused(&["--display-server", "localhost"], "HOST:PORT");
    refused(&["--display-server", "localhost:99999"], "1..=65535");
    refused(&["--display-server", "localhost:0"], "1..=65535");
    refused(&["--on-signal", "write-partial"], "give an .exr output");
    let png = d.join("partial.png");
    refused(
        &["--write-partial", png.to_str().unwrap()],
        "must end in .exr",
    );
    assert!(!png.exists());
}

/// SIGTERM (as Slurm sends at a time limit) stops a long SPPM render:
/// the outputs are not written, and the partial EXR holds the last image in
/// progress, marked partial in its header.
#[test]
fn a_stopped_render_leaves_its_partial_image_marked_partial() {
    let d = TempDir::new("live-term");
    let (exr, partial) = (d.join("out.exr"), d.join("partial.exr"));
    let child = Run::new([
        "render", "ring", "--quiet", "--width", "32", "--height", "24",
    ])
    .args(["--method", "sppm", "--iterations", "1000000"])
    .writing("--write-partial", &partial)
    .output_to(&exr)
    .spawn();
    assert_eq!(terminate_once_under_way(child, &partial), Some(143));
    assert!(!exr.exists());
    let image = Image::read_exr(&partial).unwrap();
    assert_eq!((image.width, image.height), (32, 24));
    let header = Image::exr_attributes(&partial).unwrap();
    assert!(
        header.contains(&("partial".into(), "true".into())),
        "{header:?}"
    );
}

/// Waits for `partial` to appear (the render is under way), lets the render
/// run a little longer, then stops it with SIGTERM; returns its exit code.
fn terminate_once_under_way(mut child: std::process::Child, partial: &Path) -> Option<i32> {
    let deadline = Instant::now() + Duration::from_secs(300);
    while !partial.exists() {
        assert!(Instant::now() < deadline, "no partial image came");
        assert!(
            child.try_wait().unwrap().is_none(),
            "the render ended early"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(1500));
    let killed = std::process::Command::new("kill")
        .args(["-TERM", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(killed.success());
    child.wait().unwrap().code()
}

/// `--on-signal write-partial`: SIGTERM writes the eye samples (SPPM: the
/// iterations) done to the EXR output, marked partial with their count,
/// which `merge --passes` then weighs by that count.
#[test]
fn a_signal_writes_the_work_done_when_asked() {
    let d = TempDir::new("live-on-signal");
    for (method, limit, count_field) in [
        ("paper", ["--spp", "1024"], "spp"),
        ("sppm", ["--iterations", "1000000"], "iterations"),
    ] {
        let (exr, partial) = (
            d.join(format!("{method}.exr")),
            d.join(format!("{method}.partial.exr")),
        );
        let child = Run::new([
            "render", "ring", "--quiet", "--width", "32", "--height", "24",
        ])
        .args(["--method", method, "--on-signal", "write-partial"])
        .args(limit)
        .writing("--write-partial", &partial)
        .output_to(&exr)
        .spawn();
        assert_eq!(terminate_once_under_way(child, &partial), Some(143));
        let header = Image::exr_attributes(&exr).unwrap();
        assert!(
            header.contains(&("partial".into(), "true".into())),
            "{header:?}"
        );
        let done: u32 = header
            .iter()
            .find(|(k, _)| k == "photonmap.samples_done")
            .map(|(_, v)| v.parse().unwrap())
            .unwrap_or_else(|| panic!("{method}: no count in {header:?}"));
        assert!((1..1024).contains(&done), "{method}: {done}");
        let provenance = header
            .iter()
            .find(|(k, _)| k == "photonmap.provenance")
            .map(|(_, v)| serde_json::from_str::<serde_json::Value>(v).unwrap())
            .unwrap();
        assert_eq!(provenance[count_field], done, "{method}");
        let image = Image::read_exr(&exr).unwrap();
        assert!(image.pixels.iter().flatten().any(|c| *c > 0.0), "{method}");
    }
    // A one-shot pass stopped at k samples merges with a whole one, weighed k.
    let whole = d.join("whole.exr");
    Run::new([
        "render", "ring", "--quiet", "--width", "32", "--height", "24", "--spp", "2",
    ])
    .args(["--seed", "2"])
    .output_to(&whole)
    .succeeds();
    let merged = d.join("merged.exr");
    let report = Run::new(["merge", "--passes", "--json"])
        .writing_arg(&merged)
        .args([d.join("paper.exr"), whole])
        .json();
    let weights = report["weights"].as_array().unwrap();
    assert!(weights[0].as_f64().unwrap() >= 1.0, "{report}");
    assert_eq!(weights[1], 2.0, "{report}");
}
