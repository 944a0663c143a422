//! File-level imports: a graph with a node per source file and an edge from a
//! file to each file that defines a module or item it names, through `use` or a
//! path in its code (`crate::`, `super::`, `self::`, a module it declares, or a
//! name it imported). A module that only declares its children and re-exports
//! their items (`pub use child::Item`) does not depend on them: a re-export is a
//! declaration, and a path through it resolves to the file that defines the item.

use std::collections::{BTreeMap, BTreeSet, VecDeque};

use crate::source::{code, ident_byte, sources_in, src_and_tests};

fn is_ident(s: &str) -> bool {
    s.chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
}

/// `s` without a visibility at its start (`pub`, `pub(crate)`, ...).
fn strip_visibility(s: &str) -> &str {
    let s = s.trim_start();
    if let Some(rest) = s.strip_prefix("pub(") {
        return rest.split_once(')').map_or(rest, |r| r.1).trim_start();
    }
    s.strip_prefix("pub ").map_or(s, str::trim_start)
}

/// One leaf of a `use` tree: its path, and the name it binds (None for a glob).
#[derive(Clone, Debug)]
struct UseLeaf {
    path: Vec<String>,
    name: Option<String>,
    public: bool,
    /// How many inline modules (`mod tests { ... }`) it sits in.
    inline: usize,
    /// At the file's top level (not in a function or an inline module).
    top: bool,
}

/// What one file says about modules: the modules it declares in other files
/// (with any `#[path]`), its `use` leaves, the other paths in its code (and
/// their inline-module depth), and the names of its top-level items.
#[derive(Default, Debug)]
struct FileImports {
    children: Vec<(String, Option<String>)>,
    uses: Vec<UseLeaf>,
    paths: Vec<(Vec<String>, usize)>,
    defined: BTreeSet<String>,
}

/// The `mod name;` declarations of a file, each with the file its `#[path]`
/// attribute names, if it has one.
fn declared_modules(text: &str, code: &str) -> Vec<(String, Option<String>)> {
    let raw: Vec<&str> = text.lines().collect();
    let mut out = Vec::new();
    for (i, line) in code.lines().enumerate() {
        let Some(decl) = line.trim().strip_suffix(';') else {
            continue;
        };
        let Some(name) = strip_visibility(decl).strip_prefix("mod ") else {
            continue;
        };
        if !is_ident(name.trim()) {
            continue;
        }
        let path = raw[..i]
            .iter()
            .rev()
            .take_while(|l| l.trim_start().starts_with("#[") || l.trim_start().starts_with("//"))
            .find_map(|l| {
                let rest = l.trim().strip_prefix("#[path")?.split_once('"')?.1;
                Some(rest.split_once('"')?.0.to_string())
            });
        out.push((name.trim().to_string(), path));
    }
    out
}

/// For each byte of `code`: how many braces enclose it, and how many of them
/// open inline modules (`mod name {`).
fn nesting(code: &str) -> (Vec<usize>, Vec<usize>) {
    let mut stack: Vec<bool> = Vec::new();
    let (mut braces, mut inline) = (Vec::with_capacity(code.len()), Vec::new());
    for (i, b) in code.bytes().enumerate() {
        if b == b'}' {
            stack.pop();
        }
        braces.push(stack.len());
        inline.push(stack.iter().filter(|m| **m).count());
        if b == b'{' {
            let before = code[..i].trim_end();
            let name_len = before.bytes().rev().take_while(|&c| ident_byte(c)).count();
            let head = before[..before.len() - name_len].trim_end();
            let opens_module = name_len > 0
                && head.ends_with("mod")
                && !head[..head.len() - 3]
                    .bytes()
                    .last()
                    .is_some_and(ident_byte);
            stack.push(opens_module);
        }
    }
    (braces, inline)
}

