//! Keeps the crate's layers pointing down (README, "Code map"): data → object/synth/render → gpu →
//! raster/loss/optim → mesh → articulation → fit → eval → export → pipeline/fixtures → web. It reads
//! `src/` as text, resolves every `use` and inline `crate::`/`super::` path to the file that defines
//! the item (following re-exports), and fails on an import that points up a layer, on a circle
//! between top-level modules and on a circle between files. Test-only code (`#[cfg(test)]` items and
//! the files they declare) is left out: tests may reach anywhere.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The layer of each top-level module: a module may use its own layer and those below.
const LAYERS: &[(&str, u32)] = &[
    ("data", 0),
    ("rng", 0),
    ("object", 1),
    ("synth", 1),
    ("gpu", 2),
    // The ground-truth renderer draws with the GPU's device: it sits on gpu's layer, above it in use.
    ("render", 2),
    ("raster", 3),
    ("loss", 3),
    ("optim", 3),
    ("mesh", 4),
    ("articulation", 5),
    ("fit", 6),
    ("eval", 7),
    ("export", 8),
    ("pipeline", 9),
    ("fixtures", 9),
    ("web", 10),
];

/// Source files by path relative to `src/`, e.g. `fit/mod.rs`.
type Tree = BTreeMap<String, String>;

fn read_tree(dir: &Path, rel: &str, tree: &mut Tree) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for path in entries {
        let name = path.file_name().unwrap().to_str().unwrap().to_string();
        let rel = if rel.is_empty() {
            name.clone()
        } else {
            format!("{rel}/{name}")
        };
        if path.is_dir() {
            if rel != "bin" {
                read_tree(&path, &rel, tree);
            }
        } else if name.ends_with(".rs") {
            tree.insert(rel, std::fs::read_to_string(&path).unwrap());
        }
    }
}

/// Blanks comments, string and char literals (keeping line breaks) so only code is scanned.
fn code_only(src: &str) -> String {
    let b = src.as_bytes();
    let mut out = String::with_capacity(src.len());
    let mut i = 0;
    let blank = |s: &[u8], out: &mut String| {
        out.extend(s.iter().map(|&c| if c == b'\n' { '\n' } else { ' ' }))
    };
    while i < b.len() {
        if b[i..].starts_with(b"//") {
            let end = b[i..]
                .iter()
                .position(|&c| c == b'\n')
                .map_or(b.len(), |p| i + p);
            blank(&b[i..end], &mut out);
            i = end;
        } else if b[i..].starts_with(b"/*") {
            let end = src[i..].find("*/").map_or(b.len(), |p| i + p + 2);
            blank(&b[i..end], &mut out);
            i = end;
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            let end = (j + 1).min(b.len());
            blank(&b[i..end], &mut out);
            i = end;
        } else if b[i] == b'\'' && i + 2 < b.len() && (b[i + 2] == b'\'' || b[i + 1] == b'\\') {
            let end = src[i + 2..].find('\'').map_or(b.len(), |p| i + 2 + p + 1);
            blank(&b[i..end], &mut out);
            i = end;
        } else {
            let ch = src[i..].chars().next().unwrap();
            out.push(ch);
            i += ch.len_utf8();
        }
    }
    out
}

/// Removes every item under `#[cfg(test)]`; returns the code and the modules so declared (`mod x;`).
fn without_tests(code: &str) -> (String, Vec<String>) {
    let mut out = code.to_string();
    let mut test_mods = Vec::new();
    while let Some(at) = out.find("#[cfg(test)]") {
        let rest = &out[at..];
        let semi = rest.find(';').unwrap_or(rest.len());
        let brace = rest.find('{').unwrap_or(rest.len());
        let end = if semi < brace {
            let item = rest[12..semi].trim();
            if let Some(name) = item.strip_prefix("mod ").or(item.strip_prefix("pub mod ")) {
                test_mods.push(name.trim().to_string());
            }
            at + semi + 1
        } else {
            let mut depth = 0;
            let mut end = out.len();
            for (k, c) in rest.char_indices().skip(brace) {
                match c {
                    '{' => depth += 1,
                    '}' => {
                        depth -= 1;
                        if depth == 0 {
                            end = at + k + 1;
                            break;
                        }
                    }
                    _ => {}
                }
            }
            end
        };
        out.replace_range(at..end, "");
    }
    (out, test_mods)
}

