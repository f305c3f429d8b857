//! The workspace's module graph, read from the sources as text, to keep `docs/architecture.md`
//! true: which library crates and modules exist, and whether sibling modules import each
//! other in a cycle (`cargo xtask codemap` prints it; the tests below check the document).
//!
//! A module's file set is its `.rs` file, or its directory's files. References are `crate::a::b`
//! paths (in `use` lines and inline) and `super::x` paths, resolved to the module they name.
//! Test code is left out: files named `tests.rs` or under a `tests/` directory of `src`, and
//! everything from a file's first `#[cfg(test)]` line on (the convention of this workspace: a
//! file's tests come last). Two sibling modules are in a cycle when each, directly or through
//! other siblings, refers into the other.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// One library crate's modules: module path (`sim::pdla`, `""` for the crate root) to the
/// module paths its non-test code refers to.
#[derive(Debug, Default)]
pub struct ModuleGraph {
    /// Every module of the crate, with the modules it refers to.
    pub edges: BTreeMap<String, BTreeSet<String>>,
}

/// The module path of a source file relative to `src` (`sim/pdla.rs` -> `sim::pdla`,
/// `sim/mod.rs` -> `sim`, `lib.rs` and `main.rs` -> the root).
fn module_of(rel: &Path) -> Option<String> {
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let file = parts.pop()?;
    let stem = file.strip_suffix(".rs")?;
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    } else if matches!(stem, "lib" | "main") && !parts.is_empty() {
        // src/bin/x/main.rs and the like: not library modules.
        return None;
    }
    Some(parts.join("::"))
}

fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<_> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            if p.file_name().is_some_and(|n| n == "tests" || n == "bin") {
                continue;
            }
            rs_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs")
            && p.file_name().is_some_and(|n| n != "tests.rs")
        {
            out.push(p);
        }
    }
}

/// The non-test part of a source file: up to its first `#[cfg(test)]` line.
fn non_test_code(text: &str) -> &str {
    match text.find("\n#[cfg(test)]") {
        Some(i) => &text[..i],
        None => text,
    }
}

/// Module paths named by `crate::...` and `super::...` in `code`, written in module `module`
/// (with `is_mod_file` telling whether the file is a `mod.rs`/root, whose `super` is one level
/// higher than a plain file's parent). Each path is cut to the longest known module.
fn references(code: &str, module: &str, known: &BTreeSet<String>) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let self_parts: Vec<&str> = if module.is_empty() {
        vec![]
    } else {
        module.split("::").collect()
    };
    let resolve = |segments: Vec<&str>, out: &mut BTreeSet<String>| {
        // Longest prefix that is a module.
        for n in (1..=segments.len()).rev() {
            let candidate = segments[..n].join("::");
            if known.contains(&candidate) {
                out.insert(candidate);
                return;
            }
        }
    };
    let ident = |s: &str| -> Vec<String> {
        // Segments `a::b::c` up to the first character that is not part of a path.
        let end = s
            .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
            .unwrap_or(s.len());
        s[..end]
            .split("::")
            .filter(|x| !x.is_empty())
            .map(str::to_string)
            .collect()
    };
    for line in code.lines() {
        let l = line.trim_start();
        if l.starts_with("//") {
            continue;
        }
        for (i, _) in l.match_indices("crate::") {
            if i > 0 && l[..i].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_') {
                continue; // `some_crate::`
            }
            let segs = ident(&l[i + "crate::".len()..]);
            resolve(segs.iter().map(String::as_str).collect(), &mut out);
            // `use crate::{a, b::c}`: each item of a brace group at the crate root.
            if l[i + "crate::".len()..].starts_with('{') {
                let rest = &l[i + "crate::{".len()..];
                for item in rest.split([',', '}']) {
                    let segs = ident(item.trim());
                    resolve(segs.iter().map(String::as_str).collect(), &mut out);
                }
            }
        }
        for (i, _) in l.match_indices("super::") {
            if i > 0
                && l[..i].ends_with(|c: char| c.is_ascii_alphanumeric() || c == '_' || c == ':')
            {
                continue; // `super::super::` is handled from its first `super`
            }
            let mut rest = &l[i..];
            let mut up = 0;
            while let Some(r) = rest.strip_prefix("super::") {
                up += 1;
                rest = r;
            }
            if up > self_parts.len() {
                continue;
            }
            let mut segs: Vec<&str> = self_parts[..self_parts.len() - up].to_vec();
            let tail = ident(rest);
            segs.extend(tail.iter().map(String::as_str));
            resolve(segs, &mut out);
        }
    }
    out.remove(module);
    out
}