/// The tokens of a `use` tree: identifiers, `::`, `{`, `}`, `,` and `*`.
fn use_tokens(tree: &str) -> Vec<String> {
    let mut out = Vec::new();
    let b = tree.as_bytes();
    let mut i = 0;
    while i < b.len() {
        if ident_byte(b[i]) {
            let n = b[i..].iter().take_while(|&&c| ident_byte(c)).count();
            out.push(tree[i..i + n].to_string());
            i += n;
        } else if tree[i..].starts_with("::") {
            out.push("::".into());
            i += 2;
        } else {
            if !b[i].is_ascii_whitespace() {
                out.push((b[i] as char).to_string());
            }
            i += 1;
        }
    }
    out
}

/// Expands the `use` tree at `t[*pos..]` below `prefix` into its leaves.
fn use_leaves(
    t: &[String],
    pos: &mut usize,
    prefix: &mut Vec<String>,
    out: &mut Vec<(Vec<String>, Option<String>)>,
) {
    let depth = prefix.len();
    while let Some(tok) = t.get(*pos) {
        match tok.as_str() {
            "::" => *pos += 1,
            "*" => {
                *pos += 1;
                out.push((prefix.clone(), None));
                break;
            }
            "{" => {
                *pos += 1;
                while t.get(*pos).is_some_and(|s| s != "}") {
                    use_leaves(t, pos, prefix, out);
                    if t.get(*pos).is_some_and(|s| s == ",") {
                        *pos += 1;
                    }
                }
                *pos += 1;
                break;
            }
            id if is_ident(id) => {
                prefix.push(id.to_string());
                *pos += 1;
                if t.get(*pos).is_some_and(|s| s == "::") {
                    continue;
                }
                let mut name = prefix.last().cloned();
                if t.get(*pos).is_some_and(|s| s == "as") {
                    name = t.get(*pos + 1).cloned();
                    *pos += 2;
                }
                if prefix.last().is_some_and(|s| s == "self") {
                    prefix.pop();
                    if name.as_deref() == Some("self") {
                        name = prefix.last().cloned();
                    }
                }
                out.push((prefix.clone(), name));
                break;
            }
            _ => {
                *pos += 1;
                break;
            }
        }
    }
    prefix.truncate(depth);
}

/// The path (`a::b::c`) whose first identifier starts at `i`, and where it ends.
fn path_at(code: &str, i: usize) -> (Vec<String>, usize) {
    let b = code.as_bytes();
    let mut segs = Vec::new();
    let mut k = i;
    loop {
        let n = b[k..].iter().take_while(|&&c| ident_byte(c)).count();
        segs.push(code[k..k + n].to_string());
        k += n;
        let next = k + 2;
        if !(code[k..].starts_with("::") && b.get(next).is_some_and(|&c| ident_byte(c))) {
            return (segs, k);
        }
        k = next;
    }
}

/// Whether the `use` at `i` starts a statement, and whether it is public.
fn use_statement_at(code: &str, i: usize) -> Option<bool> {
    let mut before = code[..i].trim_end();
    let mut public = false;
    if let Some(rest) = before.strip_suffix("pub") {
        (before, public) = (rest.trim_end(), true);
    } else if before.ends_with(')') {
        if let Some(at) = before.rfind("pub(") {
            if !before[at..].contains(['{', ';']) {
                (before, public) = (before[..at].trim_end(), true);
            }
        }
    }
    let starts = before.is_empty() || before.ends_with([';', '{', '}', ']']);
    starts.then_some(public)
}