/// The module path of a file: `fit/articulate/mod.rs` → ["fit", "articulate"].
fn module_of(file: &str) -> Vec<String> {
    let stem = file.trim_end_matches(".rs");
    let mut parts: Vec<String> = stem.split('/').map(str::to_string).collect();
    if matches!(parts.last().map(String::as_str), Some("mod" | "lib")) {
        parts.pop();
    }
    parts
}

/// The file of a module path, if the tree has one.
fn file_of(tree: &Tree, module: &[String]) -> Option<String> {
    if module.is_empty() {
        return Some("lib.rs".into());
    }
    let joined = module.join("/");
    [format!("{joined}.rs"), format!("{joined}/mod.rs")]
        .into_iter()
        .find(|f| tree.contains_key(f))
}

/// Expands a `use` tree (`a::{b, c::{d as e}}`) into full paths, dropping `as` renames.
fn expand_use(tree: &str) -> Vec<Vec<String>> {
    let tree: String = tree.split_whitespace().collect::<Vec<_>>().join(" ");
    fn go(prefix: &[String], s: &str, out: &mut Vec<Vec<String>>) {
        let s = s.trim();
        if s.is_empty() {
            return;
        }
        if let Some(open) = s.find('{') {
            let head: Vec<String> = s[..open]
                .split("::")
                .map(str::trim)
                .filter(|p| !p.is_empty())
                .map(str::to_string)
                .collect();
            let inner = &s[open + 1..s.rfind('}').unwrap_or(s.len())];
            let mut p = prefix.to_vec();
            p.extend(head);
            let (mut depth, mut start) = (0, 0);
            for (k, c) in inner.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        go(&p, &inner[start..k], out);
                        start = k + 1;
                    }
                    _ => {}
                }
            }
            go(&p, &inner[start..], out);
        } else {
            let s = s.split(" as ").next().unwrap_or(s);
            let mut p = prefix.to_vec();
            p.extend(
                s.split("::")
                    .map(str::trim)
                    .filter(|x| !x.is_empty())
                    .map(str::to_string),
            );
            if p.last().map(String::as_str) == Some("self") {
                p.pop();
            }
            out.push(p);
        }
    }
    let mut out = Vec::new();
    go(&[], &tree, &mut out);
    out
}

/// One file's code with test items removed, its `use` paths and inline paths.
struct Scanned {
    code: String,
    /// Every `use` path, re-exports included: they resolve other files' paths.
    uses: Vec<Vec<String>>,
    /// The `use` paths that this file's own code needs (a `pub use` re-export is a facade, not a need).
    imports: Vec<Vec<String>>,
    test_mods: Vec<String>,
}

fn scan(src: &str) -> Scanned {
    let (code, test_mods) = without_tests(&code_only(src));
    let (mut uses, mut imports) = (Vec::new(), Vec::new());
    let mut rest = code.as_str();
    while let Some(at) = find_word(rest, "use") {
        let re_export =
            rest[..at].trim_end().ends_with("pub") || rest[..at].trim_end().ends_with(')');
        let after = &rest[at + 3..];
        let end = after.find(';').unwrap_or(after.len());
        let paths = expand_use(&after[..end]);
        if !re_export {
            imports.extend(paths.iter().cloned());
        }
        uses.extend(paths);
        rest = &after[end..];
    }
    Scanned {
        code,
        uses,
        imports,
        test_mods,
    }
}

fn find_word(s: &str, word: &str) -> Option<usize> {
    let ident = |c: char| c.is_alphanumeric() || c == '_';
    s.match_indices(word).map(|(i, _)| i).find(|&i| {
        !s[..i].chars().next_back().is_some_and(ident)
            && !s[i + word.len()..].chars().next().is_some_and(ident)
    })
}

