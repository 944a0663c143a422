//! `--display-server HOST:PORT`: the running image sent to the tev HDR
//! viewer over its TCP protocol (tev's `include/tev/Ipc.h`), as pbrt-v4's
//! `--display-server` does. Each packet is a little-endian u32 length (the
//! whole packet's, itself included), a one-byte type, then its fields;
//! strings end in a zero byte. photonmap sends:
//! - CreateImage (4): grab focus, name, width, height, channel count, the
//!   channel names R, G, B;
//! - UpdateImage v3 (6): grab focus, name, channel count, the channel names,
//!   x, y, width, height of a tile, an i64 offset and an i64 stride per
//!   channel into the tile's f32 data (here interleaved RGB: offsets 0, 1, 2,
//!   strides 3), then the data, row 0 at the top;
//! - VectorGraphics (8), for a crop only: grab focus, name, append (0), the
//!   command count, then each command's one-byte type and its f32s: the
//!   crop's outline as BeginPath (6), MoveTo (10) and three LineTo (11) to
//!   its corners, ClosePath (7), StrokeColor (4, RGBA) and Stroke (5).
//!
//! A crop's image is created at the frame's size and its tiles are placed at
//! the crop, so tiles of one frame sent to one viewer sit where they belong.
//!
//! The render never waits for the viewer: images go to a slot that holds
//! only the latest one, and a thread of its own sends it. A viewer that is
//! not there is tried again at most once a second (an image it missed is
//! kept for the next try); one that goes away is dropped quietly and tried
//! again on a later image; connecting and writing time out. When the render
//! ends the last image is sent, and the render waits for that at most
//! `FINISH_TIMEOUT` before it leaves the thread behind.

use std::io::Write;
use std::net::{SocketAddr, TcpStream, ToSocketAddrs};
use std::sync::{Arc, Condvar, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use photonmap::image::Image;

/// tev's packet types (tev's `IpcPacket::EType`).
const CREATE_IMAGE: u8 = 4;
const UPDATE_IMAGE_V3: u8 = 6;
const VECTOR_GRAPHICS: u8 = 8;
/// tev's vector graphics commands (tev's `VgCommand::EType`).
const VG_STROKE_COLOR: u8 = 4;
const VG_STROKE: u8 = 5;
const VG_BEGIN_PATH: u8 = 6;
const VG_CLOSE_PATH: u8 = 7;
const VG_MOVE_TO: u8 = 10;
const VG_LINE_TO: u8 = 11;
/// Tiles of an update, at most this many pixels a side (tev's own Python
/// client's size, which keeps each packet small).
const TILE: u32 = 128;
const CONNECT_TIMEOUT: Duration = Duration::from_secs(1);
const WRITE_TIMEOUT: Duration = Duration::from_secs(2);
/// The shortest wait between two tries to reach a viewer that was not there.
const RETRY: Duration = Duration::from_secs(1);
/// The longest a finished render waits for its last image to go out.
const FINISH_TIMEOUT: Duration = Duration::from_secs(5);

/// A `--display-server` address, checked when the command line is read.
pub fn parse_address(s: &str) -> Result<String, String> {
    let (host, port) = s
        .rsplit_once(':')
        .ok_or_else(|| format!("{s}: give HOST:PORT, for example localhost:14158"))?;
    if host.is_empty() {
        return Err(format!("{s}: the host is empty; give HOST:PORT"));
    }
    match port.parse::<u16>() {
        Ok(p) if p > 0 => {}
        _ => return Err(format!("{s}: the port must be a whole number in 1..=65535")),
    }
    Ok(s.to_string())
}

/// The viewer's name of a render's image: "scene (pid)".
pub fn image_name(scene: &str) -> String {
    format!("{scene} ({})", std::process::id())
}

/// Where the images sit in the viewer's image: a crop's first pixel
/// (column, row from the top) and the frame's size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Placement {
    pub origin: (u32, u32),
    pub frame: (u32, u32),
}

#[derive(Default)]
struct Slot {
    latest: Option<Image>,
    closing: bool,
}

struct Shared {
    slot: Mutex<Slot>,
    wake: Condvar,
}

