//! Plain-Rust twins of glsl/photon/: the photon tracer fed the same random
//! numbers (the same hash of the same streams), and stencil routing simulated
//! in draw order.

use glam::{Vec2, Vec3, Vec4};

use crate::photon::projection::{ProjectionMaps, ProjectionTexels};
use crate::scene::pack::PackedScene;
use crate::scene::{Material, Scene};

use super::bsdf::{rough_metal, sample as bsdf_sample, smooth_metal_factor, Frame};
use super::intersect::intersect_geometry;
use super::light::sample_light_triangle;
use super::random::{rng_init, rng_next};
use super::ray_trace::{closest_hit, offset_scale};
use super::shading::{
    diffuse_adjoint, facing_shading_normal, specular_about, specular_adjoint, specular_shaded,
};
pub use crate::sampling::{basis_around, sample_cosine, sample_sphere};

const PI: f32 = std::f32::consts::PI;

/// One texel of each photon texture.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PhotonRecord {
    pub position: Vec4,
    pub power: Vec4,
    pub incoming: Vec4,
    pub outgoing: Vec4,
}

pub(super) fn primitive_normal(scene: &Scene, prim: usize, p: Vec3) -> Vec3 {
    use crate::scene::Geometry::*;
    match scene.shapes[prim].geometry {
        Sphere { center, .. } => (p - center).normalize(),
        Cylinder { base, axis, .. } => {
            let r = p - base;
            (r - r.dot(axis) * axis).normalize()
        }
        Parallelogram { edge1, edge2, .. } => edge1.cross(edge2).normalize(),
        Triangle { v0, v1, v2 } => (v1 - v0).cross(v2 - v0).normalize(),
    }
}

fn leaving_factor(scene: &Scene, material: i32) -> Vec3 {
    if material < 0 {
        return Vec3::ONE;
    }
    match scene.materials[material as usize] {
        Material::Diffuse { albedo } => albedo / albedo.max_element(),
        _ => Vec3::ONE,
    }
}

const DEAD: PhotonRecord = PhotonRecord {
    position: Vec4::new(0.0, 0.0, 0.0, -1.0),
    power: Vec4::ZERO,
    incoming: Vec4::ZERO,
    outgoing: Vec4::new(0.0, 0.0, 0.0, -1.0),
};

/// glsl/photon/emit.frag for the photon at frame texel (x, y); `projection`
/// (texels and resolution) is its PROJECTION_MAPS variant.
pub fn emit(
    packed: &PackedScene,
    projection: Option<(&ProjectionTexels, u32)>,
    seed: u32,
    emitted: u32,
    width: u32,
    x: u32,
    y: u32,
) -> PhotonRecord {
    if y * width + x >= emitted {
        return DEAD;
    }
    let mut rng = rng_init(seed, [x, y], 0x10000000);
    let pick = rng_next(&mut rng);
    let light_row = |l: usize, i: usize| Vec4::from(packed.lights[l * 6 + i]);
    let mut l = 0;
    let cdf = |l: usize| match projection {
        Some((t, _)) => t.texel(l, 0).x,
        None => light_row(l, 5).x,
    };
    while l + 1 < packed.light_count && pick >= cdf(l) {
        l += 1;
    }
    let choice = light_row(l, 5);
    let head = light_row(l, 0);
    let a = light_row(l, 1).truncate();
    let mut emitted_radiance = light_row(l, 4).truncate();
    let (mut u1, mut u2, mut u3, mut u4) = (
        rng_next(&mut rng),
        rng_next(&mut rng),
        rng_next(&mut rng),
        rng_next(&mut rng),
    );
    let mut probability = choice.y;
    if let Some((t, resolution)) = projection {
        let kept = t.texel(l, 0);
        probability = kept.y;
        let count = kept.w as i32;
        let c = ((rng_next(&mut rng) * count as f32) as i32).min(count - 1) as usize;
        let cell = t.texel(l, 1 + c / 4)[c % 4];
        let n = resolution as f32;
        let row = (cell / n).floor();
        let column = cell - row * n;
        if head.x as i32 == 1 {
            u1 = (column + u1) / n;
            u2 = (row + u2) / n;
        } else {
            u3 = (column + u3) / n;
            u4 = (row + u4) / n;
        }
        emitted_radiance *= kept.z;
    }
    let mut leaving = choice.z;
    let (p, d, power) = if head.x as i32 == 1 {
        (a, sample_sphere(u1, u2), 4.0 * PI * emitted_radiance)
    } else if head.x as i32 == 2 {
        let (p, normal, prim) = sample_light_triangle(packed, l, u1, u2);
        leaving = prim as f32;
        (
            p,
            sample_cosine(normal, u3, u4),
            PI * light_row(l, 1).z * emitted_radiance,
        )
    } else {
        let (e1, e2) = (light_row(l, 2).truncate(), light_row(l, 3).truncate());
        (
            a + u1 * e1 + u2 * e2,
            sample_cosine(Vec3::new(head.y, head.z, head.w), u3, u4),
            PI * e1.cross(e2).length() * emitted_radiance,
        )
    };
    PhotonRecord {
        position: p.extend(-1.0),
        power: (power / (emitted as f32 * probability)).extend(0.0),
        incoming: Vec4::new(0.0, 0.0, 0.0, 1.0),
        outgoing: d.extend(leaving),
    }
}

