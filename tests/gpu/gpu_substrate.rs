//! The substrate on the real pipeline: exact read-back, ping-pong, integer
//! addressing, shader errors located in glsl/, and every GLSL file compiling.

use crate::common;

use photonmap::gpu::program::glsl_files;
use photonmap::gpu::{DrawState, Error, PingPong, Program, Target, TexFormat, Texture};

#[test]
fn a_pass_writes_values_that_read_back_exactly() {
    let gpu = common::gpu();
    let (w, h) = (37, 19);
    let tex = Texture::new(&gpu, w, h, TexFormat::Rgba32F).unwrap();
    let target = Target::new(&gpu, &[&tex]).unwrap();
    let program = Program::fullscreen(&gpu, "test/write_values.frag").unwrap();
    let value = 0.1f32; // not a short binary fraction: must still come back bit for bit
    program
        .bind()
        .float("u_value", value)
        .draw_fullscreen(&target, &DrawState::PLAIN)
        .unwrap();
    let data = tex.read_f32();
    for y in 0..h {
        for x in 0..w {
            let i = ((y * w + x) * 4) as usize;
            assert_eq!(
                &data[i..i + 4],
                &[x as f32, y as f32, value, 16777215.0 - x as f32],
                "texel ({x}, {y})"
            );
        }
    }
}

#[test]
fn ping_pong_swaps_what_is_read_and_written() {
    let gpu = common::gpu();
    let mut pp = PingPong::new(&gpu, 8, 4, &[TexFormat::Rgba32F]).unwrap();
    pp.current_target().clear([0.0; 4]);
    let program = Program::fullscreen(&gpu, "test/add_one.frag").unwrap();
    let first = pp.current_index();
    for n in 1..=5 {
        program
            .bind()
            .texture("u_current", &pp.current()[0])
            .draw_fullscreen(pp.next_target(), &DrawState::PLAIN)
            .unwrap();
        pp.swap();
        assert_eq!(pp.current_index(), (first + n) % 2);
        assert!(
            pp.current()[0].read_f32().iter().all(|&v| v == n as f32),
            "after {n} passes"
        );
    }
}

#[test]
fn texel_addressing_is_exact_up_to_2_pow_28() {
    let gpu = common::gpu();
    let mut queries = Vec::new();
    let widths = [
        1, 2, 3, 7, 255, 256, 1000, 1024, 4095, 4096, 8191, 8192, 16383, 16384,
    ];
    let limit: i64 = 1 << 28;
    for &w in &widths {
        let w = w as i64;
        // Boundaries of rows, powers of two, 2^24 (where float addressing breaks), the top.
        let mut idx = vec![
            0,
            1,
            w - 1,
            w,
            w + 1,
            limit - 1,
            limit - w,
            (1 << 24) - 1,
            1 << 24,
            (1 << 24) + 1,
        ];
        for k in 0..28 {
            idx.push(1 << k);
            idx.push((1 << k) - 1);
        }
        let mut x: u64 = 0x9e3779b97f4a7c15 ^ w as u64;
        for _ in 0..2000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            idx.push((x % limit as u64) as i64);
        }
        for i in idx.into_iter().filter(|&i| (0..limit).contains(&i)) {
            queries.extend([i as i32, w as i32, 0, 0]);
        }
    }
    let n = queries.len() / 4;
    let tex_w = 256u32;
    let tex_h = n.div_ceil(tex_w as usize) as u32;
    queries.resize((tex_w * tex_h * 4) as usize, 0);
    for q in queries.chunks_mut(4).skip(n) {
        q[1] = 1;
    }
    let input = Texture::from_i32(&gpu, tex_w, tex_h, &queries).unwrap();
    let output = Texture::new(&gpu, tex_w, tex_h, TexFormat::Rgba32I).unwrap();
    let target = Target::new(&gpu, &[&output]).unwrap();
    let program = Program::fullscreen(&gpu, "test/addressing.frag").unwrap();
    program
        .bind()
        .texture("u_queries", &input)
        .draw_fullscreen(&target, &DrawState::PLAIN)
        .unwrap();
    let out = output.read_i32();
    let mut mismatches = 0;
    for k in 0..n {
        let (i, w) = (queries[4 * k] as i64, queries[4 * k + 1] as i64);
        let expect = [(i % w) as i32, (i / w) as i32, i as i32];
        if out[4 * k..4 * k + 3] != expect {
            mismatches += 1;
            eprintln!(
                "index {i} width {w}: got {:?}, expected {expect:?}",
                &out[4 * k..4 * k + 3]
            );
        }
    }
    assert!(n > 20_000, "tested {n} indices");
    assert_eq!(mismatches, 0);
}

