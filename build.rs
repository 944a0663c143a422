//! Embeds every file under glsl/ into the binary as (path, source) pairs, so a
//! shader added to the folder is compiled into the program and into the test
//! that compiles every GLSL file, with no list to keep by hand.
use std::path::{Path, PathBuf};

fn collect(dir: &Path, root: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .expect("read glsl/")
        .flatten()
        .collect();
    entries.sort_by_key(|e| e.path());
    for e in entries {
        let p = e.path();
        if p.is_dir() {
            collect(&p, root, out);
        } else if matches!(
            p.extension().and_then(|e| e.to_str()),
            Some("glsl" | "vert" | "frag")
        ) {
            out.push(p.strip_prefix(root).unwrap().to_path_buf());
        }
    }
}

fn main() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("glsl");
    println!("cargo:rerun-if-changed=glsl");
    let mut files = Vec::new();
    collect(&root, &root, &mut files);
    let mut code = String::from("pub static GLSL_SOURCES: &[(&str, &str)] = &[\n");
    for f in &files {
        println!("cargo:rerun-if-changed=glsl/{}", f.display());
        let name = f.to_string_lossy().replace('\\', "/");
        code += &format!(
            "    ({:?}, include_str!({:?})),\n",
            name,
            root.join(f).to_string_lossy()
        );
    }
    code += "];\n";
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap()).join("glsl_sources.rs");
    std::fs::write(out, code).unwrap();
}