/// A tev viewer the render's images are sent to, from a thread of its own.
pub struct DisplayServer {
    shared: Arc<Shared>,
    thread: Option<JoinHandle<()>>,
    /// Says when the thread has ended.
    ended: Option<std::sync::mpsc::Receiver<()>>,
}

impl DisplayServer {
    pub fn start(address: &str, name: String, placement: Option<Placement>) -> Self {
        let shared = Arc::new(Shared {
            slot: Mutex::new(Slot::default()),
            wake: Condvar::new(),
        });
        let (s, address) = (shared.clone(), address.to_string());
        let (tell, ended) = std::sync::mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("display-server".into())
            .spawn(move || {
                Sender::new(address, name, placement).run(&s);
                let _ = tell.send(());
            })
            .ok();
        Self {
            shared,
            thread,
            ended: Some(ended),
        }
    }

    /// Queues `image`, replacing one not yet sent; never waits for the viewer.
    pub fn show(&self, image: &Image) {
        if let Ok(mut slot) = self.shared.slot.lock() {
            slot.latest = Some(image.clone());
            self.shared.wake.notify_one();
        }
    }

    /// Sends what is queued, then stops the thread; waits for it at most
    /// `FINISH_TIMEOUT` (a viewer that reads too slowly is left behind).
    pub fn finish(&mut self) {
        if let Ok(mut slot) = self.shared.slot.lock() {
            slot.closing = true;
            self.shared.wake.notify_one();
        }
        let ended = self.ended.take();
        if let Some(t) = self.thread.take() {
            if ended.is_some_and(|e| e.recv_timeout(FINISH_TIMEOUT).is_ok()) {
                let _ = t.join();
            }
        }
    }
}

impl Drop for DisplayServer {
    fn drop(&mut self) {
        self.finish();
    }
}

/// The thread's side: the connection and what the viewer has been told.
struct Sender {
    address: String,
    name: String,
    placement: Option<Placement>,
    stream: Option<TcpStream>,
    /// The size of the image created on the viewer over this connection.
    created: Option<(u32, u32)>,
    last_try: Option<Instant>,
    /// An image the viewer missed while it was not there.
    missed: Option<Image>,
}

impl Sender {
    fn new(address: String, name: String, placement: Option<Placement>) -> Self {
        Self {
            address,
            name,
            placement,
            stream: None,
            created: None,
            last_try: None,
            missed: None,
        }
    }

    fn run(mut self, shared: &Shared) {
        loop {
            let (image, closing) = {
                let Ok(mut slot) = shared.slot.lock() else {
                    return;
                };
                while slot.latest.is_none() && !slot.closing {
                    slot = match shared.wake.wait(slot) {
                        Ok(s) => s,
                        Err(_) => return,
                    };
                }
                (slot.latest.take(), slot.closing)
            };
            if let Some(image) = image.or_else(|| self.missed.take().filter(|_| closing)) {
                self.send(image, closing);
            }
            if closing {
                return;
            }
        }
    }

    fn send(&mut self, image: Image, last: bool) {
        if self.stream.is_none() {
            let due = self.last_try.is_none_or(|t| t.elapsed() >= RETRY);
            if !(due || last) {
                self.missed = Some(image);
                return;
            }
            self.last_try = Some(Instant::now());
            self.stream = connect(&self.address);
            self.created = None;
        }
        let Some(stream) = &mut self.stream else {
            self.missed = Some(image);
            return;
        };
        let (origin, size) = match self.placement {
            Some(p) => (p.origin, p.frame),
            None => ((0, 0), (image.width, image.height)),
        };
        let mut sent = Ok(());
        if self.created != Some(size) {
            sent = stream.write_all(&create_image(&self.name, size.0, size.1));
            if self.placement.is_some() {
                let outline = outline(&self.name, origin, (image.width, image.height));
                sent = sent.and_then(|_| stream.write_all(&outline));
            }
            self.created = Some(size);
        }
        for packet in update_image(&self.name, &image, origin) {
            if sent.is_err() {
                break;
            }
            sent = stream.write_all(&packet);
        }
        if sent.and_then(|_| stream.flush()).is_err() {
            self.stream = None;
            self.missed = Some(image);
        }
    }
}