fn file_imports(text: &str) -> FileImports {
    let code = code(text);
    let (braces, inline) = nesting(&code);
    let mut found = FileImports {
        children: declared_modules(text, &code),
        ..FileImports::default()
    };
    let b = code.as_bytes();
    let item_keywords = [
        "fn", "struct", "enum", "trait", "type", "const", "static", "union", "mod",
    ];
    let mut i = 0;
    while i < b.len() {
        let after_path = i >= 2 && &code[i - 2..i] == "::";
        if !(b[i].is_ascii_alphabetic() || b[i] == b'_')
            || (i > 0 && (ident_byte(b[i - 1]) || matches!(b[i - 1], b'$' | b'\'')))
            || after_path
        {
            i += 1;
            continue;
        }
        let (segs, end) = path_at(&code, i);
        let public = (segs.len() == 1 && segs[0] == "use")
            .then(|| use_statement_at(&code, i))
            .flatten();
        if let Some(public) = public {
            let stop = code[end..].find(';').map_or(code.len(), |k| end + k);
            let (mut leaves, mut pos) = (Vec::new(), 0);
            use_leaves(
                &use_tokens(&code[end..stop]),
                &mut pos,
                &mut Vec::new(),
                &mut leaves,
            );
            for (path, name) in leaves {
                found.uses.push(UseLeaf {
                    path,
                    name,
                    public,
                    inline: inline[i],
                    top: braces[i] == 0,
                });
            }
            i = stop;
            continue;
        }
        if segs.len() == 1 && braces[i] == 0 && item_keywords.contains(&segs[0].as_str()) {
            let rest = code[end..].trim_start();
            let n = rest.bytes().take_while(|&c| ident_byte(c)).count();
            found.defined.insert(rest[..n].to_string());
        }
        if segs.len() >= 2 {
            found.paths.push((segs, inline[i]));
        }
        i = end;
    }
    found
}

/// `path` with its `..` and `.` steps taken.
fn normalize(path: &str) -> String {
    let mut parts: Vec<&str> = Vec::new();
    for p in path.split('/') {
        match p {
            ".." => {
                parts.pop();
            }
            "." | "" => {}
            p => parts.push(p),
        }
    }
    parts.join("/")
}

/// One crate's modules (module path -> file) and what each file imports.
struct Crate<'a> {
    modules: BTreeMap<Vec<String>, String>,
    module_of: BTreeMap<String, Vec<String>>,
    files: &'a BTreeMap<String, FileImports>,
}