impl ModuleGraph {
    /// The graph of the crate whose `src` directory is `src`.
    pub fn read(src: &Path) -> ModuleGraph {
        let mut files = Vec::new();
        rs_files(src, &mut files);
        let mut modules: Vec<(String, PathBuf)> = files
            .into_iter()
            .filter_map(|f| {
                let rel = f.strip_prefix(src).ok()?.to_path_buf();
                Some((module_of(&rel)?, f))
            })
            .collect();
        modules.sort();
        let known: BTreeSet<String> = modules.iter().map(|(m, _)| m.clone()).collect();
        let mut graph = ModuleGraph::default();
        for (module, file) in &modules {
            let text = std::fs::read_to_string(file).unwrap_or_default();
            let refs = references(non_test_code(&text), module, &known);
            graph.edges.entry(module.clone()).or_default().extend(refs);
        }
        graph
    }

    /// Every module path of the crate.
    pub fn modules(&self) -> impl Iterator<Item = &str> {
        self.edges.keys().map(String::as_str)
    }

    /// Cycles among sibling modules: for each parent, the groups of its children that refer to
    /// each other (through their whole subtrees) in a cycle. Empty when the imports are a DAG
    /// at every level.
    pub fn sibling_cycles(&self) -> Vec<Vec<String>> {
        let parent = |m: &str| m.rsplit_once("::").map_or("", |(p, _)| p).to_string();
        let mut parents: BTreeSet<String> = BTreeSet::new();
        for m in self.modules() {
            if !m.is_empty() {
                parents.insert(parent(m));
            }
        }
        let mut cycles = Vec::new();
        for p in parents {
            let children: Vec<String> = self
                .modules()
                .filter(|m| !m.is_empty() && parent(m) == p)
                .map(str::to_string)
                .collect();
            // The child of `p` whose subtree holds module `m`, if any.
            let child_of = |m: &str| -> Option<String> {
                children
                    .iter()
                    .find(|c| m == c.as_str() || m.starts_with(&format!("{c}::")))
                    .cloned()
            };
            let mut adj: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
            for (m, refs) in &self.edges {
                let Some(from) = child_of(m) else { continue };
                for r in refs {
                    if let Some(to) = child_of(r)
                        && to != from
                    {
                        adj.entry(from.clone()).or_default().insert(to);
                    }
                }
            }
            cycles.extend(strongly_connected(&children, &adj));
        }
        cycles
    }
}

