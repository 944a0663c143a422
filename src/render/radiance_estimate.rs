//! Figure 1's "radiance estimate" box (sections 2.3, 3.3, 3.4): the kNN-grid
//! search in many bounded passes, drawn as 16 x 16 point tiles that stop by
//! occlusion query (or full screen, or full screen behind a per-pixel stencil
//! mask), and the composed image, also of the running estimate.

use crate::gpu::{Bindings, DrawState, Gpu, Program, Query, Result, Target, TexFormat, Texture};
use crate::photon::PhotonMap;
use crate::scene::pack::SceneTextures;

pub use super::direct::QueryPoints;
use super::search_work::{LaneUse, SearchWork};
use super::{DirectLight, Image};

/// How the search passes are drawn.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum EstimateMode {
    /// Points of tile x tile pixels, one occlusion query each; a tile with no
    /// pixel still searching is not drawn again (section 3.3).
    Tiled { tile: u32 },
    /// One full-screen triangle per pass until no pixel searches.
    FullScreen,
    /// Full screen behind a stencil mask of finished pixels, refreshed every
    /// `every` passes (the per-pixel "computation mask" of section 4.3).
    Masked { every: u32 },
}

/// Which photons within the search sphere may light a query point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "kebab-case")]
pub enum LeakTest {
    /// Every photon in the sphere (the paper's estimate): light leaks through
    /// walls thinner than the radius.
    None,
    /// Only photons near the query's tangent plane (Jensen's disc).
    Disc,
    /// Only photons that nothing blocks from the query point.
    Visibility,
    /// Both.
    DiscAndVisibility,
}

impl LeakTest {
    /// The defines that switch the tests on in knn_search.frag and sppm_update.frag.
    pub fn defines(self) -> Vec<(&'static str, String)> {
        let mut d = Vec::new();
        if matches!(self, LeakTest::Disc | LeakTest::DiscAndVisibility) {
            d.push(("DISC_TEST", "1".into()));
        }
        if matches!(self, LeakTest::Visibility | LeakTest::DiscAndVisibility) {
            d.push(("VISIBILITY_TEST", "1".into()));
        }
        d
    }
}

/// Steps per pixel per pass by default. `bench estimate` measures 64, 128 and
/// 256 (the same image each; `results/llvmpipe/estimate/estimate.json`): in
/// each paper scene 128 took less time than 64 at half the passes and 256
/// little less again; 128 keeps the running image's steps finer than 256.
pub const DEFAULT_BUDGET: u32 = 128;

#[derive(Clone, Debug, serde::Serialize)]
pub struct EstimateOptions {
    pub mode: EstimateMode,
    /// Steps per pixel per pass (each examines one photon or moves one cell).
    pub budget: u32,
    /// A safety bound on passes.
    pub max_passes: u32,
    /// The paper's float convert1dto2d for photon addresses (`--faithful`).
    pub float_addressing: bool,
    /// Which photons in the sphere may light the query point (default:
    /// visibility; the book, "Light through walls").
    pub leak: LeakTest,
    /// Skip cells beyond the search radius unopened (the same result, bit for
    /// bit); false visits every cell of every ring, as the paper's search.
    pub cull: bool,
    /// Read a face row's cells as one range of photons in a sorted uniform
    /// grid (the same result, bit for bit); false opens cells one by one.
    pub runs: bool,
    /// Read the search state back after every pass to measure divergence
    /// (`SearchWork::lanes`); slows the search, so for profiles only.
    pub profile_lanes: bool,
}

impl EstimateOptions {
    /// These options as the photon config constrains them: under
    /// `--faithful`, the paper's float addressing and the paper's walk.
    pub fn under(&self, photons: &crate::photon::PhotonConfig) -> EstimateOptions {
        let faithful = photons.faithful;
        EstimateOptions {
            float_addressing: faithful,
            cull: self.cull && !faithful,
            runs: self.runs && !faithful,
            ..self.clone()
        }
    }
}

impl Default for EstimateOptions {
    fn default() -> Self {
        Self {
            mode: EstimateMode::Tiled { tile: 16 },
            budget: DEFAULT_BUDGET,
            max_passes: 100_000,
            float_addressing: false,
            leak: LeakTest::Visibility,
            cull: true,
            runs: true,
            profile_lanes: false,
        }
    }
}

