//! What pbrt-v4's objects become: the camera and film, the integrator's
//! options, materials, lights, and shapes (triangles, open cylinders,
//! spheres; discs and bilinear patches as triangles; emitting
//! parallelograms as area lights).

use glam::{DMat4, DVec3};

use super::super::geometry::{self, Emission, Mesh, Xf};
use super::super::model::{Emitter, Mat, RoughSource};
use super::params::{blackbody_rgb, Colour, Params};
use super::state::{AreaLight, PbrtCamera, PendingShape, Reader};
use crate::error::SceneError;
use crate::scene::metals;

/// pbrt's LookAt: the camera-from-world transform.
pub fn look_at(v: &[f64]) -> Result<DMat4, String> {
    let pos = DVec3::new(v[0], v[1], v[2]);
    let look = DVec3::new(v[3], v[4], v[5]);
    let up = DVec3::new(v[6], v[7], v[8]);
    let dir = (look - pos).normalize();
    if !dir.is_finite() || up.length() == 0.0 || up.normalize().cross(dir).length() < 1e-9 {
        return Err("the eye equals the target, or up is zero or along the view".into());
    }
    let right = up.normalize().cross(dir).normalize();
    let new_up = dir.cross(right);
    let world_from_camera = DMat4::from_cols(
        right.extend(0.0),
        new_up.extend(0.0),
        dir.extend(0.0),
        pos.extend(1.0),
    );
    Ok(world_from_camera.inverse())
}

pub fn camera(
    r: &mut Reader,
    kind: &str,
    p: &Params,
    camera_from_world: DMat4,
) -> Result<(), SceneError> {
    let w = Xf(camera_from_world.inverse());
    let mut fov = 90.0;
    if kind == "perspective" {
        fov = p.float("fov", 90.0)?;
        if !(fov > 0.0 && fov < 180.0) {
            return Err(p.err(
                p.line_of("fov"),
                "fov",
                format!("{fov} is outside (0, 180) degrees"),
            ));
        }
        if p.float("lensradius", 0.0)? > 0.0 {
            r.cx.unsupported(
                p.file,
                p.line_of("lensradius"),
                "depth of field (lensradius > 0)",
                "a pinhole camera",
            )?;
        }
        if p.has("screenwindow") {
            r.cx.unsupported(
                p.file,
                p.line_of("screenwindow"),
                "screenwindow",
                "the full screen",
            )?;
        }
        p.ignore(&[
            "focaldistance",
            "frameaspectratio",
            "shutteropen",
            "shutterclose",
        ]);
    } else {
        p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
        r.cx.unsupported(
            p.file,
            p.line,
            &format!("Camera \"{kind}\""),
            "a perspective camera of fov 90",
        )?;
    }
    r.camera = Some(PbrtCamera {
        eye: w.point(DVec3::ZERO),
        dir: w.vector(DVec3::Z).normalize(),
        up: w.vector(DVec3::Y).normalize(),
        right: w.vector(DVec3::X).normalize(),
        fov,
    });
    Ok(())
}

pub fn film(r: &mut Reader, kind: &str, p: &Params) -> Result<(), SceneError> {
    let side = |name: &str, d: i64| -> Result<u32, SceneError> {
        let v = p.int(name, d)?;
        if !(1..=16384).contains(&v) {
            return Err(p.err(p.line_of(name), name, format!("{v} is outside 1..=16384")));
        }
        Ok(v as u32)
    };
    r.film = (side("xresolution", 1280)?, side("yresolution", 720)?);
    if p.has("cropwindow") {
        r.cx.unsupported(
            p.file,
            p.line_of("cropwindow"),
            "cropwindow",
            "the whole image",
        )?;
    }
    p.ignore(&[
        "filename",
        "diagonal",
        "iso",
        "whitebalance",
        "sensor",
        "exposuretime",
        "maxcomponentvalue",
        "savefp16",
        "pixelbounds",
        "writefp16",
    ]);
    if !matches!(kind, "rgb" | "gbuffer" | "spectral") {
        r.cx.unsupported(p.file, p.line, &format!("Film \"{kind}\""), "an RGB film")?;
    }
    Ok(())
}