/// The strongly connected components of more than one node (Tarjan's algorithm, iterative
/// enough for module counts: recursion depth is the number of siblings).
fn strongly_connected(
    nodes: &[String],
    adj: &BTreeMap<String, BTreeSet<String>>,
) -> Vec<Vec<String>> {
    struct State<'a> {
        adj: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<String, usize>,
        low: BTreeMap<String, usize>,
        stack: Vec<String>,
        on_stack: BTreeSet<String>,
        next: usize,
        out: Vec<Vec<String>>,
    }
    fn visit(s: &mut State, v: &str) {
        s.index.insert(v.to_string(), s.next);
        s.low.insert(v.to_string(), s.next);
        s.next += 1;
        s.stack.push(v.to_string());
        s.on_stack.insert(v.to_string());
        let succ: Vec<String> = s
            .adj
            .get(v)
            .map(|x| x.iter().cloned().collect())
            .unwrap_or_default();
        for w in succ {
            if !s.index.contains_key(&w) {
                visit(s, &w);
                let lw = s.low[&w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(lw);
            } else if s.on_stack.contains(&w) {
                let iw = s.index[&w];
                let lv = s.low.get_mut(v).expect("visited");
                *lv = (*lv).min(iw);
            }
        }
        if s.low[v] == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(&w);
                let done = w == v;
                comp.push(w);
                if done {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                s.out.push(comp);
            }
        }
    }
    let mut s = State {
        adj,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        next: 0,
        out: Vec::new(),
    };
    for n in nodes {
        if !s.index.contains_key(n) {
            visit(&mut s, n);
        }
    }
    s.out
}

/// The library crates of the workspace: `(package name, src directory)` for each directory
/// under `crates/`, plus `xtask`.
pub fn workspace_crates(root: &Path) -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    if let Ok(entries) = std::fs::read_dir(root.join("crates")) {
        for e in entries.flatten() {
            let dir = e.path();
            if dir.join("Cargo.toml").is_file() {
                let name = e.file_name().to_string_lossy().into_owned();
                out.push((name, dir.join("src")));
            }
        }
    }
    out.push(("xtask".to_string(), root.join("xtask/src")));
    out.sort();
    out
}

/// A report of the whole workspace: each crate's sibling cycles (none, if all is well).
pub fn cycles(root: &Path) -> Vec<(String, Vec<String>)> {
    let mut out = Vec::new();
    for (name, src) in workspace_crates(root) {
        for c in ModuleGraph::read(&src).sibling_cycles() {
            out.push((name.clone(), c));
        }
    }
    out
}

/// Library names (`core_lattice`) of the workspace's crates, with their `src` directories.
fn lib_names(root: &Path) -> Vec<(String, PathBuf)> {
    workspace_crates(root)
        .into_iter()
        .map(|(name, src)| (name.replace('-', "_"), src))
        .collect()
}

/// What `docs/architecture.md` names that does not exist: crate names in backticks that are
/// no crate, crates of the workspace it does not name, and `crate::module::item` paths whose
/// modules are missing (every segment but the last must be a module; the last a module or an
/// item declared in the crate).
pub fn architecture_doc_errors(root: &Path, doc: &str) -> Vec<String> {
    let mut errors = Vec::new();
    let crates = workspace_crates(root);
    let quoted: Vec<&str> = doc
        .split('`')
        .enumerate()
        .filter(|(i, _)| i % 2 == 1)
        .map(|(_, s)| s)
        .collect();
    for (name, _) in &crates {
        if !quoted.contains(&name.as_str()) {
            errors.push(format!("crate `{name}` is not named"));
        }
    }
    let libs = lib_names(root);
    for q in &quoted {
        // Crate names the doc quotes as headings or in prose: a word with a dash that looks
        // like a crate but is none.
        if q.ends_with("-lattice") || q.ends_with("-run") || q.ends_with("-pdla") {
            if !crates.iter().any(|(n, _)| n == q) {
                errors.push(format!("`{q}` is no crate of the workspace"));
            }
            continue;
        }
        let path = q
            .split(|c: char| !(c.is_ascii_alphanumeric() || c == '_' || c == ':'))
            .next()
            .unwrap_or("");
        let Some((lib, rest)) = path.split_once("::") else {
            continue;
        };
        let Some((_, src)) = libs.iter().find(|(l, _)| l == lib) else {
            continue;
        };
        let graph = ModuleGraph::read(src);
        let segments: Vec<&str> = rest.split("::").filter(|s| !s.is_empty()).collect();
        let Some((last, modules)) = segments.split_last() else {
            continue;
        };
        let module_path = modules.join("::");
        if !modules.is_empty() && !graph.edges.contains_key(&module_path) {
            errors.push(format!("`{q}`: no module `{lib}::{module_path}`"));
            continue;
        }
        let as_module = if module_path.is_empty() {
            last.to_string()
        } else {
            format!("{module_path}::{last}")
        };
        if !graph.edges.contains_key(&as_module) && !declares(src, last) {
            errors.push(format!(
                "`{q}`: `{last}` is neither a module nor an item of `{lib}`"
            ));
        }
    }
    errors
}

