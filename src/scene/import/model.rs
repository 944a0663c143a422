//! What an importer builds: the scene in world space, in f64, as photonmap
//! can render it (spheres, open cylinders, triangles, parallelograms,
//! parallelogram and point lights), and the TOML scene that says it. The
//! importers (pbrt, Mitsuba) fill a `Model`; `to_toml` writes it, with the
//! photon-map parameters that those formats do not carry derived from the
//! scene's bounds and lights (`derived_photon_map`).

use std::fmt::Write as _;
use std::path::Path;

use glam::DVec3;

use super::source::Cx;
use crate::error::SceneError;
use crate::scene::defaults::ALPHA_RANGE;

/// A material photonmap renders.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Mat {
    Diffuse([f64; 3]),
    Mirror([f64; 3]),
    Glass(f64),
    /// A metal: eta, k, tint, alpha (0: smooth), as the scene format's
    /// `conductor`.
    Conductor {
        eta: [f64; 3],
        k: [f64; 3],
        tint: [f64; 3],
        alpha: f64,
        /// Mitsuba's microfacet model (GGX or Beckmann, separable
        /// masking) rather than pbrt's.
        mitsuba: Option<Distribution>,
    },
}

/// Where an imported rough conductor's notes point: its file, its name
/// (`what`), the line of its second roughness (`uneven_line`, for
/// anisotropy) and of its roughness (`alpha_line`), and what the file calls
/// roughness (`name`: "roughness", "alpha").
pub struct RoughSource<'a> {
    pub file: &'a Path,
    pub what: &'a str,
    pub name: &'a str,
    pub uneven_line: usize,
    pub alpha_line: usize,
}

impl Mat {
    /// A conductor as the scene format takes it: eta and k within its
    /// range, and alpha isotropic (the larger of `u`, `v`) within
    /// ALPHA_RANGE, each change noted by `Cx::unsupported` (an error unless
    /// --lenient).
    pub fn conductor(
        cx: &mut Cx,
        at: &RoughSource,
        (eta, k, tint): ([f64; 3], [f64; 3], [f64; 3]),
        (u, v): (f64, f64),
        mitsuba: Option<Distribution>,
    ) -> Result<Mat, SceneError> {
        let mut alpha = u.max(v);
        if (u - v).abs() > 1e-6 * alpha {
            cx.unsupported(
                at.file,
                at.uneven_line,
                &format!("{} with anisotropic {}", at.what, at.name),
                &format!("isotropic alpha {alpha}"),
            )?;
        }
        let (lo, hi) = ALPHA_RANGE;
        if !(f64::from(lo)..=f64::from(hi)).contains(&alpha) {
            let instead = alpha.clamp(f64::from(lo), f64::from(hi));
            cx.unsupported(
                at.file,
                at.alpha_line,
                &format!("{} alpha {alpha} (outside [{lo}, {hi}])", at.what),
                &format!("alpha {instead}"),
            )?;
            alpha = instead;
        }
        Ok(Mat::Conductor {
            eta: eta.map(|x| x.clamp(1e-4, 100.0)),
            k: k.map(|x| x.clamp(0.0, 100.0)),
            tint,
            alpha,
            mitsuba,
        })
    }
}

/// A rough lobe's microfacet distribution, as Mitsuba names it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Distribution {
    Ggx,
    Beckmann,
}

/// A surface, in world space; `material` indexes `Model::materials`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Surface {
    Sphere {
        center: DVec3,
        radius: f64,
    },
    Cylinder {
        base: DVec3,
        axis: DVec3,
        radius: f64,
        height: f64,
    },
    Triangle([DVec3; 3]),
    Parallelogram {
        corner: DVec3,
        edge1: DVec3,
        edge2: DVec3,
    },
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Emitter {
    /// A one-sided parallelogram emitting `radiance` on the side of `normal`.
    Area {
        corner: DVec3,
        edge1: DVec3,
        edge2: DVec3,
        normal: DVec3,
        radiance: [f64; 3],
    },
    Point {
        position: DVec3,
        intensity: [f64; 3],
    },
}