impl<'a> Crate<'a> {
    /// The crate whose root file is `root`, its modules found by following
    /// each file's `mod` declarations.
    fn new(root: &str, files: &'a BTreeMap<String, FileImports>) -> Crate<'a> {
        let mut modules = BTreeMap::new();
        let mut todo = vec![(Vec::new(), root.to_string())];
        while let Some((module, file)) = todo.pop() {
            let dir = file.rsplit_once('/').map_or("", |d| d.0).to_string();
            let declares_here = file == root || file.ends_with("/mod.rs");
            let child_dir = if declares_here {
                dir.clone()
            } else {
                file.trim_end_matches(".rs").to_string()
            };
            for (name, path) in &files[&file].children {
                let candidates = match path {
                    Some(p) => vec![normalize(&format!("{dir}/{p}"))],
                    None => vec![
                        format!("{child_dir}/{name}.rs"),
                        format!("{child_dir}/{name}/mod.rs"),
                    ],
                };
                if let Some(found) = candidates.into_iter().find(|c| files.contains_key(c)) {
                    let mut child = module.clone();
                    child.push(name.clone());
                    todo.push((child, found));
                }
            }
            modules.insert(module, file);
        }
        let module_of = modules
            .iter()
            .map(|(m, f)| (f.clone(), m.clone()))
            .collect();
        Crate {
            modules,
            module_of,
            files,
        }
    }

    /// The crate-absolute module path that `path`, written in `file` inside
    /// `inline` inline modules, names; None for another crate, or for a path
    /// into the file's own inline modules.
    fn absolute(
        &self,
        file: &str,
        path: &[String],
        inline: usize,
        depth: usize,
    ) -> Option<Vec<String>> {
        let here = &self.module_of[file];
        let imports = &self.files[file];
        let join = |base: &[String], rest: &[String]| [base, rest].concat();
        match path[0].as_str() {
            "crate" => Some(path[1..].to_vec()),
            "super" => {
                let ups = path.iter().take_while(|s| *s == "super").count();
                let up = ups
                    .checked_sub(inline)
                    .filter(|&u| u > 0 && u <= here.len())?;
                Some(join(&here[..here.len() - up], &path[ups..]))
            }
            "self" => (inline == 0).then(|| join(here, &path[1..])),
            first if imports.children.iter().any(|(c, _)| c == first) => Some(join(here, path)),
            first if inline == 0 && depth < 8 => {
                let leaf = imports
                    .uses
                    .iter()
                    .find(|u| u.top && u.name.as_deref() == Some(first))?;
                let target = self.absolute(file, &leaf.path, 0, depth + 1)?;
                Some(join(&target, &path[1..]))
            }
            _ => None,
        }
    }

    /// The file that defines what the crate-absolute `path` names: the deepest
    /// module file on it, or, where that file only imports the item, the file
    /// its import leads to.
    fn resolve(&self, path: &[String], depth: usize) -> Option<String> {
        let mut module: Vec<String> = Vec::new();
        let mut i = 0;
        while i < path.len()
            && self
                .modules
                .contains_key(&[&module[..], &path[i..=i]].concat())
        {
            module.push(path[i].clone());
            i += 1;
        }
        let file = &self.modules[&module];
        let Some(name) = path.get(i) else {
            return Some(file.clone());
        };
        let imports = &self.files[file];
        let imported = imports
            .uses
            .iter()
            .find(|u| u.top && u.name.as_ref() == Some(name));
        match imported {
            Some(leaf) if !imports.defined.contains(name) && depth < 8 => {
                let target = self.absolute(file, &leaf.path, 0, depth + 1)?;
                self.resolve(&[&target[..], &path[i + 1..]].concat(), depth + 1)
            }
            _ => Some(file.clone()),
        }
    }

    /// Each file of the crate and the files it imports.
    fn edges(&self) -> BTreeMap<String, BTreeSet<String>> {
        let mut edges = BTreeMap::new();
        for file in self.modules.values() {
            let imports = &self.files[file];
            // A file that declares modules only re-exports with `pub use`.
            let declares = !imports.children.is_empty();
            let uses = imports
                .uses
                .iter()
                .filter(|u| !(u.public && declares))
                .map(|u| (&u.path, u.inline));
            let paths = imports.paths.iter().map(|(p, inline)| (p, *inline));
            let targets: BTreeSet<String> = uses
                .chain(paths)
                .filter_map(|(p, inline)| self.resolve(&self.absolute(file, p, inline, 0)?, 0))
                .filter(|t| t != file)
                .collect();
            edges.insert(file.clone(), targets);
        }
        edges
    }
}

/// The files `from` reaches through `edges`.
fn reachable(edges: &BTreeMap<String, BTreeSet<String>>, from: &str) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut todo = vec![from.to_string()];
    while let Some(f) = todo.pop() {
        for next in edges.get(&f).into_iter().flatten() {
            if seen.insert(next.clone()) {
                todo.push(next.clone());
            }
        }
    }
    seen
}

/// The shortest cycle from `start` back to itself, as a path of files.
fn shortest_cycle(edges: &BTreeMap<String, BTreeSet<String>>, start: &str) -> Vec<String> {
    let mut came_from: BTreeMap<String, String> = BTreeMap::new();
    let mut todo = VecDeque::from([start.to_string()]);
    while let Some(f) = todo.pop_front() {
        for next in edges.get(&f).into_iter().flatten() {
            if next == start {
                let mut path = vec![f.clone()];
                while path.last().is_some_and(|p| p != start) {
                    path.push(came_from[path.last().unwrap()].clone());
                }
                path.reverse();
                path.push(start.to_string());
                return path;
            }
            if next != start && !came_from.contains_key(next) {
                came_from.insert(next.clone(), f.clone());
                todo.push_back(next.clone());
            }
        }
    }
    Vec::new()
}

/// The sets of files that import one another (directly or not), in every
/// crate with one of `roots`, each with the shortest cycle through each file.
pub fn file_cycles(roots: &[String]) -> Cycles {
    cycles_in(&src_and_tests(), roots)
}

/// Each set of files that import one another, with the shortest cycle through
/// each of its files.
pub type Cycles = BTreeMap<Vec<String>, BTreeSet<Vec<String>>>;