/// What the search did.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct EstimateStats {
    pub passes: u32,
    /// Pixels that took part (had a diffuse hit).
    pub query_pixels: u64,
    /// Pixels still searching at the start of each pass (occlusion-query counts).
    pub searching_per_pass: Vec<u64>,
    /// Tiles drawn in all passes, and tiles in the image (tiled mode).
    pub tile_draws: u64,
    pub tiles: u64,
    pub gpu_seconds: f64,
    pub wall_seconds: f64,
    /// Steps, photons examined and cells opened (and lane use, if profiled).
    pub work: SearchWork,
}

/// Seen after every pass: for progress and snapshots.
pub struct PassReport<'a> {
    pub pass: u32,
    pub searching: u64,
    pub query_pixels: u64,
    pub elapsed_seconds: f64,
    pub estimate: &'a RadianceEstimate,
}

pub struct RadianceEstimate {
    gpu: Gpu,
    pub flux: Texture,
    pub cursor: Texture,
    pub done: Texture,
    target: Target,
    pub image: Texture,
    image_target: Target,
    init: Program,
    mask: Program,
    compose: Program,
    /// Search programs by (routed map, tiles, float addressing, leak test),
    /// compiled on first use: a render with several eye samples or camera
    /// views runs the search many times and must not compile it each time.
    search: std::cell::RefCell<std::collections::HashMap<SearchKey, std::rc::Rc<Program>>>,
    width: u32,
    height: u32,
}

/// Routed map, tiles, float addressing, leak test, culling.
type SearchKey = (bool, bool, bool, LeakTest, bool);

/// The search program for a map kind, a way of drawing and a leak test.
fn search_program(
    gpu: &Gpu,
    (routed, tiles, float_addressing, leak, cull): SearchKey,
) -> Result<Program> {
    let mut defines: Vec<(&str, String)> = if routed {
        vec![("ROUTED", "1".into())]
    } else {
        vec![]
    };
    if float_addressing {
        defines.push(("FLOAT_ADDRESSING", "1".into()));
    }
    defines.extend(leak.defines());
    if !cull {
        defines.push(("NO_CULL", "1".into()));
    }
    if tiles {
        defines.push(("TILED", "1".into()));
    }
    let vertex = if tiles {
        "render/tile.vert"
    } else {
        "common/fullscreen.vert"
    };
    Program::new(gpu, vertex, "render/knn_search.frag", &defines)
}

impl RadianceEstimate {
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Self> {
        let flux = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let cursor = Texture::new(gpu, width, height, TexFormat::Rgba32I)?;
        let done = Texture::new(gpu, width, height, TexFormat::Rgba32I)?;
        let target = Target::with_stencil(gpu, &[&flux, &cursor, &done])?;
        let image = Texture::new(gpu, width, height, TexFormat::Rgba32F)?;
        let image_target = Target::new(gpu, &[&image])?;
        Ok(Self {
            gpu: gpu.clone(),
            flux,
            cursor,
            done,
            target,
            image,
            image_target,
            init: Program::fullscreen(gpu, "render/knn_init.frag")?,
            mask: Program::fullscreen(gpu, "render/knn_mask.frag")?,
            compose: Program::fullscreen(gpu, "render/compose.frag")?,
            search: Default::default(),
            width,
            height,
        })
    }

    /// The search program for this map and mode, compiled on first use.
    fn search_program(
        &self,
        map: &PhotonMap,
        options: &EstimateOptions,
    ) -> Result<std::rc::Rc<Program>> {
        let routed = matches!(map, PhotonMap::Routed(_));
        let tiled = matches!(options.mode, EstimateMode::Tiled { .. });
        let key = (
            routed,
            tiled,
            options.float_addressing,
            options.leak,
            options.cull,
        );
        if let Some(p) = self.search.borrow().get(&key) {
            return Ok(p.clone());
        }
        let p = std::rc::Rc::new(search_program(&self.gpu, key)?);
        self.search.borrow_mut().insert(key, p.clone());
        Ok(p)
    }