pub fn integrator(r: &mut Reader, kind: &str, p: &Params) -> Result<(), SceneError> {
    let depth = p.int("maxdepth", 5)?;
    r.model.hints.max_depth = Some(depth.clamp(1, 64) as u32);
    if kind == "sppm" {
        let iterations = p.int("iterations", p.int("numiterations", -1)?)?;
        let photons = p.int("photonsperiteration", -1)?;
        let radius = match p.has("radius") {
            true => Some(p.float("radius", 1.0)?),
            false => None,
        };
        p.ignore(&["seed", "imagewritefrequency", "regularize", "pixelbounds"]);
        let positive = |v: i64| (v > 0).then(|| v.min(u32::MAX as i64) as u32);
        r.model.hints.sppm = Some((
            positive(iterations),
            positive(photons),
            radius.filter(|&x| x > 0.0),
        ));
    } else {
        p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
    }
    Ok(())
}

/// A colour parameter as RGB: blackbodies by their colour at luminance 1,
/// spectra and textures refused (or `default` under --lenient).
fn rgb(r: &mut Reader, p: &Params, name: &str, default: [f64; 3]) -> Result<[f64; 3], SceneError> {
    Ok(match p.colour(name)? {
        None => default,
        Some(Colour::Rgb(c)) => c,
        Some(Colour::Blackbody(t)) => blackbody_rgb(t),
        Some(Colour::Other(what)) => {
            let instead = format!("the constant {default:?}");
            r.cx.unsupported(
                p.file,
                p.line_of(name),
                &format!("{} {what}", p.what),
                &instead,
            )?;
            default
        }
    })
}

fn unit(c: [f64; 3]) -> [f64; 3] {
    c.map(|v| v.clamp(0.0, 1.0))
}

/// Named metal spectra, as their normal-incidence reflectance in sRGB.
const METALS: &[(&str, [f64; 3])] = &[
    ("Cu", [0.955, 0.638, 0.538]),
    ("Au", [1.0, 0.782, 0.344]),
    ("Ag", [0.972, 0.960, 0.915]),
    ("Al", [0.913, 0.922, 0.924]),
    ("CuZn", [0.910, 0.778, 0.423]),
];
/// Named glasses, as their index at 550 nm.
const GLASSES: &[(&str, f64)] = &[
    ("glass-BK7", 1.5168),
    ("glass-BAF10", 1.6700),
    ("glass-FK51A", 1.4866),
    ("glass-LASF9", 1.8503),
    ("glass-F5", 1.6034),
    ("glass-F10", 1.6200),
    ("glass-F11", 1.6200),
];

/// A `conductor`: its eta and k from `reflectance` (pbrt's eta = 1,
/// k = 2 sqrt(r) / sqrt(1 - r)), a named `metal-*-eta`/`-k` pair (Mitsuba's
/// RGB reduction of the same metal's measurements, src/scene/metals.rs), or
/// RGB values; pbrt's default, copper, without any; rough by `roughness`
/// (remapped as pbrt-v4 remaps it, alpha = sqrt(roughness), unless
/// `remaproughness` is false).
fn conductor(r: &mut Reader, p: &Params) -> Result<Mat, SceneError> {
    let index = |(eta, k): (glam::Vec3, glam::Vec3)| {
        (eta.to_array().map(f64::from), k.to_array().map(f64::from))
    };
    let (eta, k) = if p.has("reflectance") {
        let c = rgb(r, p, "reflectance", [0.9; 3]).map(unit)?;
        index(metals::from_reflectance(glam::DVec3::from(c).as_vec3()))
    } else {
        let named = |name: &str| -> Result<Option<String>, SceneError> {
            let Some(q) = p.find(name, &["spectrum", "rgb", "float"])? else {
                return Ok(None);
            };
            Ok(match q.values.as_slice() {
                [super::lexer::Val::Str(s)] => Some(s.clone()),
                _ => None,
            })
        };
        match (named("eta")?, p.has("k")) {
            (Some(spectrum), _) => {
                p.has("k");
                let metal = spectrum
                    .strip_prefix("metal-")
                    .and_then(|m| m.strip_suffix("-eta"))
                    .unwrap_or("");
                match (
                    metals::metal(metal),
                    METALS.iter().find(|(m, _)| *m == metal),
                ) {
                    (Some(m), _) => index(m),
                    // Brass is not in Mitsuba's tables: its normal-incidence
                    // reflectance, as pbrt's `reflectance` would give it.
                    (None, Some((_, f0))) => {
                        index(metals::from_reflectance(glam::DVec3::from(*f0).as_vec3()))
                    }
                    (None, None) => {
                        r.cx.unsupported(
                            p.file,
                            p.line_of("eta"),
                            &format!("{} spectrum \"{spectrum}\"", p.what),
                            "a grey mirror of 0.9",
                        )?;
                        return Ok(Mat::Mirror([0.9; 3]));
                    }
                }
            }
            (None, _) => match (p.colour("eta")?, p.colour("k")?) {
                (None, None) => index(metals::metal("Cu").expect("copper is in the table")),
                (Some(Colour::Rgb(e)), Some(Colour::Rgb(k))) => (e, k),
                _ => {
                    r.cx.unsupported(
                        p.file,
                        p.line_of("eta"),
                        &format!("{} eta and k", p.what),
                        "a grey mirror of 0.9",
                    )?;
                    return Ok(Mat::Mirror([0.9; 3]));
                }
            },
        }
    };
    let rough = p.float("roughness", 0.0)?;
    let (u, v) = (p.float("uroughness", rough)?, p.float("vroughness", rough)?);
    let remap = p.bool("remaproughness", true)?;
    let alpha_of = |x: f64| if remap { x.max(0.0).sqrt() } else { x };
    let at = RoughSource {
        file: p.file,
        what: &p.what,
        name: "roughness",
        uneven_line: p.line_of("uroughness"),
        alpha_line: p.line_of("roughness"),
    };
    Mat::conductor(
        &mut r.cx,
        &at,
        (eta, k, [1.0; 3]),
        (alpha_of(u), alpha_of(v)),
        None,
    )
}