/// The camera as the file placed it; `right` is the world direction the
/// image's x axis runs along (photonmap's is always view x up, so a camera
/// whose `right` is the other way is rendered by mirroring the world).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpec {
    pub eye: DVec3,
    pub dir: DVec3,
    pub up: DVec3,
    pub right: DVec3,
    pub vfov_degrees: f64,
    pub width: u32,
    pub height: u32,
}

/// Render settings a file carries that are command-line options in
/// photonmap (written into the TOML as comments).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Hints {
    pub spp: Option<u32>,
    pub max_depth: Option<u32>,
    /// `--method sppm` options: iterations, photons per iteration, radius.
    pub sppm: Option<(Option<u32>, Option<u32>, Option<f64>)>,
}

#[derive(Clone, Debug, Default)]
pub struct Model {
    pub name: String,
    /// The file the scene came from, for the header comment.
    pub source: String,
    pub camera: Option<CameraSpec>,
    pub materials: Vec<(String, Mat)>,
    pub surfaces: Vec<(Surface, usize)>,
    pub emitters: Vec<Emitter>,
    pub hints: Hints,
    /// One line per mapping `--lenient` made, or other remark.
    pub notes: Vec<String>,
    /// Triangles dropped for having no area.
    pub degenerate: usize,
}

impl Model {
    /// A sphere of `material`; an emitting one (`radiance`) is refused, or
    /// under --lenient becomes a point light of the same power at its centre.
    pub fn add_sphere(
        &mut self,
        cx: &mut Cx,
        (file, line, what): (&Path, usize, &str),
        (center, radius): (DVec3, f64),
        material: usize,
        radiance: Option<[f64; 3]>,
    ) -> Result<(), SceneError> {
        match radiance {
            Some(l) => {
                cx.unsupported(
                    file,
                    line,
                    &format!("{what} emitting"),
                    "a point light of the same power at its centre",
                )?;
                self.emitters.push(Emitter::Point {
                    position: center,
                    intensity: l.map(|x| std::f64::consts::PI * radius * radius * x),
                });
            }
            None => self
                .surfaces
                .push((Surface::Sphere { center, radius }, material)),
        }
        Ok(())
    }

    /// An empty model named after the scene file it is read from.
    pub fn for_file(path: &Path) -> Self {
        Model {
            name: path
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
            source: path.display().to_string(),
            ..Model::default()
        }
    }

    /// The index of a material, added under `name` (made unique) unless an
    /// equal one exists.
    pub fn material(&mut self, name: &str, m: Mat) -> usize {
        if let Some(i) = self.materials.iter().position(|(_, x)| *x == m) {
            return i;
        }
        let mut key = sanitize(name);
        let base = key.clone();
        let mut n = 1;
        while self.materials.iter().any(|(k, _)| *k == key) {
            n += 1;
            key = format!("{base}_{n}");
        }
        self.materials.push((key, m));
        self.materials.len() - 1
    }

    /// Adds a triangle unless it has no area.
    pub fn triangle(&mut self, v: [DVec3; 3], material: usize) {
        let (a, b) = (v[1] - v[0], v[2] - v[0]);
        let scale = a.length() * b.length();
        if !(scale > 0.0 && a.cross(b).length() > 1e-6 * scale && v.iter().all(|p| p.is_finite())) {
            self.degenerate += 1;
            return;
        }
        self.surfaces.push((Surface::Triangle(v), material));
    }

    /// Axis-aligned bounds of every surface, emitter and the camera's eye.
    pub fn bounds(&self) -> (DVec3, DVec3) {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        let mut add = |p: DVec3| {
            lo = lo.min(p);
            hi = hi.max(p);
        };
        for (s, _) in &self.surfaces {
            for p in surface_points(s) {
                add(p);
            }
        }
        for e in &self.emitters {
            match *e {
                Emitter::Area {
                    corner,
                    edge1,
                    edge2,
                    ..
                } => [
                    corner,
                    corner + edge1,
                    corner + edge2,
                    corner + edge1 + edge2,
                ]
                .into_iter()
                .for_each(&mut add),
                Emitter::Point { position, .. } => add(position),
            }
        }
        (lo, hi)
    }