/// The cycles among `sources` (path, text) in the crates with `roots`.
fn cycles_in(sources: &[(String, String)], roots: &[String]) -> Cycles {
    let files: BTreeMap<String, FileImports> = sources
        .iter()
        .map(|(f, text)| (f.clone(), file_imports(text)))
        .collect();
    let mut cycles = BTreeMap::new();
    for root in roots {
        let edges = Crate::new(root, &files).edges();
        let reach: BTreeMap<&String, BTreeSet<String>> =
            edges.keys().map(|f| (f, reachable(&edges, f))).collect();
        for (f, from_f) in &reach {
            if !from_f.contains(*f) {
                continue;
            }
            let set: Vec<String> = from_f
                .iter()
                .filter(|g| reach[g].contains(*f))
                .cloned()
                .collect();
            let paths = set.iter().map(|g| shortest_cycle(&edges, g)).collect();
            cycles.insert(set, paths);
        }
    }
    cycles
}

/// The crate roots: the library and the binary in src/, each test in tests/
/// (`tests/x.rs`, or `tests/x/main.rs`).
pub fn crate_roots() -> Vec<String> {
    let mut roots = vec!["src/lib.rs".to_string(), "src/main.rs".to_string()];
    for (file, _) in sources_in("tests") {
        let parts: Vec<&str> = file.split('/').collect();
        if parts.len() == 2 || (parts.len() == 3 && parts[2] == "main.rs") {
            roots.push(file);
        }
    }
    roots
}

/// The graph on a small crate whose files say what the checker must see: a
/// re-export is no edge, `super::` through a re-export reaches the sibling,
/// and paths in strings, comments and inline test modules are nothing.
#[test]
fn the_import_graph_follows_definitions_not_re_exports() {
    let crate_files = [
        ("src/lib.rs", "pub mod a;\npub mod b;\n"),
        (
            "src/a/mod.rs",
            "mod x;\nmod y;\npub use x::X;\npub use y::Y;\npub struct Here;\n\
             pub fn make() -> y::Y { y::Y(Here) }\n",
        ),
        (
            "src/a/x.rs",
            "use super::Y;\npub struct X(Y);\n// crate::b::f\n\
             const NOT_A_PATH: &str = \"crate::b::f\";\n\
             #[cfg(test)]\nmod tests {\n    use super::*;\n}\n",
        ),
        ("src/a/y.rs", "pub struct Y(pub super::Here);\n"),
        ("src/b.rs", "use crate::a::X;\npub fn f(x: X) -> X { x }\n"),
    ];
    let sources: Vec<(String, String)> = crate_files
        .iter()
        .map(|(f, t)| (f.to_string(), t.to_string()))
        .collect();
    let files: BTreeMap<String, FileImports> = sources
        .iter()
        .map(|(f, text)| (f.clone(), file_imports(text)))
        .collect();
    let edges = Crate::new("src/lib.rs", &files).edges();
    let of = |f: &str| edges[f].iter().cloned().collect::<Vec<_>>();
    assert_eq!(of("src/a/x.rs"), ["src/a/y.rs"]);
    assert_eq!(of("src/b.rs"), ["src/a/x.rs"]);
    assert_eq!(of("src/a/y.rs"), ["src/a/mod.rs"]);
    assert_eq!(of("src/a/mod.rs"), ["src/a/y.rs"]);
    let cycles = cycles_in(&sources, &["src/lib.rs".to_string()]);
    let cycle = vec!["src/a/mod.rs".to_string(), "src/a/y.rs".to_string()];
    assert_eq!(cycles.keys().collect::<Vec<_>>(), [&cycle]);
    let paths: Vec<String> = cycles[&cycle].iter().map(|p| p.join(" -> ")).collect();
    assert_eq!(
        paths,
        [
            "src/a/mod.rs -> src/a/y.rs -> src/a/mod.rs",
            "src/a/y.rs -> src/a/mod.rs -> src/a/y.rs"
        ]
    );
}