fn connect(address: &str) -> Option<TcpStream> {
    let addrs: Vec<SocketAddr> = address.to_socket_addrs().ok()?.collect();
    let stream = addrs
        .iter()
        .find_map(|a| TcpStream::connect_timeout(a, CONNECT_TIMEOUT).ok())?;
    stream.set_write_timeout(Some(WRITE_TIMEOUT)).ok()?;
    let _ = stream.set_nodelay(true);
    Some(stream)
}

/// A packet under construction: its length is patched in at the end.
struct Packet(Vec<u8>);

impl Packet {
    fn new(kind: u8) -> Self {
        let mut bytes = vec![0; 4];
        bytes.push(kind);
        Self(bytes)
    }
    fn byte(&mut self, b: u8) -> &mut Self {
        self.0.push(b);
        self
    }
    fn string(&mut self, s: &str) -> &mut Self {
        // A zero byte would end the string early: tev's names have none.
        self.0.extend(s.bytes().filter(|&b| b != 0));
        self.0.push(0);
        self
    }
    fn i32(&mut self, v: i32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn i64(&mut self, v: i64) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn f32(&mut self, v: f32) -> &mut Self {
        self.0.extend(v.to_le_bytes());
        self
    }
    fn done(mut self) -> Vec<u8> {
        let n = self.0.len() as u32;
        self.0[..4].copy_from_slice(&n.to_le_bytes());
        self.0
    }
}

const CHANNELS: [&str; 3] = ["R", "G", "B"];

fn create_image(name: &str, width: u32, height: u32) -> Vec<u8> {
    let mut p = Packet::new(CREATE_IMAGE);
    p.byte(0).string(name);
    p.i32(width as i32)
        .i32(height as i32)
        .i32(CHANNELS.len() as i32);
    for c in CHANNELS {
        p.string(c);
    }
    p.done()
}

/// The outline of the `size` pixels at `origin`, as VectorGraphics.
fn outline(name: &str, origin: (u32, u32), size: (u32, u32)) -> Vec<u8> {
    let (x0, y0) = (origin.0 as f32, origin.1 as f32);
    let (x1, y1) = (x0 + size.0 as f32, y0 + size.1 as f32);
    let mut p = Packet::new(VECTOR_GRAPHICS);
    p.byte(0).string(name).byte(0).i32(8);
    p.byte(VG_BEGIN_PATH);
    p.byte(VG_MOVE_TO).f32(x0).f32(y0);
    for (x, y) in [(x1, y0), (x1, y1), (x0, y1)] {
        p.byte(VG_LINE_TO).f32(x).f32(y);
    }
    p.byte(VG_CLOSE_PATH);
    p.byte(VG_STROKE_COLOR).f32(1.0).f32(0.6).f32(0.0).f32(1.0);
    p.byte(VG_STROKE);
    p.done()
}

/// The image as UpdateImage v3 packets, a tile each, placed at `origin`.
fn update_image(name: &str, image: &Image, origin: (u32, u32)) -> Vec<Vec<u8>> {
    let mut packets = Vec::new();
    for y0 in (0..image.height).step_by(TILE as usize) {
        for x0 in (0..image.width).step_by(TILE as usize) {
            let (w, h) = (TILE.min(image.width - x0), TILE.min(image.height - y0));
            let mut p = Packet::new(UPDATE_IMAGE_V3);
            p.byte(0).string(name).i32(CHANNELS.len() as i32);
            for c in CHANNELS {
                p.string(c);
            }
            let (x, y) = (origin.0 + x0, origin.1 + y0);
            p.i32(x as i32).i32(y as i32).i32(w as i32).i32(h as i32);
            for offset in 0..CHANNELS.len() {
                p.i64(offset as i64);
            }
            for _ in CHANNELS {
                p.i64(CHANNELS.len() as i64);
            }
            for y in y0..y0 + h {
                for x in x0..x0 + w {
                    for v in image.get(x, y) {
                        p.f32(v);
                    }
                }
            }
            packets.push(p.done());
        }
    }
    packets
}