#[test]
fn a_broken_shader_names_its_glsl_file_and_line() {
    let gpu = common::gpu();
    // The real tree, with one include replaced by a file broken on its line 3.
    let lookup = |name: &str| -> Option<String> {
        match name {
            "test/broken.frag" => Some(
                "#version 450 core\n#include \"common/random.glsl\"\n#include \"test/broken_helper.glsl\"\nout vec4 c;\nvoid main() { c = vec4(helper()); }\n".into(),
            ),
            "test/broken_helper.glsl" => {
                Some("// a helper\nfloat helper() {\n    return undefined_name * 2.0;\n}\n".into())
            }
            other => glsl_files().find(|(n, _)| *n == other).map(|(_, s)| s.to_string()),
        }
    };
    let err = Program::from_lookup(
        &gpu,
        &lookup,
        "common/fullscreen.vert",
        "test/broken.frag",
        &[],
    )
    .err()
    .expect("the broken shader must not compile");
    let Error::Shader(e) = err else {
        panic!("expected a shader error, got {err}")
    };
    assert_eq!(
        (e.file.as_str(), e.line),
        ("test/broken_helper.glsl", 3),
        "{e}"
    );
    assert!(
        e.to_string().starts_with("glsl/test/broken_helper.glsl:3:"),
        "{e}"
    );

    // An error in the root file after an include is located there too.
    let lookup2 = |name: &str| -> Option<String> {
        match name {
            "test/broken.frag" => Some("#version 450 core\n#include \"common/random.glsl\"\nout vec4 c;\nvoid main() { c = vec4(nope); }\n".into()),
            other => glsl_files().find(|(n, _)| *n == other).map(|(_, s)| s.to_string()),
        }
    };
    let Error::Shader(e) = Program::from_lookup(
        &gpu,
        &lookup2,
        "common/fullscreen.vert",
        "test/broken.frag",
        &[],
    )
    .err()
    .unwrap() else {
        panic!()
    };
    assert_eq!((e.file.as_str(), e.line), ("test/broken.frag", 4), "{e}");
}

