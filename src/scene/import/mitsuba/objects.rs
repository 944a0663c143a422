//! What Mitsuba's objects become: the perspective sensor with its film and
//! sampler, the integrator's options, BSDFs (twosided unwrapped), shapes
//! (meshes from OBJ and PLY, rectangles, cubes, discs, spheres, cylinders)
//! with their nested area emitters, and point emitters.

use std::f64::consts::TAU;

use glam::{DMat4, DQuat, DVec3};
use roxmltree::Node;

use super::super::geometry::{self, Emission, Mesh, Xf};
use super::super::model::{CameraSpec, Distribution, Emitter, Mat, RoughSource};
use super::state::Reader;
use super::values::{At, Props};
use crate::error::SceneError;
use crate::scene::metals;

fn int(p: &Props, at: &At, name: &str, default: i64, lo: i64, hi: i64) -> Result<i64, SceneError> {
    let v = p.float(at, name, default as f64)?;
    if v.fract() != 0.0 || v < lo as f64 || v > hi as f64 {
        return Err(at.err(
            p.node,
            name,
            format!("{v} must be an integer in {lo}..={hi}"),
        ));
    }
    Ok(v as i64)
}

pub fn sensor(r: &mut Reader, at: &At, n: Node) -> Result<(), SceneError> {
    let p = Props::read(at, n)?;
    let kind = n.attribute("type").unwrap_or("");
    if kind != "perspective" {
        r.cx.unsupported(at.file, at.line(n), &p.what, "a perspective camera")?;
    }
    let (mut width, mut height) = (768, 576);
    for o in p.objects() {
        let c = Props::read(at, o.node)?;
        match o.node.tag_name().name() {
            "film" => {
                width = int(&c, at, "width", 768, 1, 16384)? as u32;
                height = int(&c, at, "height", 576, 1, 16384)? as u32;
                for x in c.objects() {
                    Props::read(at, x.node)?.ignore_all();
                }
                c.ignore_all();
            }
            "sampler" => {
                r.model.hints.spp = Some(int(&c, at, "sample_count", 4, 1, 1 << 24)? as u32);
                c.ignore_all();
            }
            other => {
                return Err(at.err(
                    o.node,
                    other,
                    format!("unknown element <{other}> in a sensor"),
                ))
            }
        }
    }
    let aspect = f64::from(width) / f64::from(height);
    let axis = p.string(at, "fov_axis")?.unwrap_or_else(|| "x".into());
    let (fov, axis) = match p.float(at, "fov", -1.0)? {
        f if f > 0.0 && f < 180.0 => (f, axis),
        f if f != -1.0 => return Err(at.err(n, "fov", format!("{f} is outside (0, 180) degrees"))),
        _ => {
            let fl = p
                .string(at, "focal_length")?
                .unwrap_or_else(|| "50mm".into());
            let mm: f64 =
                fl.trim_end_matches("mm").trim().parse().map_err(|_| {
                    at.err(n, "focal_length", format!("`{fl}` is not a length in mm"))
                })?;
            (
                (2.0 * ((36f64.hypot(24.0)) / (2.0 * mm)).atan()).to_degrees(),
                "diagonal".into(),
            )
        }
    };
    let t = |deg: f64| (deg.to_radians() / 2.0).tan();
    let tan_y = match axis.as_str() {
        "x" => t(fov) / aspect,
        "y" => t(fov),
        "diagonal" => t(fov) / (1.0 + aspect * aspect).sqrt(),
        "smaller" if aspect >= 1.0 => t(fov),
        "smaller" => t(fov) / aspect,
        "larger" if aspect >= 1.0 => t(fov) / aspect,
        "larger" => t(fov),
        other => {
            return Err(at.err(
                n,
                "fov_axis",
                format!("`{other}`: it must be x, y, diagonal, smaller or larger"),
            ))
        }
    };
    if p.get("aperture_radius").is_some() || kind == "thinlens" {
        r.cx.unsupported(
            at.file,
            at.line(n),
            "depth of field (thinlens)",
            "a pinhole camera",
        )?;
    }
    let w = Xf(p.transform(at, "to_world")?);
    p.ignore(&[
        "near_clip",
        "far_clip",
        "focus_distance",
        "shutter_open",
        "shutter_close",
        "principal_point_offset_x",
        "principal_point_offset_y",
        "srf",
    ]);
    p.finish(at)?;
    r.model.camera = Some(CameraSpec {
        eye: w.point(DVec3::ZERO),
        dir: w.vector(DVec3::Z).normalize(),
        up: w.vector(DVec3::Y).normalize(),
        // Mitsuba's camera x points to the image's left
        right: -w.vector(DVec3::X).normalize(),
        vfov_degrees: (2.0 * tan_y.atan()).to_degrees(),
        width,
        height,
    });
    Ok(())
}