/// Inline `crate::a::b` and `super::a` paths in the code (outside `use`).
fn inline_paths(code: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for root in ["crate::", "super::"] {
        let mut from = 0;
        while let Some(p) = code[from..].find(root) {
            let at = from + p;
            let preceded = code[..at]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':');
            let path: String = code[at..]
                .chars()
                .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            if !preceded {
                out.push(
                    path.split("::")
                        .filter(|s| !s.is_empty())
                        .map(str::to_string)
                        .collect(),
                );
            }
            from = at + path.len().max(1);
        }
    }
    out
}

/// Which file defines the item a path names, as seen from `file`; `None` for other crates.
fn resolve(
    tree: &Tree,
    scans: &BTreeMap<String, Scanned>,
    file: &str,
    path: &[String],
    depth: u32,
) -> Option<String> {
    let mut module = module_of(file);
    let mut segs = path;
    match segs.first().map(String::as_str) {
        Some("crate") => {
            module.clear();
            segs = &segs[1..];
        }
        Some("self") => segs = &segs[1..],
        Some("super") => {
            while segs.first().map(String::as_str) == Some("super") {
                module.pop();
                segs = &segs[1..];
            }
        }
        // A bare first segment is a child module of this file, or another crate.
        Some(first) => {
            let mut child = module.clone();
            child.push(first.to_string());
            file_of(tree, &child)?;
        }
        None => return None,
    }
    let mut at = file_of(tree, &module)?;
    for (k, seg) in segs.iter().enumerate() {
        let mut child = module.clone();
        child.push(seg.clone());
        if let Some(f) = file_of(tree, &child) {
            module = child;
            at = f;
            continue;
        }
        // An item: defined here, or brought in by a `use` we follow (re-exports).
        if depth < 8
            && !defines(&scans[&at].code, seg)
            && let Some(u) = scans[&at].uses.iter().find(|u| u.last() == Some(seg))
        {
            let mut full = u.clone();
            full.extend(segs[k + 1..].iter().cloned());
            return resolve(tree, scans, &at, &full, depth + 1).or(Some(at));
        }
        return Some(at);
    }
    Some(at)
}

fn defines(code: &str, name: &str) -> bool {
    [
        "fn",
        "struct",
        "enum",
        "trait",
        "type",
        "const",
        "static",
        "mod",
        "macro_rules!",
    ]
    .iter()
    .any(|kw| {
        code.match_indices(&format!("{kw} {name}")).any(|(i, m)| {
            !code[i + m.len()..]
                .chars()
                .next()
                .is_some_and(|c| c.is_alphanumeric() || c == '_')
        })
    })
}

/// The file-level import graph of the non-test code.
fn file_graph(tree: &Tree) -> BTreeMap<String, BTreeSet<String>> {
    let scans: BTreeMap<String, Scanned> = tree.iter().map(|(f, s)| (f.clone(), scan(s))).collect();
    let mut test_files = BTreeSet::new();
    for (f, s) in &scans {
        for m in &s.test_mods {
            let mut module = module_of(f);
            module.push(m.clone());
            test_files.extend(file_of(tree, &module));
        }
    }
    let mut graph = BTreeMap::new();
    for (f, s) in scans
        .iter()
        .filter(|(f, _)| !test_files.contains(*f) && *f != "lib.rs")
    {
        let edges: &mut BTreeSet<String> = graph.entry(f.clone()).or_default();
        for path in s.imports.iter().chain(inline_paths(&s.code).iter()) {
            if let Some(to) = resolve(tree, &scans, f, path, 0)
                && to != *f
                && to != "lib.rs"
                && !test_files.contains(&to)
            {
                edges.insert(to);
            }
        }
    }
    graph
}

