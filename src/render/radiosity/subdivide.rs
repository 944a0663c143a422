//! Adaptive subdivision (Cohen et al.'s progressive refinement with
//! substructuring): after a shot, the split test over each element's
//! neighbours, the split, the children's inherited radiosity, and the shot
//! again at the children.

use crate::gpu::{DrawState, Query, Result, Target};
use crate::scene::Scene;

use super::{Radiosity, RadiosityReport, SPLIT_SHARE};

impl Radiosity {
    /// Adaptive subdivision after a shot: split test, split, inherit, shoot
    /// again at the children, and test them in turn.
    pub(super) fn refine(
        &mut self,
        scene: &Scene,
        shooters: usize,
        floor: f32,
        report: &mut RadiosityReport,
    ) -> Result<()> {
        let max_depth = self.options.subdivide;
        // Only tiles this shot changes by SPLIT_SHARE of their radiosity
        // power or more: later shots add little to what is already there.
        let powers = self.tile_powers()?;
        let e = &self.elements;
        let mut candidates: Vec<usize> = (0..e.tiles.len())
            .filter(|&t| {
                let tile = e.tiles[t];
                tile.alive
                    && tile.depth < max_depth
                    && !e.patches[tile.patch as usize].emitter
                    && powers[t][2] > 0.0
                    && powers[t][2] >= SPLIT_SHARE * (powers[t][1] + powers[t][2])
            })
            .collect();
        while !candidates.is_empty() && !report.atlas_full {
            let counts = self.discontinuities(&candidates, floor)?;
            report.split_tests += candidates.len();
            let mut split = Vec::new();
            for (&t, &count) in candidates.iter().zip(&counts) {
                if count <= u64::from(self.elements.res / 2) {
                    continue;
                }
                match self.elements.split(scene, t) {
                    Some(children) => split.push((t, children)),
                    None => {
                        report.atlas_full = true;
                        break;
                    }
                }
            }
            report.splits += split.len();
            for (parent, children) in &split {
                self.adopt(*parent, children)?;
            }
            self.upload_nodes()?;
            self.gpu.texture_barrier();
            candidates = Vec::new();
            for (_, children) in &split {
                for &c in children {
                    self.shot_pass(shooters, self.elements.tile_region(c))?;
                    if self.elements.tiles[c].depth < max_depth {
                        candidates.push(c);
                    }
                }
            }
        }
        Ok(())
    }

    /// The split test's fragment count for each tile (an occlusion query a tile).
    pub fn discontinuities(&mut self, tiles: &[usize], floor: f32) -> Result<Vec<u64>> {
        while self.queries.len() < tiles.len() {
            self.queries.push(Query::occlusion(&self.gpu)?);
        }
        self.gpu.texture_barrier();
        for (&t, q) in tiles.iter().zip(&self.queries) {
            let (x, y) = self.elements.tile_base(t);
            q.around(|| {
                self.programs
                    .discontinuity
                    .bind()
                    .texture("u_radiosity", &self.radiosity)
                    .texture("u_shot", &self.shot)
                    .texture("u_element_position", &self.position)
                    .ivec2("u_tile_base", [x as i32, y as i32])
                    .int("u_res", self.elements.res as i32)
                    .float("u_gradient", self.options.gradient)
                    .float("u_floor", floor)
                    .draw_region(
                        &self.residual_target,
                        &DrawState::NO_COLOR,
                        self.elements.tile_region(t),
                    )
            })?;
        }
        Ok(self.queries[..tiles.len()]
            .iter()
            .map(Query::count)
            .collect())
    }

    /// A split's records on the GPU: the children's elements and their
    /// inherited radiosity, residual, direct part and deposit; the parent
    /// retired.
    pub(super) fn adopt(&self, parent: usize, children: &[usize]) -> Result<()> {
        let e = &self.elements;
        let upload = |t: usize| -> Result<()> {
            let (x, y) = e.tile_base(t);
            let region = [x, y, e.res, e.res];
            self.position
                .upload_region(region, &e.tile_records(t, &e.position))?;
            self.normal
                .upload_region(region, &e.tile_records(t, &e.normal))?;
            self.albedo
                .upload_region(region, &e.tile_records(t, &e.albedo))
        };
        let (px, py) = e.tile_base(parent);
        let parent_tile = e.tiles[parent];
        self.gpu.texture_barrier();
        for &c in children {
            upload(c)?;
            let tile = e.tiles[c];
            let (cx, cy) = e.tile_base(c);
            let quadrant = [
                (tile.origin[0] - 2 * parent_tile.origin[0]) / e.res,
                (tile.origin[1] - 2 * parent_tile.origin[1]) / e.res,
            ];
            self.programs
                .inherit
                .bind()
                .texture("u_radiosity", &self.radiosity)
                .texture("u_residual", &self.residual)
                .texture("u_direct", &self.direct)
                .texture("u_deposited", &self.deposit)
                .ivec2("u_child_base", [cx as i32, cy as i32])
                .ivec2("u_parent_base", [px as i32, py as i32])
                .ivec2("u_quadrant", [quadrant[0] as i32, quadrant[1] as i32])
                .int("u_res", e.res as i32)
                .draw_region(&self.atlas_target, &DrawState::PLAIN, e.tile_region(c))?;
        }
        self.gpu.texture_barrier();
        self.zero_region(&self.atlas_target, parent)?;
        upload(parent)
    }

    /// Zero over tile t's region of `target`'s textures.
    pub(super) fn zero_region(&self, target: &Target, tile: usize) -> Result<()> {
        self.programs.zero.bind().draw_region(
            target,
            &DrawState::PLAIN,
            self.elements.tile_region(tile),
        )
    }
}
