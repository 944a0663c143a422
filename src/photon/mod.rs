//! Figure 1's "trace photons" and "build photon map" boxes: breadth-first photon
//! tracing into frames of photon textures (section 2.1), and the two photon-map
//! builds, bitonic merge sort + binary search (2.2.1) and stencil routing (2.2.2).

pub mod bitonic;
pub mod build;
pub mod compaction;
pub mod counting;
pub mod differentials;
pub mod fit;
pub mod halton;
pub mod projection;
pub mod stencil_routing;
pub mod trace;

use glam::{IVec3, Vec3};

use crate::gpu::Bindings;
use crate::scene::Scene;

pub use bitonic::{BitonicBuild, SortedPhotonMap};
pub use build::{build_map, check_storage, BuiltMap, PhotonConfig};
pub use counting::CountingBuild;
pub use halton::{RandomSource, ScrambledHalton, HALTON_DIMENSIONS};
pub use projection::ProjectionMaps;
pub use stencil_routing::{LostPower, RoutedPhotonMap, StencilRouting, VertexFeed};
pub use trace::{PhotonBatch, PhotonFrames, PhotonTracer, TraceConfig, TraceReport};

/// The grid photons are sorted or routed into.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    pub min: Vec3,
    pub max: Vec3,
    pub resolution: [u32; 3],
    /// Where the photons of a cell are kept: in the cell's own slot, or in a
    /// hash table's bucket (section 4.4).
    pub storage: GridStorage,
}

/// How a grid stores its cells (`--grid`, `--hash-buckets`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GridStorage {
    /// One slot per cell (cells + 1 first indices, or a block per cell):
    /// every empty cell costs its slot.
    Uniform,
    /// Section 4.4: photons kept in `buckets` hash buckets by their cell's
    /// address (`cell_slot`); a search rejects bucket-mates of other cells.
    Hashed { buckets: u32 },
}

/// The `--grid` choice, before the bucket count is known.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum GridKind {
    /// One slot per cell (the paper's uniform grid).
    #[default]
    Uniform,
    /// A hash table of buckets keyed by the cell's address (section 4.4).
    Hash,
}

/// The bucket of `cell` in a table of `buckets`: the PCG hash of the cell's
/// index, modulo the bucket count. grid_slot in glsl/common/grid.glsl is the
/// same arithmetic (uint, wrapping).
pub fn hash_bucket(cell: u32, buckets: u32) -> u32 {
    crate::random::pcg_hash(cell) % buckets
}

impl Grid {
    /// The scene's grid: its bounds if it fixes them, else the scene's bounds
    /// padded by a thousandth of its size so surfaces on the boundary fall inside.
    pub fn for_scene(scene: &Scene) -> Self {
        let (min, max) = scene.photon_map.grid_bounds.unwrap_or_else(|| {
            let (lo, hi) = scene.bounds();
            let pad = Vec3::splat(1e-3 * scene.size());
            (lo - pad, hi + pad)
        });
        Self {
            min,
            max,
            resolution: scene.photon_map.grid_resolution,
            storage: GridStorage::Uniform,
        }
    }

    /// The same cells stored as `storage` says.
    pub fn with_storage(self, storage: GridStorage) -> Self {
        Self { storage, ..self }
    }

    /// Hash buckets, or None for a uniform grid.
    pub fn buckets(&self) -> Option<u32> {
        match self.storage {
            GridStorage::Uniform => None,
            GridStorage::Hashed { buckets } => Some(buckets),
        }
    }

    /// Slots the map keeps: one per cell, or one per bucket. The sorted map's
    /// first-index texture has slots + 1 entries; stencil routing a block per slot.
    pub fn slot_count(&self) -> u32 {
        self.buckets().unwrap_or_else(|| self.cell_count())
    }

    /// The slot holding `cell`'s photons: the cell itself, or its bucket.
    pub fn slot_of_cell(&self, cell: u32) -> u32 {
        match self.storage {
            GridStorage::Uniform => cell,
            GridStorage::Hashed { buckets } => hash_bucket(cell, buckets),
        }
    }

