//! Regions of the image that an error can be split by: the diffuse surfaces
//! the pixels see first, read back from the ray tracer's own first-hit
//! record, and rectangles the user names (`NAME=X0:X1:Y0:Y1`). `bench
//! accuracy --regions` reports each method's energy and error in each, and
//! `bench mitsuba --region` each image's energy in the rectangles.

use crate::gpu::{Gpu, Result};
use crate::render::{render, Image, RenderOptions};
use crate::scene::{Geometry, Scene};

/// A named set of pixels (top row first, as [`crate::render::Image`]).
#[derive(Clone, Debug)]
pub struct Region {
    pub name: String,
    pub pixels: Vec<bool>,
}

impl Region {
    pub fn count(&self) -> usize {
        self.pixels.iter().filter(|&&p| p).count()
    }
}

/// A rectangle of pixels: columns `x0..x1`, rows `y0..y1` (row 0 at the top).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Rectangle {
    pub name: String,
    pub x0: u32,
    pub x1: u32,
    pub y0: u32,
    pub y1: u32,
}

/// An image's mean over a reference's in one region (channels together).
#[derive(serde::Serialize, Clone, Debug)]
pub struct RegionEnergy {
    pub name: String,
    /// Its pixels.
    pub pixels: usize,
    pub energy: f64,
}

/// Each region's energy: `image`'s sum over `reference`'s on its pixels.
pub fn region_energies(regions: &[Region], image: &Image, reference: &Image) -> Vec<RegionEnergy> {
    let sum = |img: &Image, r: &Region| -> f64 {
        img.pixels
            .iter()
            .zip(&r.pixels)
            .filter(|(_, &inside)| inside)
            .map(|(p, _)| p.iter().map(|&v| f64::from(v)).sum::<f64>())
            .sum()
    };
    regions
        .iter()
        .map(|r| RegionEnergy {
            name: r.name.clone(),
            pixels: r.count(),
            energy: sum(image, r) / sum(reference, r),
        })
        .collect()
}

/// `rectangles` as regions of a `width` x `height` image, each less what
/// `mask` leaves out; refused (naming the option, `--region`) when one lies
/// outside the image or keeps no pixel.
pub fn masked_rectangles(
    rectangles: &[Rectangle],
    (width, height): (u32, u32),
    mask: Option<&[bool]>,
) -> std::result::Result<Vec<Region>, String> {
    let mut out = Vec::new();
    for r in rectangles {
        let shown = format!("--region {}={}:{}:{}:{}", r.name, r.x0, r.x1, r.y0, r.y1);
        if r.x1 > width || r.y1 > height {
            return Err(format!("{shown}: outside the {width} x {height} pixels"));
        }
        let mut region = r.region(width, height);
        if let Some(m) = mask {
            region.pixels.iter_mut().zip(m).for_each(|(p, &k)| *p &= k);
        }
        if region.count() == 0 {
            return Err(format!("{shown}: the mask leaves none of its pixels"));
        }
        out.push(region);
    }
    Ok(out)
}

/// `NAME=X0:X1:Y0:Y1`: whole pixels, X0 < X1, Y0 < Y1, ends excluded (the
/// form `--region` takes).
impl std::str::FromStr for Rectangle {
    type Err = String;

    fn from_str(text: &str) -> std::result::Result<Self, String> {
        let usage =
            || format!("{text:?}: expected NAME=X0:X1:Y0:Y1 (whole pixels, X0 < X1, Y0 < Y1)");
        let (name, bounds) = text.rsplit_once('=').ok_or_else(usage)?;
        let numbers: Vec<u32> = bounds
            .split(':')
            .map(str::parse)
            .collect::<std::result::Result<_, _>>()
            .map_err(|_| usage())?;
        match numbers[..] {
            [x0, x1, y0, y1] if !name.is_empty() && x0 < x1 && y0 < y1 => Ok(Rectangle {
                name: name.to_string(),
                x0,
                x1,
                y0,
                y1,
            }),
            _ => Err(usage()),
        }
    }
}

impl Rectangle {
    /// The rectangle's pixels in a `width` x `height` image (clipped to it).
    pub fn region(&self, width: u32, height: u32) -> Region {
        let pixels = (0..height)
            .flat_map(|y| (0..width).map(move |x| (x, y)))
            .map(|(x, y)| (self.x0..self.x1).contains(&x) && (self.y0..self.y1).contains(&y))
            .collect();
        Region {
            name: self.name.clone(),
            pixels,
        }
    }
}

/// One region per diffuse surface that some pixel centre sees first, in the
/// order of the scene's shapes: coplanar primitives of one material (a wall
/// of two triangles) are one surface. Pixels whose first hit is a light, a
/// mirror, glass or nothing belong to none. Rendered at `width` x `height`
/// with one eye ray a pixel and no specular bounce, so that the record is of
/// the first hit itself.
pub fn first_hit_regions(gpu: &Gpu, scene: &Scene, width: u32, height: u32) -> Result<Vec<Region>> {
    let mut first = scene.clone();
    first.render.max_specular_depth = 0;
    first.render.shadow_rays = 1;
    let mut options = RenderOptions::for_scene(&first).direct_only();
    (options.width, options.height) = (width, height);
    let out = render(gpu, &first, &options, &mut ())?;
    let position = out.state.direct.diffuse_position.read_f32();
    let throughput = out.state.direct.diffuse_throughput.read_f32();
    let surfaces = surfaces_of(scene);
    let mut regions: Vec<(usize, Region)> = Vec::new();
    let mut index_of_surface = vec![None; surfaces.names.len()];
    let pixels = (width * height) as usize;
    // GL rows are bottom first; regions are top first.
    for (i, (p, t)) in position.chunks(4).zip(throughput.chunks(4)).enumerate() {
        let primitive = t[3].round();
        if p[3] < 0.5 || primitive < 0.0 || primitive as usize >= scene.shapes.len() {
            continue;
        }
        let surface = surfaces.of_shape[primitive as usize];
        let r = *index_of_surface[surface].get_or_insert_with(|| {
            let name = surfaces.names[surface].clone();
            let pixels = vec![false; pixels];
            regions.push((surface, Region { name, pixels }));
            regions.len() - 1
        });
        let (x, row) = (i as u32 % width, i as u32 / width);
        regions[r].1.pixels[((height - 1 - row) * width + x) as usize] = true;
    }
    regions.sort_by_key(|(surface, _)| *surface);
    Ok(regions.into_iter().map(|(_, r)| r).collect())
}