    /// Runs the search to the end; `on_pass` sees every pass.
    #[allow(clippy::too_many_arguments)]
    pub fn run(
        &self,
        scene: &SceneTextures,
        map: &PhotonMap,
        queries: QueryPoints<'_>,
        k: u32,
        max_radius: f32,
        options: &EstimateOptions,
        on_pass: &mut dyn FnMut(&PassReport<'_>),
    ) -> Result<EstimateStats> {
        self.gpu.finish();
        let wall = std::time::Instant::now();
        let search = self.search_program(map, options)?;
        let timer = Query::timer(&self.gpu)?;
        let mut stats = EstimateStats::default();
        self.init
            .bind()
            .texture("u_query_position", queries.position)
            .draw_fullscreen(&self.target, &DrawState::PLAIN)?;
        self.target.clear_depth_stencil(1.0, 0);
        self.gpu.texture_barrier();
        let query = SearchQuery {
            scene,
            leak: options.leak,
            map,
            queries,
            k,
            max_radius,
            budget: options.budget,
            runs: options.runs,
        };
        let mut tiles = Tiles::new(options.mode, self.width, self.height);
        stats.tiles = tiles.count as u64;
        let queries: Vec<Query> = (0..tiles.count.max(1))
            .map(|_| Query::occlusion(&self.gpu))
            .collect::<Result<_>>()?;
        let mut lanes = options.profile_lanes.then(LaneUse::default);
        for pass in 0..options.max_passes {
            crate::interrupt::check()?;
            timer.begin();
            let searching = match options.mode {
                EstimateMode::Tiled { .. } => {
                    let mut b = search.bind();
                    self.bind_search(&mut b, &query);
                    tiles.draw(&mut b, &self.target, &queries, &mut stats)?
                }
                EstimateMode::FullScreen | EstimateMode::Masked { .. } => {
                    self.full_screen_pass(&search, &query, options.mode, pass, &queries[0])?
                }
            };
            timer.end();
            stats.gpu_seconds += timer.seconds();
            self.gpu.texture_barrier();
            if pass == 0 {
                stats.query_pixels = searching;
            }
            if searching == 0 {
                break;
            }
            stats.passes = pass + 1;
            stats.searching_per_pass.push(searching);
            if let Some(lanes) = &mut lanes {
                lanes.add_pass(&self.done.read_i32(), self.width as usize);
            }
            on_pass(&PassReport {
                pass,
                searching,
                query_pixels: stats.query_pixels,
                elapsed_seconds: wall.elapsed().as_secs_f64(),
                estimate: self,
            });
        }
        self.gpu.check("radiance estimate")?;
        self.gpu.finish();
        stats.wall_seconds = wall.elapsed().as_secs_f64();
        // Read after the clock stops: the counters are not the search's work.
        stats.work = SearchWork::from_done(&self.done.read_i32());
        stats.work.lanes = lanes;
        Ok(stats)
    }

    /// The photon map, the queries and the search state, as knn_search.frag declares them.
    fn bind_search(&self, b: &mut Bindings<'_>, q: &SearchQuery<'_>) {
        q.map.bind(b);
        if let PhotonMap::Sorted(_) = q.map {
            b.int("u_cell_runs", q.runs as i32);
        }
        if q.leak != LeakTest::None {
            b.texture("u_query_normal", q.queries.normal);
        }
        if matches!(q.leak, LeakTest::Visibility | LeakTest::DiscAndVisibility) {
            q.scene.bind(b);
        }
        b.texture("u_query_position", q.queries.position)
            .texture("u_state_flux", &self.flux)
            .texture("u_state_cursor", &self.cursor)
            .texture("u_state_done", &self.done)
            .int("u_k", q.k as i32)
            .float("u_max_radius", q.max_radius)
            .int("u_budget", q.budget as i32);
    }

    /// One full-screen search pass (behind the stencil mask, refreshed every
    /// `every` passes, in masked mode); returns the pixels still searching.
    fn full_screen_pass(
        &self,
        search: &Program,
        query: &SearchQuery<'_>,
        mode: EstimateMode,
        pass: u32,
        counter: &Query,
    ) -> Result<u64> {
        let state = match mode {
            EstimateMode::Masked { every } => {
                if pass.is_multiple_of(every.max(1)) {
                    // Stencil := 1 where the search is done.
                    self.mask
                        .bind()
                        .texture("u_state_done", &self.done)
                        .draw_fullscreen(&self.target, &DrawState::stencil_replace(1))?;
                }
                DrawState::where_stencil_equals(0)
            }
            _ => DrawState::PLAIN,
        };
        let mut b = search.bind();
        self.bind_search(&mut b, query);
        counter.around(|| b.draw_fullscreen(&self.target, &state))?;
        Ok(counter.count())
    }

    /// `program`, a pass that turns the finished search into light at the
    /// first hits (compose.frag, gather_accumulate.frag), bound to what both
    /// read: the scene, the first hits' weights, and each query's flux and
    /// radius, its accepted photons, and the k and radius of the estimate.
    pub fn bind_result<'a>(
        &self,
        program: &'a Program,
        scene: &SceneTextures,
        direct: &DirectLight,
        k: u32,
        max_radius: f32,
    ) -> Bindings<'a> {
        let mut b = program.bind();
        scene.bind(&mut b);
        direct.bind_weights(&mut b);
        b.texture("u_state_flux", &self.flux)
            .texture("u_state_cursor", &self.cursor)
            .int("u_k", k as i32)
            .float("u_max_radius", max_radius);
        b
    }

    /// The image `draw_composed` left in `image`, read back.
    pub fn composed_image(&self) -> Image {
        Image::from_gl_rgba(self.width, self.height, &self.image.read_f32())
    }

    /// The image from the current state (final or running), left in `image`
    /// (adaptive sampling's packed levels read it there, on the GPU): direct
    /// light plus the estimate at each first diffuse hit, as chosen.
    pub fn draw_composed(
        &self,
        scene: &SceneTextures,
        direct: &DirectLight,
        k: u32,
        max_radius: f32,
        include_direct: bool,
        include_indirect: bool,
    ) -> Result<()> {
        let mut b = self.bind_result(&self.compose, scene, direct, k, max_radius);
        b.texture("u_direct", &direct.radiance)
            .int("u_include_direct", include_direct as i32)
            .int("u_include_indirect", include_indirect as i32)
            .draw_fullscreen(&self.image_target, &DrawState::PLAIN)
    }
}