    /// Surface area of every surface and area light.
    fn area(&self) -> f64 {
        use std::f64::consts::PI;
        let s: f64 = self
            .surfaces
            .iter()
            .map(|(s, _)| match *s {
                Surface::Sphere { radius, .. } => 4.0 * PI * radius * radius,
                Surface::Cylinder { radius, height, .. } => 2.0 * PI * radius * height,
                Surface::Triangle(v) => 0.5 * (v[1] - v[0]).cross(v[2] - v[0]).length(),
                Surface::Parallelogram { edge1, edge2, .. } => edge1.cross(edge2).length(),
            })
            .sum();
        let lights: f64 = self
            .emitters
            .iter()
            .map(|e| match *e {
                Emitter::Area { edge1, edge2, .. } => edge1.cross(edge2).length(),
                Emitter::Point { .. } => 0.0,
            })
            .sum();
        s + lights
    }
}

/// Points whose box bounds the surface.
fn surface_points(s: &Surface) -> Vec<DVec3> {
    match *s {
        Surface::Sphere { center, radius } => {
            vec![center - DVec3::splat(radius), center + DVec3::splat(radius)]
        }
        Surface::Cylinder {
            base,
            axis,
            radius,
            height,
        } => {
            let top = base + axis * height;
            let r = DVec3::splat(radius);
            vec![base - r, base + r, top - r, top + r]
        }
        Surface::Triangle(v) => v.to_vec(),
        Surface::Parallelogram {
            corner,
            edge1,
            edge2,
        } => vec![
            corner,
            corner + edge1,
            corner + edge2,
            corner + edge1 + edge2,
        ],
    }
}

/// A TOML bare key from a name: letters, digits, `_` and `-`; others `_`.
fn sanitize(name: &str) -> String {
    let s: String = name
        .chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '_' || c == '-' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if s.is_empty() {
        "material".into()
    } else {
        s
    }
}

/// The photon-map parameters a pbrt or Mitsuba file does not carry.
#[derive(Clone, Debug, PartialEq)]
pub struct DerivedPhotonMap {
    pub photons_stored: u32,
    pub k: u32,
    pub max_radius: f64,
    pub grid_resolution: [u32; 3],
}

/// Photons stored for the first light, for each other, and at most.
const PHOTONS_FIRST_LIGHT: u32 = 20_000;
const PHOTONS_PER_OTHER_LIGHT: u32 = 5_000;
const MAX_DERIVED_PHOTONS: u32 = 40_000;
/// Photons sought per estimate.
const DERIVED_K: u32 = 100;

/// The derivation (the book's import chapters state it): 20,000 stored
/// photons, 5,000 more for each light after the first (at most 40,000), k = 100, and a maximum radius of
/// twice the radius of a disc that holds k photons were they spread evenly
/// over all the scene's surface area A (r = 2 sqrt(k A / (pi N))), at most
/// a tenth of the scene's size; the grid's cells are about that radius on a
/// side along each axis of the bounds, 1 to 128 of them.
pub fn derived_photon_map(model: &Model) -> DerivedPhotonMap {
    let others = model.emitters.len().saturating_sub(1).min(64) as u32;
    let photons_stored =
        (PHOTONS_FIRST_LIGHT + PHOTONS_PER_OTHER_LIGHT * others).min(MAX_DERIVED_PHOTONS);
    let (lo, hi) = model.bounds();
    let extent = (hi - lo).max(DVec3::ZERO);
    let size = extent.max_element().max(1e-9);
    let area = model.area().max(1e-18);
    let spread = 2.0
        * (f64::from(DERIVED_K) * area / (std::f64::consts::PI * f64::from(photons_stored))).sqrt();
    let max_radius = spread.min(0.1 * size);
    let cells = |side: f64| ((side / max_radius).ceil() as u32).clamp(1, 128);
    DerivedPhotonMap {
        photons_stored,
        k: DERIVED_K,
        max_radius,
        grid_resolution: [cells(extent.x), cells(extent.y), cells(extent.z)],
    }
}

/// The reflection that makes the camera's image right equal photonmap's
/// (view x up): None when it already does; else the plane's point and normal.
fn mirror_of(c: &CameraSpec) -> Option<(DVec3, DVec3)> {
    let ours = c.dir.cross(c.up);
    (c.right.dot(ours) < 0.0).then(|| (c.eye, ours.normalize()))
}