/// Strongly connected components with more than one member (Tarjan).
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, (usize, usize)>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(t: &mut T<'a>, v: &'a str) {
        let n = t.index.len();
        t.index.insert(v, (n, n));
        t.stack.push(v);
        t.on.insert(v);
        for w in t.g.get(v).into_iter().flatten() {
            if !t.index.contains_key(w.as_str()) {
                visit(t, w);
                let lw = t.index[w.as_str()].1;
                t.index.get_mut(v).unwrap().1 = t.index[v].1.min(lw);
            } else if t.on.contains(w.as_str()) {
                let iw = t.index[w.as_str()].0;
                t.index.get_mut(v).unwrap().1 = t.index[v].1.min(iw);
            }
        }
        if t.index[v].0 == t.index[v].1 {
            let mut comp = Vec::new();
            while let Some(w) = t.stack.pop() {
                t.on.remove(w);
                comp.push(w.to_string());
                if w == v {
                    break;
                }
            }
            if comp.len() > 1 {
                comp.sort();
                t.out.push(comp);
            }
        }
    }
    let mut t = T {
        g: graph,
        index: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        if !t.index.contains_key(v.as_str()) {
            visit(&mut t, v);
        }
    }
    t.out
}

/// Every layering fault of a tree, as sentences.
fn faults(tree: &Tree) -> Vec<String> {
    let top = |f: &str| {
        f.split('/')
            .next()
            .unwrap()
            .trim_end_matches(".rs")
            .to_string()
    };
    let layer = |m: &str| LAYERS.iter().find(|(n, _)| *n == m).map(|(_, l)| *l);
    let graph = file_graph(tree);
    let mut faults = Vec::new();
    let mut modules: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (from, tos) in &graph {
        let Some(lf) = layer(&top(from)) else {
            faults.push(format!(
                "src/{from}: module `{}` has no layer in tests/native/layering.rs",
                top(from)
            ));
            continue;
        };
        for to in tos {
            let (a, b) = (top(from), top(to));
            if a != b {
                modules.entry(a.clone()).or_default().insert(b.clone());
            }
            if layer(&b).is_some_and(|lt| lt > lf) {
                faults.push(format!(
                    "src/{from} imports src/{to}: `{a}` must not use the higher layer `{b}`"
                ));
            }
        }
    }
    for c in circles(&modules) {
        faults.push(format!(
            "import circle between top-level modules: {}",
            c.join(" ↔ ")
        ));
    }
    for c in circles(&graph) {
        faults.push(format!("import circle between files: {}", c.join(" ↔ ")));
    }
    faults
}

fn crate_tree() -> Tree {
    let mut tree = Tree::new();
    read_tree(
        &Path::new(env!("CARGO_MANIFEST_DIR")).join("src"),
        "",
        &mut tree,
    );
    tree
}

#[test]
fn layers_point_down_and_nothing_imports_in_a_circle() {
    let faults = faults(&crate_tree());
    assert!(faults.is_empty(), "layering faults:\n{}", faults.join("\n"));
}

#[test]
fn an_upward_import_is_caught() {
    let mut tree = crate_tree();
    let fit = tree.get_mut("fit/mod.rs").expect("src/fit/mod.rs");
    fit.push_str("\nuse crate::export::Twin;\n");
    let faults = faults(&tree);
    assert!(
        faults
            .iter()
            .any(|f| f.contains("src/fit/mod.rs imports src/export")),
        "an added `use crate::export` under fit/ went unnoticed: {faults:?}"
    );
}

#[test]
fn a_file_circle_is_caught() {
    let mut tree = Tree::new();
    tree.insert("lib.rs".into(), "pub mod data;".into());
    tree.insert("data/mod.rs".into(), "pub mod a;\npub mod b;".into());
    tree.insert("data/a.rs".into(), "use super::b::B;\npub struct A;".into());
    tree.insert(
        "data/b.rs".into(),
        "// uses crate::data::a::A\npub struct B(crate::data::a::A);".into(),
    );
    let faults = faults(&tree);
    assert!(
        faults.iter().any(|f| f.contains("data/a.rs ↔ data/b.rs")),
        "{faults:?}"
    );
}