/// The integrator's `max_depth` counts a path's segments from the camera
/// (1: emitters seen directly, 2: direct light), one more than the bounces
/// photonmap counts (as pbrt-v4's `maxdepth` does): `max_depth` D gives
/// D - 1 bounces. -1 (unbounded, Mitsuba's default) leaves photonmap's.
pub fn integrator(r: &mut Reader, at: &At, n: Node) -> Result<(), SceneError> {
    let p = Props::read(at, n)?;
    let depth = p.float(at, "max_depth", -1.0)?;
    if depth > 0.0 && depth < 2.0 {
        r.cx.unsupported(
            at.file,
            p.line_of(at, "max_depth"),
            &format!("max_depth {depth} (no light on any surface)"),
            "max_depth 2 (direct light)",
        )?;
    }
    if depth > 0.0 {
        r.model.hints.max_depth = Some((depth - 1.0).clamp(1.0, 64.0) as u32);
    }
    if n.attribute("type") == Some("sppm") {
        let photons = p.float(at, "photon_count", -1.0)?;
        let radius = p.float(at, "initial_radius", -1.0)?;
        let passes = p.float(at, "max_passes", -1.0)?;
        let positive = |v: f64| (v >= 1.0).then(|| v.min(f64::from(u32::MAX)) as u32);
        r.model.hints.sppm = Some((
            positive(passes),
            positive(photons),
            (radius > 0.0).then_some(radius),
        ));
    }
    p.ignore_all();
    for o in p.objects() {
        Props::read(at, o.node)?.ignore_all();
    }
    Ok(())
}

/// Indices of refraction Mitsuba names.
const IORS: &[(&str, f64)] = &[
    ("vacuum", 1.0),
    ("helium", 1.000036),
    ("hydrogen", 1.000132),
    ("air", 1.000277),
    ("carbon dioxide", 1.00045),
    ("water", 1.333),
    ("acetone", 1.36),
    ("ethanol", 1.361),
    ("carbon tetrachloride", 1.461),
    ("glycerol", 1.4729),
    ("benzene", 1.501),
    ("silicone oil", 1.52045),
    ("bromine", 1.661),
    ("water ice", 1.31),
    ("fused quartz", 1.458),
    ("pyrex", 1.47),
    ("acrylic glass", 1.49),
    ("polypropylene", 1.49),
    ("bk7", 1.5046),
    ("sodium chloride", 1.544),
    ("amber", 1.55),
    ("pet", 1.575),
    ("diamond", 2.419),
];

fn ior(at: &At, p: &Props, name: &str, default: f64) -> Result<f64, SceneError> {
    let named = match p.get(name).map(|x| &x.value) {
        Some(super::values::Value::Str(s)) => s.clone(),
        _ => return p.float(at, name, default),
    };
    match IORS.iter().find(|(k, _)| *k == named.to_ascii_lowercase()) {
        Some((_, v)) => Ok(*v),
        None => Err(at.err(
            p.node,
            name,
            format!("unknown index of refraction `{named}`"),
        )),
    }
}

fn colour(
    r: &mut Reader,
    at: &At,
    p: &Props,
    name: &str,
    default: [f64; 3],
) -> Result<[f64; 3], SceneError> {
    match p.colour(at, name)? {
        None => Ok(default),
        Some(Ok(c)) => Ok(c),
        Some(Err(what)) => {
            r.cx.unsupported(
                at.file,
                p.line_of(at, name),
                &format!("{} {name} {what}", p.what),
                &format!("the constant {default:?}"),
            )?;
            Ok(default)
        }
    }
}

