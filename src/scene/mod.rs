//! The scene: a plain-Rust model of camera, shapes, materials, lights and the
//! paper's per-scene parameters, loaded from TOML (+ OBJ) and validated.

pub mod bvh;
pub mod camera_path;
pub mod defaults;
pub mod embedded;
pub mod file;
pub mod generate;
pub mod import;
pub mod load;
pub mod metals;
pub mod obj;
pub mod pack;
pub mod rebase;

use glam::{DVec3, Vec3};

pub use load::{
    load_scene, load_scene_str, load_scene_str_translated, load_scene_str_with_overrides,
    SceneError,
};
pub use rebase::Rebase;

#[derive(Clone, Debug)]
pub struct Camera {
    pub position: Vec3,
    pub look_at: Vec3,
    pub up: Vec3,
    /// Full vertical field of view, degrees.
    pub vfov_degrees: f32,
    pub width: u32,
    pub height: u32,
}

impl Camera {
    /// Orthonormal basis (right, up, backward) with the camera looking down -w.
    pub fn basis(&self) -> (Vec3, Vec3, Vec3) {
        let w = (self.position - self.look_at).normalize();
        let u = self.up.cross(w).normalize();
        let v = w.cross(u);
        (u, v, w)
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Material {
    /// Lambertian, BRDF = albedo / pi, the same on both sides.
    Diffuse { albedo: Vec3 },
    /// Perfect specular reflection scaled by `reflectance`, both sides.
    Mirror { reflectance: Vec3 },
    /// Smooth dielectric in air, exact unpolarised Fresnel, no absorption.
    Glass { ior: f32 },
    /// A metal, both sides: exact unpolarised Fresnel of the complex index
    /// eta + i k (per channel), times `tint`. `alpha` 0: smooth (a delta
    /// lobe, as a mirror); above 0: rough, an isotropic microfacet lobe of
    /// that alpha and `microfacet` model (glsl/common/bsdf.glsl).
    Conductor {
        eta: Vec3,
        k: Vec3,
        tint: Vec3,
        alpha: f32,
        microfacet: Microfacet,
    },
    /// An area light's surface: emits `radiance` on the side of `normal`, reflects
    /// nothing. `normal` None: each primitive's front face, the side of its
    /// geometric normal (e1 x e2; counter-clockwise winding), as for the
    /// emissive triangles of an OBJ mesh.
    Emitter {
        radiance: Vec3,
        normal: Option<Vec3>,
    },
}

/// A rough lobe's microfacet model: pbrt-v4's is Trowbridge-Reitz with
/// height-correlated masking; Mitsuba 3's is GGX or Beckmann with the
/// product of the two directions' G1.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Microfacet {
    pub beckmann: bool,
    pub separable: bool,
}

impl Microfacet {
    /// Mitsuba's `roughconductor` of the given distribution.
    pub fn mitsuba(beckmann: bool) -> Self {
        Self {
            beckmann,
            separable: true,
        }
    }

    /// The MICROFACET_* bits glsl/common/bsdf.glsl reads.
    pub fn bits(&self) -> u32 {
        u32::from(self.beckmann) * crate::layout::MICROFACET_BECKMANN
            + u32::from(self.separable) * crate::layout::MICROFACET_SEPARABLE
    }
}

impl Material {
    /// Whether it reflects or refracts other than diffusely: mirrors,
    /// glass and metals, smooth or rough. Photons that leave it make
    /// caustics, and projection maps aim at it.
    pub fn is_specular(&self) -> bool {
        matches!(
            self,
            Material::Mirror { .. } | Material::Glass { .. } | Material::Conductor { .. }
        )
    }

    /// Whether it has a glossy lobe (a rough metal): sampled and evaluated,
    /// neither a visible point nor one direction.
    pub fn is_glossy(&self) -> bool {
        matches!(self, Material::Conductor { alpha, .. } if *alpha > 0.0)
    }

