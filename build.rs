//! Embeds every file under glsl/ (shaders) and every scene under scenes/ into
//! the binary as (path, source) pairs: a shader or scene added to its folder
//! is compiled in, and into the tests that check them all, with no list to
//! keep by hand. The embedded scenes let the installed binary render the paper
//! scenes by name and run the stress suite from any folder; the test scenes
//! of scenes/tests/ are embedded the same way (`scene::embedded` keeps them
//! out of the listing).
use std::path::{Path, PathBuf};

fn collect(dir: &Path, root: &Path, extensions: &[&str], out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("read {}: {e}", dir.display()))
        .flatten()
        .collect();
    entries.sort_by_key(|e| e.path());
    for e in entries {
        let p = e.path();
        if p.is_dir() {
            collect(&p, root, extensions, out);
        } else if p
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| extensions.contains(&e))
        {
            out.push(p.strip_prefix(root).unwrap().to_path_buf());
        }
    }
}

fn table(name: &str, folder: &str, extensions: &[&str]) -> String {
    // The package's folder as this run is given it: `env!` would bake in the
    // folder the build script was compiled in, which a copied target/ keeps.
    let manifest_dir = std::env::var("CARGO_MANIFEST_DIR").unwrap();
    let root = Path::new(&manifest_dir).join(folder);
    println!("cargo:rerun-if-changed={folder}");
    let mut files = Vec::new();
    collect(&root, &root, extensions, &mut files);
    let mut code = format!("pub static {name}: &[(&str, &str)] = &[\n");
    for f in &files {
        println!("cargo:rerun-if-changed={folder}/{}", f.display());
        let path = f.to_string_lossy().replace('\\', "/");
        code += &format!(
            "    ({:?}, include_str!({:?})),\n",
            path,
            root.join(f).to_string_lossy()
        );
    }
    code + "];\n"
}

/// The commit being built, when this is a git checkout with git at hand, for
/// the provenance every output records.
fn git_commit() {
    println!("cargo:rerun-if-changed=.git/HEAD");
    println!("cargo:rerun-if-changed=.git/refs/heads");
    let head = std::process::Command::new("git")
        .args(["rev-parse", "--short=12", "HEAD"])
        .output();
    if let Ok(out) = head {
        let commit = String::from_utf8_lossy(&out.stdout).trim().to_string();
        if out.status.success() && !commit.is_empty() {
            println!("cargo:rustc-env=PHOTONMAP_GIT_COMMIT={commit}");
        }
    }
}

fn main() {
    git_commit();
    let out = PathBuf::from(std::env::var("OUT_DIR").unwrap());
    std::fs::write(
        out.join("glsl_sources.rs"),
        table("GLSL_SOURCES", "glsl", &["glsl", "vert", "geom", "frag"]),
    )
    .unwrap();
    std::fs::write(
        out.join("scene_sources.rs"),
        table("SCENE_SOURCES", "scenes", &["toml", "obj", "mtl"]),
    )
    .unwrap();
}