fn roughness(p: &Params) -> Result<f64, SceneError> {
    let r = p.float("roughness", 0.0)?;
    let u = p.float("uroughness", r)?;
    let v = p.float("vroughness", r)?;
    p.ignore(&["remaproughness"]);
    Ok(u.max(v))
}

/// A material (None: `interface`, whose shapes only bound media).
pub fn material(r: &mut Reader, kind: &str, p: &Params) -> Result<Option<Mat>, SceneError> {
    p.ignore(&["type"]);
    if p.has("displacement") || p.has("normalmap") {
        p.unsupported(&mut r.cx, "displacement or normal map", "ignored")?;
    }
    let rough = |r: &mut Reader, p: &Params, what: &str, instead: &str| -> Result<(), SceneError> {
        if roughness(p)? > 0.0 {
            r.cx.unsupported(p.file, p.line, &format!("{} ({what})", p.what), instead)?;
        }
        Ok(())
    };
    Ok(Some(match kind {
        "diffuse" => Mat::Diffuse(unit(rgb(r, p, "reflectance", [0.5; 3])?)),
        "conductor" => conductor(r, p)?,
        "dielectric" | "thindielectric" => {
            if kind == "thindielectric" {
                r.cx.unsupported(p.file, p.line, &p.what, "solid glass")?;
            } else {
                rough(r, p, "rough glass", "smooth glass")?;
            }
            let eta = match p
                .find("eta", &["float", "spectrum"])?
                .map(|q| q.values.clone())
                .as_deref()
            {
                None => 1.5,
                Some([super::lexer::Val::Num(x)]) => *x,
                Some([super::lexer::Val::Str(s)]) => match GLASSES.iter().find(|(g, _)| g == s) {
                    Some((_, n)) => *n,
                    None => {
                        r.cx.unsupported(
                            p.file,
                            p.line_of("eta"),
                            &format!("{} eta \"{s}\"", p.what),
                            "ior 1.5",
                        )?;
                        1.5
                    }
                },
                Some(_) => {
                    r.cx.unsupported(
                        p.file,
                        p.line_of("eta"),
                        &format!("{} sampled eta", p.what),
                        "ior 1.5",
                    )?;
                    1.5
                }
            };
            if !(1.0..=10.0).contains(&eta) {
                let instead = if eta > 0.0 && eta < 1.0 {
                    1.0 / eta
                } else {
                    1.5
                };
                r.cx.unsupported(
                    p.file,
                    p.line_of("eta"),
                    &format!("{} eta {eta} (outside [1, 10])", p.what),
                    &format!("ior {instead}"),
                )?;
                Mat::Glass(instead.clamp(1.0, 10.0))
            } else {
                Mat::Glass(eta)
            }
        }
        "interface" => {
            p.unsupported(
                &mut r.cx,
                "(a medium's boundary)",
                "its shapes are left out",
            )?;
            return Ok(None);
        }
        _ => {
            let fallback = match kind {
                "coateddiffuse" | "diffusetransmission" | "subsurface" => {
                    Mat::Diffuse(unit(rgb(r, p, "reflectance", [0.5; 3])?))
                }
                "coatedconductor" => Mat::Mirror(METALS[0].1),
                _ => Mat::Diffuse([0.5; 3]),
            };
            p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
            r.cx.unsupported(p.file, p.line, &p.what, &format!("{fallback:?}"))?;
            fallback
        }
    }))
}

