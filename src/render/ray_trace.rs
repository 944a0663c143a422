//! Eye rays, closest hits and specular continuation as fragment passes over
//! per-pixel ray and hit textures (breadth-first: one depth at a time, the
//! paper's ray tracer), or a pixel's whole eye path in one fused pass.

use crate::gpu::{Bindings, DrawState, Gpu, Program, Result, Target, TexFormat, Texture};
use crate::scene::pack::SceneTextures;
use crate::scene::Camera;

use super::plan::PassPlan;

/// Per-pixel rays: origin (w = active), unit direction, throughput.
pub struct RayBuffers {
    pub origin: Texture,
    pub direction: Texture,
    pub throughput: Texture,
    target: Target,
}

/// Per-pixel hit records of one specular depth, as the paper's ray tracer writes them.
pub struct HitBuffers {
    /// xyz, w = material index (-1: no hit)
    pub position: Texture,
    /// geometric normal, w = primitive index
    pub normal: Texture,
    /// path throughput, w = 1 while the path is alive
    pub throughput: Texture,
    /// incoming unit direction, w = distance along the ray
    pub direction: Texture,
    target: Target,
}

impl HitBuffers {
    pub fn bind(&self, b: &mut crate::gpu::Bindings<'_>) {
        b.texture("u_hit_position", &self.position)
            .texture("u_hit_normal", &self.normal)
            .texture("u_hit_throughput", &self.throughput)
            .texture("u_hit_direction", &self.direction);
    }
}

pub struct RayTracer {
    pub rays: RayBuffers,
    pub hits: HitBuffers,
    eye_program: Program,
    intersect_program: Program,
    specular_program: Program,
    /// The whole eye path in one pass (`render/eye_path.frag`).
    eye_path_program: Program,
}

/// The uniforms of `common/camera.glsl` for eye sample `sample`.
pub(crate) fn bind_camera(b: &mut Bindings<'_>, camera: &Camera, plan: &PassPlan, sample: u32) {
    let (strata_x, strata_y) = crate::sampling::strata(plan.spp);
    let (u, v, w) = camera.basis();
    let tan_v = (camera.vfov_degrees.to_radians() * 0.5).tan();
    let aspect = plan.width as f32 / plan.height as f32;
    b.vec3("u_camera_position", camera.position.to_array())
        .vec3("u_camera_right", u.to_array())
        .vec3("u_camera_up", v.to_array())
        .vec3("u_camera_backward", w.to_array())
        .vec2("u_tan_half_fov", [tan_v * aspect, tan_v])
        .vec2("u_image_size", [plan.width as f32, plan.height as f32])
        .int("u_jitter", plan.jitter as i32)
        .int("u_sample", sample as i32)
        .ivec2("u_strata", [strata_x as i32, strata_y as i32]);
}

fn rgba(gpu: &Gpu, w: u32, h: u32) -> Result<Texture> {
    Texture::new(gpu, w, h, TexFormat::Rgba32F)
}

impl RayTracer {
    pub fn new(gpu: &Gpu, width: u32, height: u32) -> Result<Self> {
        let (origin, direction, throughput) = (
            rgba(gpu, width, height)?,
            rgba(gpu, width, height)?,
            rgba(gpu, width, height)?,
        );
        let target = Target::new(gpu, &[&origin, &direction, &throughput])?;
        let rays = RayBuffers {
            origin,
            direction,
            throughput,
            target,
        };
        let (position, normal, hthroughput, hdirection) = (
            rgba(gpu, width, height)?,
            rgba(gpu, width, height)?,
            rgba(gpu, width, height)?,
            rgba(gpu, width, height)?,
        );
        let target = Target::new(gpu, &[&position, &normal, &hthroughput, &hdirection])?;
        let hits = HitBuffers {
            position,
            normal,
            throughput: hthroughput,
            direction: hdirection,
            target,
        };
        Ok(Self {
            rays,
            hits,
            eye_program: Program::fullscreen(gpu, "render/eye_rays.frag")?,
            intersect_program: Program::fullscreen(gpu, "render/intersect.frag")?,
            specular_program: Program::fullscreen(gpu, "render/specular.frag")?,
            eye_path_program: Program::fullscreen(gpu, "render/eye_path.frag")?,
        })
    }

    /// Every pixel's whole eye path in one pass, into `direct` (a
    /// `DirectLight`'s target: radiance and first-diffuse-hit records): what `eye_rays`, then per depth
    /// `intersect`, `DirectLight::shade` and `specular`, compute.
    pub fn eye_paths_fused(
        &self,
        scene: &SceneTextures,
        direct: &Target,
        camera: &Camera,
        plan: &PassPlan,
        sample: u32,
        seed: u32,
    ) -> Result<()> {
        let (nx, _) = crate::sampling::strata(plan.shadow_rays);
        let mut b = self.eye_path_program.bind();
        scene.bind(&mut b);
        bind_camera(&mut b, camera, plan, sample);
        b.uint("u_seed", seed)
            .int("u_depths", plan.depths as i32)
            .int("u_shadow_rays", plan.shadow_rays as i32)
            .int("u_strata_x", nx as i32)
            .int("u_light_sampling", plan.light_sampling as i32)
            .draw_fullscreen(direct, &DrawState::PLAIN)
    }

    /// One ray per pixel: through its centre with one sample per pixel (the
    /// paper), else through a jittered point of stratum `sample` of spp.
    pub fn eye_rays(&self, camera: &Camera, plan: &PassPlan, sample: u32, seed: u32) -> Result<()> {
        let mut b = self.eye_program.bind();
        bind_camera(&mut b, camera, plan, sample);
        b.uint("u_seed", seed)
            .draw_fullscreen(&self.rays.target, &DrawState::PLAIN)
    }

    /// Closest hit of every active ray into the hit textures.
    pub fn intersect(&self, scene: &SceneTextures) -> Result<()> {
        let mut b = self.intersect_program.bind();
        scene.bind(&mut b);
        b.texture("u_ray_origin", &self.rays.origin)
            .texture("u_ray_direction", &self.rays.direction)
            .texture("u_ray_throughput", &self.rays.throughput)
            .draw_fullscreen(&self.hits.target, &DrawState::PLAIN)
    }

    /// Reflected or refracted rays from the specular hits of this depth.
    pub fn specular(&self, scene: &SceneTextures, depth: u32, seed: u32) -> Result<()> {
        let mut b = self.specular_program.bind();
        scene.bind(&mut b);
        self.hits.bind(&mut b);
        b.uint("u_seed", seed)
            .int("u_depth", depth as i32)
            .draw_fullscreen(&self.rays.target, &DrawState::PLAIN)
    }
}
