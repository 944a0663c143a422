//! `photonmap info`: the platform, the driver and the limits this program relies on.

use anyhow::Result;
use clap::Args;

use photonmap::gpu::Platform;

/// Print the headless platform, the GL implementation and the limits this program relies on.
#[derive(Args)]
pub struct InfoArgs {
    /// As JSON on stdout.
    #[arg(long)]
    pub json: bool,
}

pub fn run(args: &InfoArgs, platform: Platform) -> Result<()> {
    let caps = super::gpu(platform)?.capabilities();
    if args.json {
        return super::print_json(&caps);
    }
    println!("platform          {}", caps.platform);
    println!(
        "platform vendor   {} ({})",
        caps.platform_vendor, caps.platform_version
    );
    println!("GL vendor         {}", caps.gl_vendor);
    println!("GL renderer       {}", caps.gl_renderer);
    println!(
        "GL version        {} (context {})",
        caps.gl_version, caps.context_version
    );
    println!("GLSL version      {}", caps.glsl_version);
    println!("max texture size  {}", caps.max_texture_size);
    println!("max draw buffers  {}", caps.max_draw_buffers);
    println!(
        "point size range  {} .. {}",
        caps.point_size_range[0], caps.point_size_range[1]
    );
    println!("stencil bits      {}", caps.stencil_bits);
    println!("timer query bits  {}", caps.timer_query_bits);
    println!("occlusion query bits {}", caps.occlusion_query_bits);
    Ok(())
}