/// How far along the view the written `look_at` stands: the scene's size
/// (a power of two, so the sum stays exact where it can), so that the
/// direction keeps its precision after the loader rounds both points to f32.
fn look_distance(model: &Model) -> f64 {
    let (lo, hi) = model.bounds();
    let size = (hi - lo).max_element();
    if size.is_finite() && size > 0.0 {
        2f64.powi(size.log2().ceil() as i32)
    } else {
        1.0
    }
}

/// Writes the TOML scene (with the derivations and hints as comments).
pub fn to_toml(model: &Model) -> String {
    let camera = model.camera.expect("importers check the camera");
    let mirror = mirror_of(&camera);
    let p = |v: DVec3| match mirror {
        Some((o, n)) => fmt_v(v - 2.0 * (v - o).dot(n) * n),
        None => fmt_v(v),
    };
    let d = |v: DVec3| match mirror {
        Some((_, n)) => fmt_v(v - 2.0 * v.dot(n) * n),
        None => fmt_v(v),
    };
    let mut s = String::new();
    let w = &mut s;
    let _ = writeln!(w, "# Converted by photonmap from {}.", model.source);
    if mirror.is_some() {
        let _ = writeln!(w, "# The file's camera is left-handed: the world is mirrored so that the image is the same.");
    }
    write_hints(w, &model.hints);
    let _ = writeln!(w, "name = {}", toml_string(&model.name));
    let _ = writeln!(
        w,
        "\n[camera]\nposition = {}\nlook_at = {}\nup = {}",
        p(camera.eye),
        p(camera.eye + camera.dir * look_distance(model)),
        d(camera.up)
    );
    let _ = writeln!(
        w,
        "vfov = {}\nwidth = {}\nheight = {}",
        fmt(camera.vfov_degrees),
        camera.width,
        camera.height
    );
    let area_lights = model
        .emitters
        .iter()
        .any(|e| matches!(e, Emitter::Area { .. }));
    let depth = model.hints.max_depth.unwrap_or(10).min(64);
    let _ = writeln!(
        w,
        "\n[render]\nshadow_rays = {}\nmax_specular_depth = {depth}",
        if area_lights { 16 } else { 1 }
    );
    let pm = derived_photon_map(model);
    let _ = writeln!(
        w,
        "\n# Not in the file: derived from the scene's bounds and lights (--set overrides)."
    );
    let _ = writeln!(
        w,
        "[photon_map]\nphotons_stored = {}\nk = {}\nmax_radius = {}",
        pm.photons_stored,
        pm.k,
        fmt(pm.max_radius)
    );
    let [gx, gy, gz] = pm.grid_resolution;
    let _ = writeln!(
        w,
        "grid_resolution = [{gx}, {gy}, {gz}]\nmax_bounces = {}",
        depth.max(1)
    );
    if !model.surfaces.is_empty() {
        let _ = writeln!(w, "\n[materials]");
    }
    let used = |i: usize| model.surfaces.iter().any(|(_, m)| *m == i);
    for (i, (name, m)) in model.materials.iter().enumerate() {
        if !used(i) {
            continue;
        }
        let _ = match *m {
            Mat::Diffuse(c) => writeln!(
                w,
                "{name} = {{ type = \"diffuse\", albedo = {} }}",
                fmt_c(c)
            ),
            Mat::Mirror(c) => writeln!(
                w,
                "{name} = {{ type = \"mirror\", reflectance = {} }}",
                fmt_c(c)
            ),
            Mat::Glass(ior) => writeln!(w, "{name} = {{ type = \"glass\", ior = {} }}", fmt(ior)),
            Mat::Conductor {
                eta,
                k,
                tint,
                alpha,
                mitsuba,
            } => writeln!(
                w,
                "{name} = {{ type = \"conductor\", eta = {}, k = {}, tint = {}, alpha = {}{} }}",
                fmt_c(eta),
                fmt_c(k),
                fmt_c(tint),
                fmt(alpha),
                match mitsuba.filter(|_| alpha > 0.0) {
                    None => "",
                    Some(Distribution::Ggx) => ", distribution = \"ggx\", masking = \"separable\"",
                    Some(Distribution::Beckmann) => {
                        ", distribution = \"beckmann\", masking = \"separable\""
                    }
                }
            ),
        };
    }
    write_shapes(w, model, &p, &d);

    s
}