    /// Its name in the scene format (`type = ...`), for messages.
    pub fn kind_name(&self) -> &'static str {
        match self {
            Material::Diffuse { .. } => "diffuse",
            Material::Mirror { .. } => "mirror",
            Material::Glass { .. } => "glass",
            Material::Conductor { alpha, .. } if *alpha > 0.0 => "rough conductor",
            Material::Conductor { .. } => "conductor",
            Material::Emitter { .. } => "emitter",
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Geometry {
    Sphere {
        center: Vec3,
        radius: f32,
    },
    /// Open cylinder: no caps, zero thickness; `axis` is a unit vector from the
    /// centre of the base circle, `height` along it.
    Cylinder {
        base: Vec3,
        axis: Vec3,
        radius: f32,
        height: f32,
    },
    /// Points corner + a*edge1 + b*edge2 for a, b in [0, 1].
    Parallelogram {
        corner: Vec3,
        edge1: Vec3,
        edge2: Vec3,
    },
    Triangle {
        v0: Vec3,
        v1: Vec3,
        v2: Vec3,
    },
}

impl Geometry {
    /// A flat shape's corners (a triangle's last one twice, so that every
    /// flat shape has four); None for a sphere or cylinder.
    pub fn flat_corners(&self) -> Option<[Vec3; 4]> {
        match *self {
            Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            } => Some([
                corner,
                corner + edge1,
                corner + edge2,
                corner + edge1 + edge2,
            ]),
            Geometry::Triangle { v0, v1, v2 } => Some([v0, v1, v2, v2]),
            Geometry::Sphere { .. } | Geometry::Cylinder { .. } => None,
        }
    }

    /// The shape scaled by `scale` and moved: `point` maps its points (the
    /// caller's scaling and move, in whatever precision it likes), and its
    /// lengths scale by `scale`; directions stay.
    pub fn scaled(&self, scale: f32, point: impl Fn(Vec3) -> Vec3) -> Geometry {
        match *self {
            Geometry::Sphere { center, radius } => Geometry::Sphere {
                center: point(center),
                radius: radius * scale,
            },
            Geometry::Cylinder {
                base,
                axis,
                radius,
                height,
            } => Geometry::Cylinder {
                base: point(base),
                axis,
                radius: radius * scale,
                height: height * scale,
            },
            Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            } => Geometry::Parallelogram {
                corner: point(corner),
                edge1: edge1 * scale,
                edge2: edge2 * scale,
            },
            Geometry::Triangle { v0, v1, v2 } => Geometry::Triangle {
                v0: point(v0),
                v1: point(v1),
                v2: point(v2),
            },
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shape {
    pub geometry: Geometry,
    pub material: usize,
    /// Vertex normals of a triangle (at v0, v1, v2; unit, on the side of its
    /// geometric normal), used as shading normals: interpolated across the
    /// triangle for the BSDF and for mirror and glass directions, while the
    /// geometric normal still decides sides and ray offsets. None for every
    /// other shape, and for triangles without them.
    pub normals: Option<[Vec3; 3]>,
}

impl Shape {
    /// A shape without vertex normals.
    pub fn new(geometry: Geometry, material: usize) -> Self {
        Shape {
            geometry,
            material,
            normals: None,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Light {
    /// One-sided parallelogram emitter of constant radiance; power = pi * area * Le.
    Area {
        corner: Vec3,
        edge1: Vec3,
        edge2: Vec3,
        normal: Vec3,
        radiance: Vec3,
    },
    /// Isotropic point light of radiant intensity I (W/sr); power = 4 pi I.
    Point { position: Vec3, intensity: Vec3 },
    /// The emissive triangles of one (object, material) group of an OBJ
    /// mesh: the triangle shapes `shapes[first..first + count]`, each
    /// emitting constant `radiance` from its front face (the side of its
    /// geometric normal). One light however many triangles: it is sampled by
    /// area (a triangle in proportion to its area, then a uniform point in
    /// it), so its shadow rays and photons cost what one area light's do.
    /// Power = pi * (total area) * radiance.
    Triangles {
        first: usize,
        count: usize,
        radiance: Vec3,
    },
}

impl Light {
    /// Radiant power (W per channel); `shapes` are the scene's, which
    /// `Triangles` lights index.
    pub fn power(&self, shapes: &[Shape]) -> Vec3 {
        match *self {
            Light::Area {
                edge1,
                edge2,
                radiance,
                ..
            } => std::f32::consts::PI * edge1.cross(edge2).length() * radiance,
            Light::Point { intensity, .. } => 4.0 * std::f32::consts::PI * intensity,
            Light::Triangles { radiance, .. } => {
                std::f32::consts::PI * self.area(shapes) * radiance
            }
        }
    }

    /// The emitting area: a parallelogram's, or the sum of a `Triangles`
    /// light's triangle areas (in f64, then f32); 0 for a point light.
    pub fn area(&self, shapes: &[Shape]) -> f32 {
        match *self {
            Light::Area { edge1, edge2, .. } => edge1.cross(edge2).length(),
            Light::Point { .. } => 0.0,
            Light::Triangles { first, count, .. } => shapes[first..first + count]
                .iter()
                .map(|s| f64::from(triangle_area(&s.geometry)))
                .sum::<f64>() as f32,
        }
    }
}

/// The surface area of a shape (a cylinder's side, with no caps).
pub fn surface_area(g: &Geometry) -> f32 {
    use std::f32::consts::PI;
    match *g {
        Geometry::Sphere { radius, .. } => 4.0 * PI * radius * radius,
        Geometry::Cylinder { radius, height, .. } => 2.0 * PI * radius * height,
        Geometry::Parallelogram { edge1, edge2, .. } => edge1.cross(edge2).length(),
        Geometry::Triangle { .. } => triangle_area(g),
    }
}

/// The area of a triangle (0 for any other geometry).
pub fn triangle_area(g: &Geometry) -> f32 {
    match *g {
        Geometry::Triangle { v0, v1, v2 } => 0.5 * (v1 - v0).cross(v2 - v0).length(),
        _ => 0.0,
    }
}

/// Ray-tracing parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderParams {
    /// Shadow rays per pixel to each area light (point lights always take one).
    pub shadow_rays: u32,
    /// Specular bounces an eye path may take before it is dropped.
    pub max_specular_depth: u32,
}

/// The paper's photon-map parameters (used by the photon and estimate stages).
#[derive(Clone, Debug, PartialEq)]
pub struct PhotonMapParams {
    /// Photons in the map (not emitted): 5,000 / 16,000 / 65,000 in the paper.
    pub photons_stored: u32,
    pub grid_resolution: [u32; 3],
    /// Grid bounds; None = fitted automatically.
    pub grid_bounds: Option<(Vec3, Vec3)>,
    /// Photons sought per radiance estimate.
    pub k: u32,
    pub max_radius: f32,
    pub max_bounces: u32,
    /// Store photons at their first diffuse hit too (off in the paper's split,
    /// where shadow rays count direct light; on for tests of the photon flux).
    pub store_direct: bool,
    /// Store caustic photons only (light, one or more specular bounces, then
    /// the first diffuse hit, where the photon ends). Photons then leave each
    /// light only through the cells of its projection map that can reach a
    /// specular object (Jensen's projection maps).
    pub caustics_only: bool,
    /// Store only photons whose last bounce was specular (a mirror or glass),
    /// tracing every path on through diffuse hits: all light that reaches a
    /// diffuse surface from a specular one, L (S|D)* S D, including the light
    /// a diffuse surface sends through mirrors and glass (L D S+ D), which
    /// point connections cannot carry. Set by IGI and radiosity for their
    /// caustic map; not a scene-file field.
    pub specular_last_only: bool,
    /// Cells per side of each light's projection map (caustics only).
    pub projection_resolution: u32,
}

#[derive(Clone, Debug)]
pub struct Scene {
    pub name: String,
    pub camera: Camera,
    pub materials: Vec<Material>,
    pub shapes: Vec<Shape>,
    pub lights: Vec<Light>,
    pub render: RenderParams,
    pub photon_map: PhotonMapParams,
    /// Where the scene's local origin stands in the world (its file's
    /// frame): every point above is relative to it. The loader reads points
    /// in f64 and rebases them (`rebase`) so that a scene far from the
    /// world's origin keeps f32's precision; the renderer, translation-
    /// invariant, works in the local frame. Zero for `with_shapes`.
    pub origin: DVec3,
}

impl Scene {
    /// Axis-aligned bounds of every shape (area lights included) and point light.
    pub fn bounds(&self) -> (Vec3, Vec3) {
        bounds_of(&self.shapes, &self.lights)
    }

    /// The longest side of the scene's bounds: its size, wherever it stands.
    pub fn size(&self) -> f32 {
        bounds_size(&self.shapes, &self.lights)
    }

    /// The largest coordinate magnitude over the scene's size, in the local
    /// frame the renderer works in: past ~1e3, f32 positions are coarse
    /// against the scene's own details, which blur. A loaded scene is
    /// rebased to its centre, so a scene that is merely far from the world's
    /// origin measures ~1 here; what remains large is a scene whose parts
    /// (camera included) are far from each other against its shapes' size.
    pub fn offset_ratio(&self) -> f32 {
        let (lo, hi) = self.bounds();
        let far = lo
            .abs()
            .max(hi.abs())
            .max_element()
            .max(self.camera.position.abs().max_element());
        far / self.size()
    }

    /// This scene with its photons bouncing up to `bounces` times: the
    /// methods that trace their own photons choose their bounces.
    pub fn with_max_bounces(&self, bounces: u32) -> Scene {
        let mut s = self.clone();
        s.photon_map.max_bounces = bounces;
        s
    }

    /// The first shape's material with a glossy lobe (a rough metal).
    pub fn glossy_material(&self) -> Option<&Material> {
        self.shapes
            .iter()
            .map(|s| &self.materials[s.material])
            .find(|m| m.is_glossy())
    }

    pub fn has_specular(&self) -> bool {
        self.shapes
            .iter()
            .any(|s| self.materials[s.material].is_specular())
    }

    /// Whether light can pass straight from one diffuse surface to another:
    /// false where every diffuse shape is flat and lies in one plane (GLASS
    /// BALL's and RING's floor), whose points see each other only edge-on.
    /// Planes are compared to a hundred-thousandth of the scene's size.
    pub fn has_diffuse_interreflection(&self) -> bool {
        let tolerance = 1e-5 * self.size();
        let mut plane: Option<(Vec3, f32)> = None;
        for s in &self.shapes {
            if !matches!(self.materials[s.material], Material::Diffuse { .. }) {
                continue;
            }
            let Some(corners) = s.geometry.flat_corners() else {
                return true;
            };
            let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]);
            if normal.length() == 0.0 {
                // No area: it reflects nothing.
                continue;
            }
            let (n, d) = *plane.get_or_insert_with(|| {
                let n = normal.normalize();
                (n, n.dot(corners[0]))
            });
            if corners.iter().any(|c| (n.dot(*c) - d).abs() > tolerance) {
                return true;
            }
        }
        false
    }
}

/// Axis-aligned bounds of these shapes (area lights included) and point lights.
fn bounds_of(shapes: &[Shape], lights: &[Light]) -> (Vec3, Vec3) {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    let mut add = |p: Vec3| {
        lo = lo.min(p);
        hi = hi.max(p);
    };
    for s in shapes {
        match s.geometry {
            Geometry::Sphere { center, radius } => {
                add(center - Vec3::splat(radius));
                add(center + Vec3::splat(radius));
            }
            Geometry::Cylinder {
                base,
                axis,
                radius,
                height,
            } => {
                for end in [base, base + axis * height] {
                    add(end - Vec3::splat(radius));
                    add(end + Vec3::splat(radius));
                }
            }
            Geometry::Parallelogram { .. } | Geometry::Triangle { .. } => {
                for p in s.geometry.flat_corners().into_iter().flatten() {
                    add(p);
                }
            }
        }
    }
    for l in lights {
        if let Light::Point { position, .. } = l {
            add(*position);
        }
    }
    (lo, hi)
}

/// The longest side of the bounds of these shapes and point lights (1 when
/// they have none): the scene's size, wherever it stands.
fn bounds_size(shapes: &[Shape], lights: &[Light]) -> f32 {
    let (lo, hi) = bounds_of(shapes, lights);
    let s = (hi - lo).max_element();
    if s.is_finite() && s > 0.0 {
        s
    } else {
        1.0
    }
}
