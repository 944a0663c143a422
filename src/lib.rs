//! photonmap-gl: Purcell et al., "Photon Mapping on Programmable Graphics
//! Hardware" (Graphics Hardware 2003), as OpenGL fragment passes, headless.
//! ARCHITECTURE.md maps each box of the paper's Figure 1 to a module here.

pub mod gpu;
pub mod metrics;
pub mod photon;
pub mod reference;
pub mod render;
pub mod scene;
pub mod stress;