/// The shapes and lights, each point through `p` and direction through `d`.
fn write_shapes(
    w: &mut String,
    model: &Model,
    p: &dyn Fn(DVec3) -> String,
    d: &dyn Fn(DVec3) -> String,
) {
    for (surface, m) in &model.surfaces {
        let name = &model.materials[*m].0;
        let _ = match *surface {
            Surface::Sphere { center, radius } => writeln!(
                w,
                "\n[[shape]]\ntype = \"sphere\"\ncenter = {}\nradius = {}",
                p(center),
                fmt(radius)
            ),
            Surface::Cylinder {
                base,
                axis,
                radius,
                height,
            } => writeln!(
                w,
                "\n[[shape]]\ntype = \"cylinder\"\nbase = {}\naxis = {}\nradius = {}\nheight = {}",
                p(base),
                d(axis),
                fmt(radius),
                fmt(height)
            ),
            Surface::Triangle(v) => writeln!(
                w,
                "\n[[shape]]\ntype = \"triangle\"\nvertices = [{}, {}, {}]",
                p(v[0]),
                p(v[1]),
                p(v[2])
            ),
            Surface::Parallelogram {
                corner,
                edge1,
                edge2,
            } => writeln!(
                w,
                "\n[[shape]]\ntype = \"parallelogram\"\ncorner = {}\nedge1 = {}\nedge2 = {}",
                p(corner),
                d(edge1),
                d(edge2)
            ),
        };
        let _ = writeln!(w, "material = {}", toml_string(name));
    }
    for e in &model.emitters {
        let _ = match *e {
            Emitter::Area { corner, edge1, edge2, normal, radiance } => writeln!(w, "\n[[light]]\ntype = \"area\"\ncorner = {}\nedge1 = {}\nedge2 = {}\nnormal = {}\nradiance = {}", p(corner), d(edge1), d(edge2), d(normal), fmt_c(radiance)),
            Emitter::Point { position, intensity } => writeln!(w, "\n[[light]]\ntype = \"point\"\nposition = {}\nintensity = {}", p(position), fmt_c(intensity)),
        };
    }
}

/// The file's render settings that are options here, as comments.
fn write_hints(w: &mut String, h: &Hints) {
    if let Some(spp) = h.spp {
        let _ = writeln!(
            w,
            "# The file asks for {spp} samples per pixel: render with --spp {}.",
            spp.min(1024)
        );
    }
    if let Some((iterations, photons, radius)) = h.sppm {
        let mut flags = String::from("--method sppm");
        if let Some(i) = iterations {
            let _ = write!(flags, " --iterations {i}");
        }
        if let Some(n) = photons {
            let _ = write!(flags, " --photons-per-iteration {n}");
        }
        if let Some(r) = radius {
            let _ = write!(flags, " --radius {}", fmt(r));
        }
        let _ = writeln!(w, "# The file's integrator is SPPM: render with {flags}.");
    }
}

/// A TOML basic string.
fn toml_string(s: &str) -> String {
    let mut out = String::from("\"");
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if c.is_control() => {
                let _ = write!(out, "\\u{:04x}", c as u32);
            }
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// A number as TOML reads it back exactly (always with a point or exponent).
/// A value that is an f32 (as PLY files store them) is written as that
/// f32's shortest decimal.
pub fn fmt(x: f64) -> String {
    let x = if x == 0.0 { 0.0 } else { x };
    let s = if f64::from(x as f32) == x {
        format!("{:?}", x as f32)
    } else {
        format!("{x:?}")
    };
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}

fn fmt_v(v: DVec3) -> String {
    format!("[{}, {}, {}]", fmt(v.x), fmt(v.y), fmt(v.z))
}

fn fmt_c(c: [f64; 3]) -> String {
    format!("[{}, {}, {}]", fmt(c[0]), fmt(c[1]), fmt(c[2]))
}