/// What one search looks for: in which map, from which first hits, how far.
struct SearchQuery<'a> {
    scene: &'a SceneTextures,
    leak: LeakTest,
    map: &'a PhotonMap,
    queries: QueryPoints<'a>,
    k: u32,
    max_radius: f32,
    budget: u32,
    runs: bool,
}

/// The tiles of tiled mode (section 3.3): those still searching are drawn,
/// one occlusion query each, and a tile whose count is 0 is not drawn again.
struct Tiles {
    tile: u32,
    per_row: u32,
    count: u32,
    active: Vec<u32>,
}

impl Tiles {
    fn new(mode: EstimateMode, width: u32, height: u32) -> Self {
        let (tile, per_row, count) = match mode {
            EstimateMode::Tiled { tile } => {
                let per_row = width.div_ceil(tile);
                (tile, per_row, per_row * height.div_ceil(tile))
            }
            _ => (0, 0, 0),
        };
        Self {
            tile,
            per_row,
            count,
            active: (0..count).collect(),
        }
    }

    /// Draws every active tile; returns the pixels still searching.
    fn draw(
        &mut self,
        b: &mut Bindings<'_>,
        target: &Target,
        queries: &[Query],
        stats: &mut EstimateStats,
    ) -> Result<u64> {
        b.int("u_tile", self.tile as i32)
            .int("u_tiles_per_row", self.per_row as i32)
            .ivec2("u_target_size", [target.width as i32, target.height as i32]);
        for (q, &t) in queries.iter().zip(&self.active) {
            q.around(|| b.draw_points(target, &DrawState::PLAIN, t as i32, 1))?;
        }
        stats.tile_draws += self.active.len() as u64;
        let counts: Vec<u64> = queries
            .iter()
            .take(self.active.len())
            .map(|q| q.count())
            .collect();
        let mut kept = Vec::with_capacity(self.active.len());
        for (t, c) in self.active.iter().zip(&counts) {
            if *c > 0 {
                kept.push(*t);
            }
        }
        self.active = kept;
        Ok(counts.iter().sum())
    }
}
