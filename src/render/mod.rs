//! Ray trace the scene and estimate radiance: the frame (`frame.rs`), the
//! methods that run inside it (one `Method` arm each, prepared once and
//! asked for each eye sample's light: `method.rs`), and SPPM, which runs its
//! own iterations. This file only declares and re-exports.

pub mod adaptive;
pub mod bias_compensation;
pub mod differentials;
pub mod direct;
pub mod explain;
pub mod eye_paths;
pub mod final_gather;
pub mod frame;
pub mod igi;
pub mod method;
pub mod observer;
pub mod options;
pub mod output;
pub mod photon_map;
pub mod photon_options;
pub mod plan;
pub mod progressive;
pub mod radiance_estimate;
pub mod radiosity;
pub mod ray_trace;
pub mod sample;
pub mod search_work;
pub mod software;
pub mod sppm;
pub mod sppm_adaptive;
pub mod vcm;

pub use crate::image::Image;
pub use crate::timing::{StageTiming, Timings};
pub use adaptive::{Adaptive, AdaptiveOptions, AdaptiveStats};
pub use differentials::{
    DifferentialPhotons, DifferentialsOptions, DifferentialsReport, DifferentialsRun,
    FootprintEstimate, FootprintStats, Kernel,
};
pub use direct::DirectLight;
pub use explain::ExplainLine;
pub use eye_paths::{trace_eye_paths, EyeSample};
pub use final_gather::{FinalGather, FinalGatherOptions, GatherRays, GatherStats};
pub use frame::{render, render_views};
pub use igi::{Igi, IgiOptions, IgiRun, IgiStats, VplGather, VplReport, Vpls};
pub use method::MethodRun;
pub use observer::{At, EstimatePass, Progress, RenderObserver, StopReason};
pub use options::{Method, PixelBounds, RenderOptions};
pub use output::{FrameState, RenderOutput};
pub use photon_map::{MapEstimate, PhotonMapRun, PhotonReport};
pub use photon_options::{CausticPaths, PhotonMapOptions, WithCausticMap, WithPhotons};
pub use plan::PassPlan;
pub use radiance_estimate::{
    EstimateMode, EstimateOptions, EstimateStats, QueryPoints, RadianceEstimate,
};
pub use radiosity::{Radiosity, RadiosityOptions, RadiosityReport, RadiosityRun};
pub use ray_trace::{HitBuffers, RayBuffers, RayTracer};