fn unit(c: [f64; 3]) -> [f64; 3] {
    c.map(|v| v.clamp(0.0, 1.0))
}

/// A `conductor` or `roughconductor`: eta and k by `material` (Mitsuba's
/// named metals, src/scene/metals.rs, reduced to RGB as its RGB variants
/// reduce them; `none`, its default, a perfect mirror) or as colours, times
/// `specular_reflectance`; rough by `alpha` (or equal `alpha_u`/`alpha_v`)
/// with the GGX distribution.
fn conductor(r: &mut Reader, at: &At, p: &Props, rough: bool) -> Result<Mat, SceneError> {
    let tint = unit(colour(r, at, p, "specular_reflectance", [1.0; 3])?);
    let index = |(eta, k): (glam::Vec3, glam::Vec3)| {
        (eta.to_array().map(f64::from), k.to_array().map(f64::from))
    };
    let (eta, k) = match (p.colour(at, "eta")?, p.colour(at, "k")?) {
        (Some(Ok(e)), Some(Ok(k))) => (e, k),
        (None, None) => {
            let name = p.string(at, "material")?.unwrap_or_else(|| "none".into());
            match metals::metal(&name) {
                Some(m) => index(m),
                None if name == "none" && !rough => return Ok(Mat::Mirror(tint)),
                None if name == "none" => index((glam::Vec3::ZERO, glam::Vec3::splat(1e3))),
                None => {
                    let what = format!("{} material `{name}`", p.what);
                    return Ok(Mat::Mirror(grey_mirror(
                        r,
                        at,
                        p.line_of(at, "material"),
                        &what,
                    )?));
                }
            }
        }
        _ => {
            let what = format!("{} eta and k", p.what);
            return Ok(Mat::Mirror(grey_mirror(
                r,
                at,
                p.line_of(at, "eta"),
                &what,
            )?));
        }
    };
    let (mut u, mut v) = (0.0, 0.0);
    let mut model = Distribution::Ggx;
    if rough {
        let distribution = p
            .string(at, "distribution")?
            .unwrap_or_else(|| "beckmann".into());
        p.ignore(&["sample_visible"]);
        let a = p.float(at, "alpha", 0.1)?;
        (u, v) = (p.float(at, "alpha_u", a)?, p.float(at, "alpha_v", a)?);
        model = match distribution.as_str() {
            "ggx" => Distribution::Ggx,
            "beckmann" => Distribution::Beckmann,
            other => {
                r.cx.unsupported(
                    at.file,
                    p.line_of(at, "distribution"),
                    &format!("{} with the {other} distribution", p.what),
                    &format!("Beckmann of alpha {}", u.max(v)),
                )?;
                Distribution::Beckmann
            }
        };
    }
    let source = RoughSource {
        file: at.file,
        what: &p.what,
        name: "alpha",
        uneven_line: p.line_of(at, "alpha_u"),
        alpha_line: p.line_of(at, "alpha"),
    };
    Mat::conductor(&mut r.cx, &source, (eta, k, tint), (u, v), Some(model))
}

/// What a conductor it cannot colour becomes (`what`, at `line`, unsupported).
fn grey_mirror(r: &mut Reader, at: &At, line: usize, what: &str) -> Result<[f64; 3], SceneError> {
    r.cx.unsupported(at.file, line, what, "a grey mirror of 0.9")?;
    Ok([0.9; 3])
}