pub fn area_light(r: &mut Reader, kind: &str, p: &Params) -> Result<AreaLight, SceneError> {
    if kind != "diffuse" {
        p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
        r.cx.unsupported(p.file, p.line, &p.what, "a diffuse area light of L = 1")?;
        return Ok(AreaLight { radiance: [1.0; 3] });
    }
    let l = rgb(r, p, "L", [1.0; 3])?;
    let scale = p.float("scale", 1.0)?;
    if p.has("filename") || p.has("power") {
        p.unsupported(
            &mut r.cx,
            "filename or power",
            "ignored: L and scale give the radiance",
        )?;
    }
    p.ignore(&["alpha"]);
    if p.bool("twosided", false)? {
        let what = format!("{} twosided (a two-sided emitter)", p.what);
        r.cx.unsupported(
            p.file,
            p.line_of("twosided"),
            &what,
            "it emits on its front side only",
        )?;
    }
    Ok(AreaLight {
        radiance: l.map(|c| c * scale.max(0.0)),
    })
}

pub fn light(r: &mut Reader, kind: &str, p: &Params) -> Result<(), SceneError> {
    let as_point = matches!(kind, "point" | "spot" | "goniometric" | "projection");
    if !as_point {
        p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
        return r.cx.unsupported(p.file, p.line, &p.what, "left out");
    }
    if kind != "point" {
        p.ignore(&["to", "coneangle", "conedelta", "filename", "fov"]);
        r.cx.unsupported(
            p.file,
            p.line,
            &p.what,
            "a point light of the same intensity",
        )?;
    }
    let i = rgb(r, p, "I", [1.0; 3])?;
    let scale = p.float("scale", 1.0)?;
    if p.has("power") {
        r.cx.unsupported(
            p.file,
            p.line_of("power"),
            &format!("{} power", p.what),
            "ignored: I and scale give the intensity",
        )?;
    }
    let from = p
        .vec3s("from", &["point3", "point"])?
        .map_or(DVec3::ZERO, |v| v[0]);
    let position = Xf(r.state.ctm).point(from);
    r.model.emitters.push(Emitter::Point {
        position,
        intensity: i.map(|c| c * scale.max(0.0)),
    });
    Ok(())
}

/// A triangle mesh's parameters: P, indices, N, uv.
fn triangle_mesh(p: &Params, per_face: usize) -> Result<Mesh, SceneError> {
    let positions = p
        .vec3s("P", &["point3", "point"])?
        .ok_or_else(|| p.err(p.line, "P", "is missing".into()))?;
    let indices = match p.ints("indices")? {
        Some(v) => v.into_iter().map(|i| i as usize).collect(),
        None if positions.len() == per_face => (0..per_face).collect::<Vec<_>>(),
        None => return Err(p.err(p.line, "indices", "is missing".into())),
    };
    if !indices.len().is_multiple_of(per_face) {
        return Err(p.err(
            p.line_of("indices"),
            "indices",
            format!(
                "has {} entries, not a multiple of {per_face}",
                indices.len()
            ),
        ));
    }
    let normals = p.vec3s("N", &["normal", "normal3"])?;
    let uv = p
        .nums("uv", &["point2", "float"], 2)?
        .map(|v| v.chunks(2).map(|c| [c[0], c[1]]).collect());
    p.ignore(&["S", "faceIndices", "emission"]);
    let mut mesh = Mesh {
        positions,
        normals,
        uv,
        triangles: Vec::new(),
    };
    if per_face == 3 {
        mesh.triangles = indices.chunks(3).map(|c| [c[0], c[1], c[2]]).collect();
    } else {
        bilinear(&mut mesh, &indices);
    }
    mesh.check().map_err(|m| p.err(p.line, "indices", m))?;
    Ok(mesh)
}

/// Bilinear patches (p00, p10, p01, p11) as two triangles each, in the
/// order that makes a parallelogram's pair (its normal dp/du x dp/dv).
fn bilinear(mesh: &mut Mesh, indices: &[usize]) {
    for q in indices.chunks(4) {
        mesh.triangles.push([q[0], q[1], q[3]]);
        mesh.triangles.push([q[0], q[3], q[2]]);
    }
}