    /// The slot of point p (None outside the grid): the sort key of grid.glsl's grid_key.
    pub fn slot_of(&self, p: Vec3) -> Option<u32> {
        self.cell_of(p).map(|c| self.slot_of_cell(c))
    }

    /// A grid over the whole scene (its box padded by a thousandth of its
    /// size, whatever bounds the scene fixes for the paper's estimate) with
    /// cells of about `cell` on every axis, at most 512 a side and
    /// `max_cells` in all (cells grow until they fit).
    pub fn over_scene(scene: &Scene, cell: f32, max_cells: u64) -> Self {
        let (lo, hi) = scene.bounds();
        let pad = Vec3::splat(1e-3 * scene.size());
        let (min, max) = (lo - pad, hi + pad);
        let extent = max - min;
        let mut cell = cell.max(extent.max_element() / 512.0);
        loop {
            let resolution: [u32; 3] =
                std::array::from_fn(|a| ((extent[a] / cell).ceil() as u32).clamp(1, 512));
            if resolution.iter().map(|&r| r as u64).product::<u64>() <= max_cells {
                return Self {
                    min,
                    max,
                    resolution,
                    storage: GridStorage::Uniform,
                };
            }
            cell *= 1.25;
        }
    }

    /// Cells along x, y and z.
    pub fn sides(&self) -> IVec3 {
        IVec3::from_array(self.resolution.map(|r| r as i32))
    }

    /// A cell's extent along each axis.
    pub fn cell_size(&self) -> Vec3 {
        (self.max - self.min) / self.sides().as_vec3()
    }

    pub fn cell_count(&self) -> u32 {
        self.resolution.iter().product()
    }

    /// Cells as u64 (a grid of 1024^3 cells still fits u32; the product of
    /// three unchecked sides might not).
    pub fn cells_u64(&self) -> u64 {
        self.resolution.iter().map(|&r| r as u64).product()
    }

    /// The cell of p, or None outside the closed bounds: the arithmetic of
    /// glsl/common/grid.glsl.
    pub fn cell_of(&self, p: Vec3) -> Option<u32> {
        let res = Vec3::new(
            self.resolution[0] as f32,
            self.resolution[1] as f32,
            self.resolution[2] as f32,
        );
        let f = (p - self.min) / (self.max - self.min) * res;
        if f.cmplt(Vec3::ZERO).any() || f.cmpgt(res).any() || !f.is_finite() {
            return None;
        }
        let c = f.floor().min(res - Vec3::ONE);
        let [x, y, z] = [c.x as u32, c.y as u32, c.z as u32];
        Some(x + self.resolution[0] * (y + self.resolution[1] * z))
    }

    pub fn bind(&self, b: &mut Bindings<'_>) {
        b.vec3("u_grid_min", self.min.to_array())
            .vec3("u_grid_max", self.max.to_array())
            .ivec3("u_grid_resolution", self.sides().to_array())
            .int("u_hash_buckets", self.buckets().unwrap_or(0) as i32);
    }
}

/// Which photon-map build to run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
pub enum BuildMethod {
    /// Counting sort into the grid: a slot histogram, its prefix sums by
    /// HistoPyramid and one pass placing each photon; O(log n) passes, the
    /// bitonic build's map (`--faithful` takes the bitonic sort).
    Counting,
    /// Bitonic merge sort + binary search (section 2.2.1): exact, O(log^2 n) passes.
    Bitonic,
    /// Stencil routing (section 2.2.2): one pass, at most m^2 photons a cell.
    Stencil,
}

impl std::fmt::Display for BuildMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            BuildMethod::Counting => "counting sort + HistoPyramid prefix sums",
            BuildMethod::Bitonic => "bitonic sort + binary search",
            BuildMethod::Stencil => "stencil routing",
        })
    }
}