/// The scene's surfaces: every shape's surface, and each surface's name.
struct Surfaces {
    of_shape: Vec<usize>,
    names: Vec<String>,
}

/// Groups coplanar parallelograms and triangles of one material into one
/// surface (planes compared to a thousandth of the scene's size); every other
/// shape is its own.
fn surfaces_of(scene: &Scene) -> Surfaces {
    let size = scene.size().max(f32::MIN_POSITIVE);
    let mut keys: Vec<Option<(usize, [i64; 4])>> = Vec::new();
    let mut names = Vec::new();
    let mut of_shape = Vec::with_capacity(scene.shapes.len());
    for (i, s) in scene.shapes.iter().enumerate() {
        let plane = match s.geometry {
            Geometry::Parallelogram {
                corner,
                edge1,
                edge2,
            } => Some((corner, edge1.cross(edge2))),
            Geometry::Triangle { v0, v1, v2 } => Some((v0, (v1 - v0).cross(v2 - v0))),
            _ => None,
        };
        let key = plane.filter(|(_, n)| n.length() > 0.0).map(|(p, n)| {
            let n = n.normalize();
            let q = |v: f32| (v * 1000.0).round() as i64;
            (s.material, [q(n.x), q(n.y), q(n.z), q(n.dot(p) / size)])
        });
        let existing = key.and_then(|k| keys.iter().position(|e| *e == Some(k)));
        of_shape.push(existing.unwrap_or_else(|| {
            keys.push(key);
            names.push(surface_name(
                scene,
                i,
                plane.map(|(p, n)| (p, n.normalize())),
            ));
            keys.len() - 1
        }));
    }
    Surfaces { of_shape, names }
}

/// "plane y = 2.000 (facing -y), material 0", "sphere 5 at (-0.45, 0.35, -0.35)".
fn surface_name(scene: &Scene, shape: usize, plane: Option<(glam::Vec3, glam::Vec3)>) -> String {
    let s = &scene.shapes[shape];
    let at = |p: glam::Vec3| format!("({:.2}, {:.2}, {:.2})", p.x, p.y, p.z);
    match (plane, s.geometry) {
        (Some((p, n)), _) => {
            let axis = (0..3).find(|&a| n[a].abs() > 0.999);
            match axis {
                Some(a) => {
                    let letter = ["x", "y", "z"][a];
                    let sign = if n[a] > 0.0 { "+" } else { "-" };
                    format!(
                        "plane {letter} = {:.3} (facing {sign}{letter}), material {}",
                        p[a], s.material
                    )
                }
                None => format!(
                    "plane through {} facing {}, material {}",
                    at(p),
                    at(n),
                    s.material
                ),
            }
        }
        (None, Geometry::Sphere { center, .. }) => format!("sphere {shape} at {}", at(center)),
        (None, Geometry::Cylinder { base, .. }) => format!("cylinder {shape} at {}", at(base)),
        (None, _) => format!("shape {shape}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A region's energy is the image's sum over the reference's on its
    /// pixels alone, channels together; a masked-out or outside rectangle is
    /// refused.
    #[test]
    fn region_energy_is_the_ratio_of_the_region_sums() {
        let mut image = Image::new(2, 2);
        let mut reference = Image::new(2, 2);
        image.pixels = vec![[1.0, 2.0, 3.0], [9.0; 3], [4.0; 3], [0.0; 3]];
        reference.pixels = vec![[2.0; 3], [1.0; 3], [2.0; 3], [5.0; 3]];
        let left: Rectangle = "left=0:1:0:2".parse().unwrap();
        let regions = masked_rectangles(std::slice::from_ref(&left), (2, 2), None).unwrap();
        let e = region_energies(&regions, &image, &reference);
        assert_eq!((e[0].name.as_str(), e[0].pixels), ("left", 2));
        assert!((e[0].energy - (6.0 + 12.0) / (6.0 + 6.0)).abs() < 1e-12);
        let mask = [false, true, false, true];
        let err = masked_rectangles(&[left], (2, 2), Some(&mask)).unwrap_err();
        assert!(err.contains("the mask leaves none"), "{err}");
        let wide: Rectangle = "wide=0:3:0:1".parse().unwrap();
        let err = masked_rectangles(&[wide], (2, 2), None).unwrap_err();
        assert!(err.contains("outside the 2 x 2 pixels"), "{err}");
    }

    #[test]
    fn rectangles_parse_and_refuse() {
        let r: Rectangle = "under the balls=0:256:190:215".parse().unwrap();
        assert_eq!(
            (r.name.as_str(), r.x0, r.x1, r.y0, r.y1),
            ("under the balls", 0, 256, 190, 215)
        );
        for bad in [
            "ceiling",
            "=0:1:0:1",
            "a=0:1:0",
            "a=1:1:0:1",
            "a=0:1:x:1",
            "a=0:1:0:-1",
        ] {
            assert!(bad.parse::<Rectangle>().is_err(), "{bad}");
        }
    }
}