/// Whether some source file under `src` declares an item named `name`.
fn declares(src: &Path, name: &str) -> bool {
    let mut files = Vec::new();
    rs_files(src, &mut files);
    let kinds = [
        "fn",
        "struct",
        "enum",
        "trait",
        "const",
        "static",
        "type",
        "mod",
        "macro_rules!",
    ];
    files.iter().any(|f| {
        let text = std::fs::read_to_string(f).unwrap_or_default();
        kinds.iter().any(|k| {
            text.contains(&format!("{k} {name}("))
                || text.contains(&format!("{k} {name}<"))
                || text.contains(&format!("{k} {name} "))
                || text.contains(&format!("{k} {name}:"))
                || text.contains(&format!("{k} {name};"))
        }) || text.contains(&format!("pub use {name}"))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn graph(files: &[(&str, &str)]) -> ModuleGraph {
        let dir = tempfile::tempdir().unwrap();
        for (path, text) in files {
            let p = dir.path().join(path);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        }
        ModuleGraph::read(dir.path())
    }

    #[test]
    fn finds_a_cycle_between_siblings_and_none_in_a_dag() {
        let g = graph(&[
            ("lib.rs", "mod a; mod b; mod c;"),
            ("a.rs", "use crate::b::X;"),
            ("b.rs", "const Y: u8 = crate::a::Z;"),
            ("c.rs", "use crate::a::Z;"),
        ]);
        assert_eq!(
            g.sibling_cycles(),
            vec![vec!["a".to_string(), "b".to_string()]]
        );
        let g = graph(&[
            ("lib.rs", "mod a; mod b;"),
            ("a.rs", "use crate::b::X;"),
            (
                "b.rs",
                "pub struct X;\n#[cfg(test)]\nmod tests { use crate::a::*; }",
            ),
        ]);
        assert!(g.sibling_cycles().is_empty(), "test code does not count");
    }

    #[test]
    fn resolves_super_and_nested_modules() {
        let g = graph(&[
            ("lib.rs", "mod sim;"),
            ("sim/mod.rs", "mod x; mod y;"),
            ("sim/x.rs", "use super::y::Thing;"),
            ("sim/y.rs", "use crate::sim::x::Other;"),
        ]);
        assert_eq!(
            g.sibling_cycles(),
            vec![vec!["sim::x".to_string(), "sim::y".to_string()]]
        );
        assert!(g.edges["sim::x"].contains("sim::y"));
    }

    /// `docs/architecture.md` names every crate and only modules that exist, and claims no
    /// import cycle only while there is none (the test below).
    #[test]
    fn the_architecture_doc_names_what_exists() {
        let root = crate::workspace_root();
        let doc = std::fs::read_to_string(root.join("docs/architecture.md")).unwrap();
        let errors = architecture_doc_errors(&root, &doc);
        assert!(errors.is_empty(), "docs/architecture.md: {errors:#?}");
        assert!(doc.contains("**No import cycles.**"));
        // The check can fail: a module that does not exist is reported.
        let wrong = architecture_doc_errors(&root, "`spatial::quadtree` and `dlca::sim::nowhere`");
        assert_eq!(wrong.len(), 2 + workspace_crates(&root).len(), "{wrong:?}");
    }

    #[test]
    fn the_workspace_has_no_import_cycle() {
        let found = cycles(&crate::workspace_root());
        assert!(
            found.is_empty(),
            "modules that import each other (docs/architecture.md claims none): {found:?}"
        );
    }
}