/// A photon map from either build.
pub enum PhotonMap {
    Sorted(SortedPhotonMap),
    Routed(RoutedPhotonMap),
}

impl PhotonMap {
    pub fn grid(&self) -> &Grid {
        match self {
            PhotonMap::Sorted(m) => &m.grid,
            PhotonMap::Routed(m) => &m.grid,
        }
    }

    /// Each photon's direction of arrival.
    pub fn incoming(&self) -> &crate::gpu::Texture {
        match self {
            PhotonMap::Sorted(m) => &m.incoming,
            PhotonMap::Routed(m) => &m.incoming,
        }
    }

    /// The map and its grid as glsl/common/photon_map.glsl declares them
    /// (the build's layout: sorted, or ROUTED).
    pub fn bind(&self, b: &mut Bindings<'_>) {
        match self {
            PhotonMap::Sorted(m) => {
                b.texture("u_map_position", &m.position)
                    .texture("u_map_power", &m.power)
                    .texture("u_grid_first", &m.grid_first)
                    .int("u_grid_width", m.grid_width as i32)
                    .int("u_sorted_width", m.position.width as i32);
            }
            PhotonMap::Routed(m) => {
                b.texture("u_map_position", &m.position)
                    .texture("u_map_power", &m.power)
                    .texture("u_map_counts", &m.counts)
                    .int("u_count_width", m.count_width as i32)
                    .int("u_block", m.block as i32)
                    .int("u_blocks_per_row", m.blocks_per_row as i32);
            }
        }
        self.grid().bind(b);
    }

    /// Texels of the grid's own structure: the sorted map's first-index
    /// texture (slots + 1 entries, as laid out), or stencil routing's
    /// routing buffer plus its count textures (the memory §4.4 is about).
    pub fn grid_texels(&self) -> u64 {
        match self {
            PhotonMap::Sorted(m) => m.grid_first.texel_count() as u64,
            PhotonMap::Routed(m) => {
                (m.position.texel_count()
                    + m.counts.texel_count()
                    + m.cell_counts.as_ref().map_or(0, |c| c.texel_count())) as u64
            }
        }
    }

    /// Photons destined to each slot (read back): the sorted map's slot
    /// ranges, or stencil routing's exact counts (which may exceed m^2). A
    /// slot is a cell of a uniform grid, or a bucket of a hashed one.
    pub fn photons_per_cell(&self) -> Vec<u32> {
        let cells = self.grid().slot_count() as usize;
        match self {
            PhotonMap::Sorted(m) => {
                let first: Vec<i32> = m.grid_first.read_i32().chunks(4).map(|c| c[0]).collect();
                (0..cells)
                    .map(|c| (first[c + 1] - first[c]) as u32)
                    .collect()
            }
            PhotonMap::Routed(m) => m
                .counts
                .read_f32()
                .chunks(4)
                .take(cells)
                .map(|c| c[0] as u32)
                .collect(),
        }
    }
}

/// Times one stage of a build: GPU time by timer query, wall clock with the
/// GPU finished at both ends (llvmpipe's timer queries miss work; see timing).
pub(crate) struct StageClock<'a> {
    gpu: &'a crate::gpu::Gpu,
    query: &'a crate::gpu::Query,
    start: std::time::Instant,
}

impl<'a> StageClock<'a> {
    pub(crate) fn start(gpu: &'a crate::gpu::Gpu, query: &'a crate::gpu::Query) -> Self {
        gpu.finish();
        query.begin();
        Self {
            gpu,
            query,
            start: std::time::Instant::now(),
        }
    }

    pub(crate) fn stop(self, timings: &mut crate::timing::Timings, name: &str, passes: usize) {
        self.query.end();
        self.gpu.finish();
        let wall = self.start.elapsed().as_secs_f64();
        timings.add_both(name, self.query.seconds(), wall, passes);
    }
}

/// The smallest power of two >= n.
pub fn next_power_of_two(n: u64) -> u64 {
    n.max(1).next_power_of_two()
}