/// glsl/photon/bounce.glsl: bounce `bounce` of a photon whose last record is `last`.
pub fn bounce(
    scene: &Scene,
    seed: u32,
    bounce: u32,
    x: u32,
    local_y: u32,
    last: &PhotonRecord,
) -> PhotonRecord {
    if last.incoming.w == 0.0 {
        return DEAD;
    }
    let floor = 1e-6 * scene.size();
    let power = last.power.truncate() * leaving_factor(scene, last.position.w as i32);
    let d = last.outgoing.truncate();
    let last_prim = last.outgoing.w as i32;
    let mut origin = last.position.truncate();
    if last_prim >= 0 {
        let n = primitive_normal(scene, last_prim as usize, origin);
        let s = offset_scale(origin, floor);
        origin += if d.dot(n) >= 0.0 { s } else { -s } * n;
    }
    let Some((prim, _t, p, n)) = closest_hit(scene, origin, d) else {
        return DEAD;
    };
    let mat = scene.shapes[prim].material;
    let material = scene.materials[mat];
    if matches!(material, Material::Emitter { .. }) {
        return DEAD;
    }
    let nf = if n.dot(d) < 0.0 { n } else { -n };
    let mut rng = rng_init(seed, [x, local_y], 0x10000000 + bounce);
    let (u0, u1, u2) = (rng_next(&mut rng), rng_next(&mut rng), rng_next(&mut rng));
    let (mut stored, mut alive) = (false, true);
    let shape = &scene.shapes[prim];
    let shaded = shape.normals.is_some();
    let ms = facing_shading_normal(shape, p, n, d);
    let mut power = power;
    let next = match material {
        Material::Diffuse { albedo } => {
            stored = bounce >= 2 || scene.photon_map.store_direct;
            let last_mat = last.position.w as i32;
            let after_specular = last_mat >= 0
                && !matches!(scene.materials[last_mat as usize], Material::Diffuse { .. });
            if scene.photon_map.specular_last_only {
                stored = stored && after_specular;
            }
            alive = !scene.photon_map.caustics_only && u0 < albedo.max_element();
            if shaded {
                power *= diffuse_adjoint(d, nf, ms);
            }
            sample_cosine(nf, u1, u2)
        }
        Material::Conductor { .. } if material.is_glossy() => {
            let b = rough_metal(&material).expect("a rough metal");
            let s = bsdf_sample(&b, &Frame::around(ms), -d, Vec2::new(u1, u2));
            alive = s.lobe != 0 && s.wi.dot(nf) > 0.0;
            let next = if alive { s.wi } else { d };
            power *= if alive { s.weight } else { Vec3::ZERO };
            if shaded && alive {
                power *= specular_adjoint(d, next, nf, ms);
            }
            next
        }
        Material::Mirror { .. } | Material::Glass { .. } | Material::Conductor { .. } => {
            let ior = match material {
                Material::Glass { ior } => ior,
                _ => 0.0,
            };
            let entering = n.dot(d) < 0.0;
            let (next, used) = if shaded {
                let (next, used) = specular_shaded(d, nf, ms, ior, entering, u0);
                if used {
                    power *= specular_adjoint(d, next, nf, ms);
                }
                (next, used)
            } else {
                (specular_about(d, nf, ior, entering, u0), false)
            };
            if let Material::Mirror { reflectance } = material {
                power *= reflectance;
            }
            power *= smooth_metal_factor(&material, d, if used { ms } else { nf });
            next
        }
        Material::Emitter { .. } => unreachable!(),
    };
    PhotonRecord {
        position: p.extend(mat as f32),
        power: power.extend(if stored { 1.0 } else { 0.0 }),
        incoming: d.extend(if alive { 1.0 } else { 0.0 }),
        outgoing: next.normalize().extend(prim as f32),
    }
}