/// A `<bsdf>` (or `<ref>` to one) as a material.
pub fn bsdf(r: &mut Reader, at: &At, n: Node) -> Result<Mat, SceneError> {
    if n.tag_name().name() == "ref" {
        let id = at.req(n, "id")?;
        return r
            .bsdfs
            .get(&id)
            .copied()
            .ok_or_else(|| at.err(n, "ref", format!("no <bsdf id=\"{id}\">")));
    }
    let p = Props::read(at, n)?;
    let kind = n.attribute("type").unwrap_or("");
    let nested = |r: &mut Reader, p: &Props| -> Result<Mat, SceneError> {
        match p.objects().next() {
            Some(o) => bsdf(r, at, o.node),
            None => Ok(Mat::Diffuse([0.5; 3])),
        }
    };
    let m = match kind {
        "twosided" => nested(r, &p)?,
        "diffuse" => Mat::Diffuse(unit(colour(r, at, &p, "reflectance", [0.5; 3])?)),
        "dielectric" | "roughdielectric" | "thindielectric" => {
            if kind != "dielectric" {
                p.ignore(&[
                    "alpha",
                    "alpha_u",
                    "alpha_v",
                    "distribution",
                    "sample_visible",
                ]);
                r.cx.unsupported(at.file, at.line(n), &p.what, "smooth glass")?;
            }
            let eta = ior(at, &p, "int_ior", 1.5046)? / ior(at, &p, "ext_ior", 1.000277)?;
            p.ignore(&["specular_reflectance", "specular_transmittance"]);
            if !(1.0..=10.0).contains(&eta) {
                r.cx.unsupported(
                    at.file,
                    at.line(n),
                    &format!("{} of relative ior {eta} (outside [1, 10])", p.what),
                    "ior 1.5",
                )?;
                Mat::Glass(1.5)
            } else {
                Mat::Glass(eta)
            }
        }
        "conductor" | "roughconductor" => conductor(r, at, &p, kind == "roughconductor")?,
        _ => {
            let fallback = match kind {
                "plastic" | "roughplastic" => {
                    Mat::Diffuse(unit(colour(r, at, &p, "diffuse_reflectance", [0.5; 3])?))
                }
                "principled" => Mat::Diffuse(unit(colour(r, at, &p, "base_color", [0.5; 3])?)),
                "mask" | "bumpmap" | "normalmap" | "blendbsdf" => nested(r, &p)?,
                _ => Mat::Diffuse([0.5; 3]),
            };
            p.ignore_all();
            r.cx.unsupported(at.file, at.line(n), &p.what, &format!("{fallback:?}"))?;
            fallback
        }
    };
    p.finish(at)?;
    Ok(m)
}

/// A shape's BSDF (named by its id, or its type) and area emitter, from
/// its nested objects.
fn nested(
    r: &mut Reader,
    at: &At,
    p: &Props,
) -> Result<(String, Mat, Option<[f64; 3]>), SceneError> {
    let (mut name, mut mat, mut radiance) = ("diffuse".to_string(), Mat::Diffuse([0.5; 3]), None);
    for o in p.objects() {
        match o.node.tag_name().name() {
            "bsdf" | "ref" => {
                mat = bsdf(r, at, o.node)?;
                name = at
                    .attr(o.node, "id")?
                    .unwrap_or_else(|| o.node.attribute("type").unwrap_or("bsdf").to_string());
            }
            "emitter" if o.node.attribute("type") == Some("area") => {
                let e = Props::read(at, o.node)?;
                radiance = Some(colour(r, at, &e, "radiance", [1.0; 3])?);
                e.finish(at)?;
            }
            "emitter" => {
                Props::read(at, o.node)?.ignore_all();
                r.cx.unsupported(
                    at.file,
                    at.line(o.node),
                    &format!(
                        "<emitter type=\"{}\"> in a shape",
                        o.node.attribute("type").unwrap_or("")
                    ),
                    "left out",
                )?;
            }
            "medium" => r.cx.unsupported(
                at.file,
                at.line(o.node),
                "<medium> (participating media)",
                "ignored",
            )?,
            other => {
                return Err(at.err(
                    o.node,
                    other,
                    format!("unknown element <{other}> in a shape"),
                ))
            }
        }
    }
    Ok((name, mat, radiance))
}