#[test]
fn every_glsl_file_compiles() {
    let gpu = common::gpu();
    let on_disk: Vec<String> = walk(&common::root().join("glsl"));
    let embedded: Vec<&str> = glsl_files().map(|(n, _)| n).collect();
    for f in &on_disk {
        assert!(embedded.contains(&f.as_str()), "glsl/{f} is not embedded");
    }
    // Fragment programs drawn from points pair with their vertex program; the
    // rest with the full-screen triangle. Programs with #ifdef variants are
    // built each way the program builds them.
    let vertices_of = |frag: &str| -> Vec<&str> {
        match frag {
            "photon/route.frag" | "photon/count.frag" | "photon/count_cell.frag" => {
                vec!["photon/route.vert"]
            }
            "render/knn_search.frag" => vec!["common/fullscreen.vert", "render/tile.vert"],
            "radiosity/select.frag" => vec!["radiosity/select.vert"],
            "radiosity/deposit.frag" => vec!["radiosity/deposit.vert"],
            "radiosity/item_buffer.frag" => vec!["radiosity/item_buffer.vert"],
            "vcm/light_splat.frag" => vec!["vcm/light_splat.vert"],
            "photon/place.frag" => vec!["photon/place.vert"],
            _ => vec!["common/fullscreen.vert"],
        }
    };
    let variants = |frag: &str| -> Vec<Vec<(&str, String)>> {
        match frag {
            "photon/route.frag" | "photon/count.frag" => {
                vec![vec![], vec![("READBACK", "1".into())]]
            }
            "photon/count_cell.frag" => vec![
                vec![("CELL_COUNT", "1".into())],
                vec![("CELL_COUNT", "1".into()), ("READBACK", "1".into())],
            ],
            "photon/redistribute.frag" => vec![vec![], vec![("HASHED", "1".into())]],
            "render/knn_search.frag" => vec![
                vec![],
                vec![("ROUTED", "1".into())],
                vec![("FLOAT_ADDRESSING", "1".into())],
            ],
            "photon/bitonic.frag"
            | "photon/keys.frag"
            | "photon/binary_search.frag"
            | "photon/gather.frag" => {
                vec![vec![], vec![("FLOAT_ADDRESSING", "1".into())]]
            }
            "photon/pyramid_base.frag" | "photon/compact.frag" => {
                vec![vec![], vec![("RECORD_ORDER", "1".into())]]
            }
            "photon/emit.frag" | "photon/trace.frag" => {
                vec![vec![], vec![("RANDOM_TEXTURE", "1".into())]]
            }
            // The mode is compiled in: every mode.
            "vcm/camera_path.frag" | "vcm/light_connect.frag" => ["PT", "LT", "PPM", "BPT", "VCM"]
                .iter()
                .map(|m| vec![("VCM_MODE", format!("VCM_MODE_{m}"))])
                .collect(),
            _ => vec![vec![]],
        }
    };
    // Programs with a geometry stage: (vertex, geometry, fragment).
    let staged = [(
        "radiosity/item_buffer.vert",
        "radiosity/item_buffer.geom",
        "radiosity/item_buffer.frag",
    )];
    let mut compiled = 0;
    for (name, _) in glsl_files().filter(|(n, _)| n.ends_with(".frag")) {
        if let Some((v, g, f)) = staged.iter().find(|s| s.2 == name) {
            Program::with_geometry(&gpu, v, g, f, &[]).unwrap_or_else(|e| panic!("{e}"));
            compiled += 1;
            continue;
        }
        for vertex in vertices_of(name) {
            for defines in variants(name) {
                Program::new(&gpu, vertex, name, &defines).unwrap_or_else(|e| panic!("{e}"));
                compiled += 1;
            }
        }
    }
    for (name, _) in glsl_files().filter(|(n, _)| n.ends_with(".geom")) {
        assert!(
            staged.iter().any(|s| s.1 == name),
            "glsl/{name} is in no staged program, so nothing compiles it"
        );
    }
    for (name, _) in glsl_files().filter(|(n, _)| n.ends_with(".vert")) {
        let used =
            glsl_files().any(|(f, _)| f.ends_with(".frag") && vertices_of(f).contains(&name));
        assert!(
            used,
            "glsl/{name} is paired with no fragment program, so nothing compiles it"
        );
    }
    // Helpers (.glsl) compile as part of the passes that include them; make sure each is used.
    for (name, _) in glsl_files().filter(|(n, _)| n.ends_with(".glsl")) {
        let used = glsl_files().any(|(_, src)| src.contains(&format!("#include \"{name}\"")));
        assert!(
            used,
            "glsl/{name} is included by no pass, so nothing compiles it"
        );
    }
    assert!(compiled >= 6);
}