/// Every record of every frame, row 0 of frame 0 first (the GPU texture
/// layout), aimed by `projection` when given (as the GPU tracer is when the
/// scene stores caustics only).
pub fn trace_photons(
    scene: &Scene,
    projection: Option<&ProjectionMaps>,
    seed: u32,
    emitted: u32,
    width: u32,
    frame_height: u32,
) -> Vec<PhotonRecord> {
    let packed = PackedScene::new(scene);
    let texels = projection.map(|p| (p.texels(scene), p.resolution));
    let projection = texels.as_ref().map(|(t, r)| (t, *r));
    let frames = scene.photon_map.max_bounces + 1;
    let per_frame = (width * frame_height) as usize;
    let mut out = vec![DEAD; per_frame * frames as usize];
    for y in 0..frame_height {
        for x in 0..width {
            let i = (y * width + x) as usize;
            out[i] = emit(&packed, projection, seed, emitted, width, x, y);
            for b in 1..frames {
                let last = out[(b as usize - 1) * per_frame + i];
                out[b as usize * per_frame + i] = bounce(scene, seed, b, x, y, &last);
            }
        }
    }
    out
}

/// Whether any primitive other than the closest lies within `eps` of its
/// distance (a near-tie that f32 rounding may decide either way).
pub fn near_tie(scene: &Scene, o: Vec3, d: Vec3, eps: f32) -> bool {
    let mut ts: Vec<f32> = scene
        .shapes
        .iter()
        .filter_map(|s| intersect_geometry(&s.geometry, o, d).map(|h| h.0))
        .collect();
    ts.sort_by(f32::total_cmp);
    ts.windows(2).any(|w| w[1] - w[0] < eps * w[0].max(1.0))
}

/// Stencil routing in draw order: `cells[i]` is record i's cell (None: not
/// drawn). Returns, per cell, the records in slot order (slot m^2-1 first) and
/// how many were destined.
pub fn route(cells: &[Option<u32>], cell_count: u32, block: u32) -> (Vec<Vec<usize>>, Vec<u32>) {
    let slots = (block * block) as usize;
    let mut stored = vec![Vec::new(); cell_count as usize];
    let mut destined = vec![0u32; cell_count as usize];
    for (record, cell) in cells.iter().enumerate() {
        if let Some(c) = *cell {
            destined[c as usize] += 1;
            if stored[c as usize].len() < slots {
                stored[c as usize].push(record);
            }
        }
    }
    (stored, destined)
}

/// Stencil routing into a hashed grid (section 4.4) in draw order, with the
/// exact redistribution of glsl/photon/count_cell.frag and redistribute.frag.
#[derive(Clone, Debug, Default)]
pub struct HashedRoute {
    /// Per bucket: the records kept, in slot order (slot m^2-1 first).
    pub stored: Vec<Vec<usize>>,
    /// Per bucket: how many records were destined to it.
    pub destined: Vec<u32>,
    /// Per record: destined / kept of its own cell (0 where not kept).
    pub scale: Vec<f32>,
    /// Records of cells that their bucket kept none of: their power is lost.
    pub lost: Vec<usize>,
}

/// `cells[i]`: record i's cell (None: not drawn); buckets by `bucket_of`.
pub fn route_hashed(
    cells: &[Option<u32>],
    buckets: u32,
    block: u32,
    bucket_of: &dyn Fn(u32) -> u32,
) -> HashedRoute {
    use std::collections::HashMap;
    let slots = (block * block) as usize;
    let mut r = HashedRoute {
        stored: vec![Vec::new(); buckets as usize],
        destined: vec![0; buckets as usize],
        scale: vec![0.0; cells.len()],
        lost: Vec::new(),
    };
    let (mut destined, mut kept) = (HashMap::new(), HashMap::new());
    for (record, cell) in cells.iter().enumerate() {
        if let Some(c) = *cell {
            let b = bucket_of(c) as usize;
            r.destined[b] += 1;
            *destined.entry(c).or_insert(0u32) += 1;
            if r.stored[b].len() < slots {
                r.stored[b].push(record);
                *kept.entry(c).or_insert(0u32) += 1;
            }
        }
    }
    for kept_records in &r.stored {
        for &record in kept_records {
            let c = cells[record].unwrap_or_default();
            r.scale[record] = destined[&c] as f32 / kept[&c] as f32;
        }
    }
    r.lost = (0..cells.len())
        .filter(|&i| cells[i].is_some_and(|c| !kept.contains_key(&c)))
        .collect();
    r
}