pub fn shape(r: &mut Reader, at: &At, n: Node) -> Result<(), SceneError> {
    let p = Props::read(at, n)?;
    let kind = n.attribute("type").unwrap_or("");
    let (name, mat, radiance) = nested(r, at, &p)?;
    let material = r.model.material(&name, mat);
    let xf = Xf(p.transform(at, "to_world")?);
    let flip_normals = p.bool(at, "flip_normals", false)?;
    let analytic = Emission {
        radiance: [0.0; 3],
        flip: flip_normals ^ xf.swaps_handedness(),
        follow_normals: false,
        flip_normals,
    };
    let (mesh, emission) = match kind {
        "obj" | "ply" => {
            let name = p
                .string(at, "filename")?
                .ok_or_else(|| at.err(n, "filename", format!("{} needs a filename", p.what)))?;
            let (path, bytes) = r.read(at, n, &name)?;
            let mut mesh = match kind {
                "obj" => {
                    obj(&bytes).map_err(|(line, m)| SceneError::new(&path, line, "(obj)", m))?
                }
                _ => super::super::ply::parse_ply(&bytes)
                    .map_err(|e| SceneError::new(&path, e.line, "(ply)", e.message))?,
            };
            if p.bool(at, "face_normals", false)? {
                mesh.normals = None;
            }
            let follow = mesh.normals.is_some();
            (
                mesh,
                Emission {
                    flip: flip_normals,
                    follow_normals: follow,
                    ..analytic
                },
            )
        }
        "rectangle" => (geometry::rectangle(), analytic),
        "cube" => (geometry::cube(), analytic),
        "disk" => (geometry::disc(1.0, 0.0, 0.0, TAU), analytic),
        "sphere" => return sphere(r, at, &p, &xf, material, radiance),
        "cylinder" => return cylinder(r, at, &p, &xf, material, radiance),
        _ => {
            p.ignore_all();
            return r.cx.unsupported(at.file, at.line(n), &p.what, "left out");
        }
    };
    p.finish(at)?;
    let emission = radiance.map(|radiance| Emission {
        radiance,
        ..emission
    });
    let unpaired = geometry::place_mesh(&mut r.model, &mesh, &xf, material, emission);
    r.cx.unpaired_triangles(at.file, at.line(n), &p.what, unpaired)
}

fn sphere(
    r: &mut Reader,
    at: &At,
    p: &Props,
    xf: &Xf,
    material: usize,
    radiance: Option<[f64; 3]>,
) -> Result<(), SceneError> {
    let c = p.point(at, "center")?.unwrap_or(DVec3::ZERO);
    let radius = p.float(at, "radius", 1.0)?.abs();
    p.finish(at)?;
    let Some(s) = xf.uniform_scale() else {
        return Err(at.err(
            p.node,
            "to_world",
            "a sphere's to_world must rotate and scale evenly".into(),
        ));
    };
    let place = (at.file, at.line(p.node), p.what.as_str());
    r.model.add_sphere(
        &mut r.cx,
        place,
        (xf.point(c), radius * s),
        material,
        radiance,
    )
}

fn cylinder(
    r: &mut Reader,
    at: &At,
    p: &Props,
    xf: &Xf,
    material: usize,
    radiance: Option<[f64; 3]>,
) -> Result<(), SceneError> {
    let p0 = p.point(at, "p0")?.unwrap_or(DVec3::ZERO);
    let p1 = p.point(at, "p1")?.unwrap_or(DVec3::Z);
    let radius = p.float(at, "radius", 1.0)?;
    p.finish(at)?;
    if radiance.is_some() {
        r.cx.unsupported(
            at.file,
            at.line(p.node),
            &format!("{} emitting", p.what),
            "kept without emission",
        )?;
    }
    let axis = p1 - p0;
    if axis.length() == 0.0 {
        return Err(at.err(p.node, "p1", "equals p0".into()));
    }
    let frame =
        DMat4::from_rotation_translation(DQuat::from_rotation_arc(DVec3::Z, axis.normalize()), p0);
    let placed = Xf(xf.0 * frame);
    match geometry::cylinder(radius, 0.0, axis.length(), &placed) {
        Ok(s) => r.model.surfaces.push((s, material)),
        Err(mesh) => {
            geometry::place_mesh(&mut r.model, &mesh, &placed, material, None);
        }
    }
    Ok(())
}