fn walk(dir: &std::path::Path) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().flatten() {
        let p = e.path();
        if p.is_dir() {
            for f in walk(&p) {
                out.push(format!("{}/{f}", p.file_name().unwrap().to_string_lossy()));
            }
        } else {
            out.push(p.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    out
}

#[test]
fn capabilities_report_what_later_stages_rely_on() {
    let gpu = common::gpu();
    let caps = gpu.capabilities();
    assert!(!caps.gl_renderer.is_empty());
    assert!(caps.max_texture_size >= 4096, "{caps:?}");
    assert!(caps.max_draw_buffers >= 4, "{caps:?}");
    assert_eq!(caps.stencil_bits, 8, "{caps:?}");
    assert!(
        caps.timer_query_bits > 0 && caps.occlusion_query_bits > 0,
        "{caps:?}"
    );
    assert!(caps.point_size_range[1] >= 16.0, "{caps:?}");
}

/// A uniform renamed in GLSL only must not fail silently (the estimate would
/// read 0 and go dark): setting a name the program does not declare makes the
/// draw fail, naming the program and the uniform.
#[test]
fn a_uniform_the_program_does_not_declare_is_an_error() {
    let gpu = common::gpu();
    let renamed = |n: &str| {
        glsl_files().find(|(f, _)| *f == n).map(|(_, s)| {
            if n == "render/knn_search.frag" {
                s.replace("u_max_radius", "u_max_radius_renamed")
            } else {
                s.to_string()
            }
        })
    };
    let program = Program::from_lookup(
        &gpu,
        &renamed,
        "common/fullscreen.vert",
        "render/knn_search.frag",
        &[],
    )
    .unwrap();
    let tex = Texture::new(&gpu, 4, 4, TexFormat::Rgba32F).unwrap();
    let target = Target::new(&gpu, &[&tex]).unwrap();
    let err = program
        .bind()
        .int("u_k", 8)
        .float("u_max_radius", 0.25)
        .draw_fullscreen(&target, &DrawState::PLAIN)
        .unwrap_err();
    match &err {
        Error::UndeclaredUniform { program, name } => {
            assert_eq!(
                (program.as_str(), name.as_str()),
                ("render/knn_search.frag", "u_max_radius")
            );
        }
        other => panic!("expected UndeclaredUniform, got {other}"),
    }
    // The declared name draws.
    program
        .bind()
        .float("u_max_radius_renamed", 0.25)
        .draw_fullscreen(&target, &DrawState::PLAIN)
        .unwrap();
}

/// Layout constants are defined once, in src/layout.rs: every program sees
/// them as #defines, and no shader spells one itself.
#[test]
fn layout_constants_reach_every_program_and_no_shader_redefines_them() {
    use photonmap::gpu::program::preprocessed_source;
    let text = preprocessed_source("render/direct.frag", &[]).unwrap();
    for (name, value) in photonmap::layout::glsl_defines() {
        assert!(
            text.contains(&format!("#define {name} {value}\n")),
            "{name}"
        );
    }
    assert!(text.contains(&format!(
        "#define LIGHT_TEXELS {}\n",
        photonmap::layout::LIGHT_TEXELS
    )));
    for (file, src) in glsl_files() {
        for (name, _) in photonmap::layout::glsl_defines() {
            for form in [
                format!("const int {name} "),
                format!("const float {name} "),
                format!("#define {name} "),
            ] {
                assert!(!src.contains(&form), "glsl/{file} defines {name} itself");
            }
        }
    }
}

/// Dropping a context that is not current leaves the current one current:
/// the later context's textures still upload and read back.
#[test]
fn dropping_another_context_leaves_this_one_current() {
    let _turn = common::rendering_turn();
    std::thread::spawn(|| {
        let first = common::OwnGpu::new(photonmap::gpu::Platform::Auto).unwrap();
        let second = common::OwnGpu::new(photonmap::gpu::Platform::Auto).unwrap();
        drop(first);
        let t = Texture::new(&second, 2, 1, TexFormat::Rgba32F).unwrap();
        let texels = [1.0f32, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
        t.upload_f32(&texels).unwrap();
        assert_eq!(t.read_f32(), texels);
    })
    .join()
    .unwrap();
}