pub fn shape(r: &mut Reader, s: &PendingShape, p: &Params, extra: &Xf) -> Result<(), SceneError> {
    let xf = Xf(extra.0 * s.state.ctm);
    let Some((name, mat)) = s.state.material.clone() else {
        p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
        return Ok(());
    };
    let material = r.model.material(&name, mat);
    if p.has("alpha") {
        r.cx.unsupported(
            p.file,
            p.line_of("alpha"),
            &format!("{} alpha", p.what),
            "opaque",
        )?;
    }
    let emission = s.state.area.as_ref().map(|a| Emission {
        radiance: a.radiance,
        flip: s.state.reverse ^ xf.swaps_handedness(),
        follow_normals: true,
        flip_normals: s.state.reverse,
    });
    let mesh = match s.kind.as_str() {
        "trianglemesh" => triangle_mesh(p, 3)?,
        "bilinearmesh" => triangle_mesh(p, 4)?,
        "loopsubdiv" => {
            p.ignore(&["levels"]);
            r.cx.unsupported(p.file, p.line, &p.what, "its control mesh")?;
            triangle_mesh(p, 3)?
        }
        "plymesh" => ply_mesh(r, p)?,
        "disk" => {
            let phi = p.float("phimax", 360.0)?.clamp(0.0, 360.0).to_radians();
            geometry::disc(
                p.float("radius", 1.0)?,
                p.float("innerradius", 0.0)?,
                p.float("height", 0.0)?,
                phi,
            )
        }
        "sphere" => return sphere(r, p, &xf, material, emission),
        "cylinder" => return cylinder(r, p, &xf, material, emission),
        _ => {
            p.ignore(&p.list.iter().map(|x| x.name.as_str()).collect::<Vec<_>>());
            return r.cx.unsupported(p.file, p.line, &p.what, "left out");
        }
    };
    let unpaired = geometry::place_mesh(&mut r.model, &mesh, &xf, material, emission);
    r.cx.unpaired_triangles(p.file, p.line, &p.what, unpaired)
}

fn ply_mesh(r: &mut Reader, p: &Params) -> Result<Mesh, SceneError> {
    let name = p
        .string("filename")?
        .ok_or_else(|| p.err(p.line, "filename", "is missing".into()))?;
    if p.has("displacement") {
        r.cx.unsupported(
            p.file,
            p.line_of("displacement"),
            &format!("{} displacement", p.what),
            "ignored",
        )?;
    }
    p.ignore(&["edgelength"]);
    let line = p.line_of("filename");
    let (path, bytes) =
        r.cx.read(&r.dir, &name)
            .map_err(|m| p.err(line, "filename", m))?;
    super::super::ply::parse_ply(&bytes)
        .map_err(|e| SceneError::new(&path, e.line, "(ply)", e.message))
}

fn full_turn(r: &mut Reader, p: &Params) -> Result<(), SceneError> {
    let phi = p.float("phimax", 360.0)?;
    let (zmin, zmax) = (p.has("zmin"), p.has("zmax"));
    if phi < 360.0 || (p.what.contains("sphere") && (zmin || zmax)) {
        p.unsupported(&mut r.cx, "cut (phimax, zmin, zmax)", "the whole shape")?;
    }
    Ok(())
}

fn sphere(
    r: &mut Reader,
    p: &Params,
    xf: &Xf,
    material: usize,
    emission: Option<Emission>,
) -> Result<(), SceneError> {
    let radius = p.float("radius", 1.0)?;
    p.float("zmin", -radius)?;
    p.float("zmax", radius)?;
    full_turn(r, p)?;
    let scale = match xf.uniform_scale() {
        Some(s) => s,
        None => {
            p.unsupported(
                &mut r.cx,
                "scaled unevenly (an ellipsoid)",
                "a sphere of the mean scale",
            )?;
            let m = glam::DMat3::from_mat4(xf.0);
            (m.x_axis.length() * m.y_axis.length() * m.z_axis.length()).cbrt()
        }
    };
    let sphere = (xf.point(DVec3::ZERO), radius.abs() * scale);
    let place = (p.file, p.line, p.what.as_str());
    let radiance = emission.map(|e| e.radiance);
    r.model
        .add_sphere(&mut r.cx, place, sphere, material, radiance)
}

fn cylinder(
    r: &mut Reader,
    p: &Params,
    xf: &Xf,
    material: usize,
    emission: Option<Emission>,
) -> Result<(), SceneError> {
    let radius = p.float("radius", 1.0)?;
    let (z0, z1) = (p.float("zmin", -1.0)?, p.float("zmax", 1.0)?);
    full_turn(r, p)?;
    if emission.is_some() {
        p.unsupported(&mut r.cx, "emitting", "kept without emission")?;
    }
    match geometry::cylinder(radius, z0, z1, xf) {
        Ok(s) => r.model.surfaces.push((s, material)),
        Err(mesh) => {
            geometry::place_mesh(&mut r.model, &mesh, xf, material, None);
        }
    }
    Ok(())
}