pub fn emitter(r: &mut Reader, at: &At, n: Node) -> Result<(), SceneError> {
    let p = Props::read(at, n)?;
    let kind = n.attribute("type").unwrap_or("");
    if !matches!(kind, "point" | "spot") {
        p.ignore_all();
        return r.cx.unsupported(at.file, at.line(n), &p.what, "left out");
    }
    if kind == "spot" {
        p.ignore(&["cutoff_angle", "beam_width", "texture"]);
        r.cx.unsupported(
            at.file,
            at.line(n),
            &p.what,
            "a point light of the same intensity",
        )?;
    }
    let intensity = colour(r, at, &p, "intensity", [1.0; 3])?;
    let position =
        Xf(p.transform(at, "to_world")?).point(p.point(at, "position")?.unwrap_or(DVec3::ZERO));
    p.finish(at)?;
    r.model.emitters.push(Emitter::Point {
        position,
        intensity,
    });
    Ok(())
}

/// An OBJ file's geometry (Mitsuba reads no materials from it): `v`, `vn`,
/// `f` (any of `v`, `v/t`, `v//n`, `v/t/n`, negative indices), polygons
/// fanned; every other statement is ignored. Errors give the line.
pub fn obj(bytes: &[u8]) -> Result<Mesh, (usize, String)> {
    let text = String::from_utf8_lossy(bytes);
    let (mut v, mut vn) = (Vec::new(), Vec::new());
    let mut mesh = Mesh {
        normals: Some(Vec::new()),
        ..Mesh::default()
    };
    let mut all_normals = true;
    for (i, line) in text.lines().enumerate() {
        let line_no = i + 1;
        let mut t = line.split_whitespace();
        let nums = |t: std::str::SplitWhitespace| -> Result<DVec3, (usize, String)> {
            let x: Vec<f64> = t
                .take(3)
                .map(|s| s.parse::<f64>().ok().filter(|x| x.is_finite()))
                .collect::<Option<_>>()
                .ok_or((line_no, "a coordinate is not a number".to_string()))?;
            (x.len() == 3)
                .then(|| DVec3::new(x[0], x[1], x[2]))
                .ok_or((line_no, "takes 3 numbers".into()))
        };
        match t.next() {
            Some("v") => v.push(nums(t)?),
            Some("vn") => vn.push(nums(t)?),
            Some("f") => {
                let mut corners = Vec::new();
                for c in t {
                    let mut parts = c.split('/');
                    let at =
                        |s: Option<&str>, len: usize| -> Result<Option<usize>, (usize, String)> {
                            match s.filter(|s| !s.is_empty()) {
                                None => Ok(None),
                                Some(s) => {
                                    let k: i64 = s
                                        .parse()
                                        .map_err(|_| (line_no, format!("`{s}` is not an index")))?;
                                    let idx = if k < 0 { len as i64 + k } else { k - 1 };
                                    (0..len as i64)
                                        .contains(&idx)
                                        .then_some(Some(idx as usize))
                                        .ok_or((line_no, format!("index {k} is out of range")))
                                }
                            }
                        };
                    let p = at(parts.next(), v.len())?
                        .ok_or((line_no, "a face corner has no vertex".to_string()))?;
                    let _ = parts.next();
                    let nrm = at(parts.next(), vn.len())?;
                    all_normals &= nrm.is_some();
                    mesh.positions.push(v[p]);
                    mesh.normals
                        .as_mut()
                        .expect("kept")
                        .push(nrm.map_or(DVec3::ZERO, |k| vn[k]));
                    corners.push(mesh.positions.len() - 1);
                }
                if corners.len() < 3 {
                    return Err((line_no, format!("a face of {} corners", corners.len())));
                }
                for k in 1..corners.len() - 1 {
                    mesh.triangles
                        .push([corners[0], corners[k], corners[k + 1]]);
                }
            }
            _ => {}
        }
    }
    if !all_normals || mesh.positions.is_empty() {
        mesh.normals = None;
    }
    Ok(mesh)
}
