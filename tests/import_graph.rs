//! The module graph as the source states it, held to docs/design.md: every `crate::module`
//! path a module's code names (comments and its tests left out) must be one of the imports its
//! row in the design's "Modules" table allows, and the modules must import each other without
//! a circle. A circle means one module holds data another one needs: move the data. It reads
//! the source tree and the design as files (from the package's folder) and needs nothing of
//! the crate itself.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Top-level module (each `pub mod` of lib.rs) → the modules its code names, read from `src/`.
fn imports(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let lib = std::fs::read_to_string(src.join("lib.rs")).expect("src/lib.rs");
    let mut graph: BTreeMap<String, BTreeSet<String>> = lib
        .lines()
        .filter_map(|l| l.strip_prefix("pub mod ")?.strip_suffix(';'))
        .map(|m| (m.to_string(), BTreeSet::new()))
        .collect();
    let mut stack = vec![src.to_path_buf()];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).expect("src/ is readable") {
            let path = entry.expect("a folder entry").path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|e| e != "rs") {
                continue;
            }
            let relative = path.strip_prefix(src).expect("below src/");
            let module = relative
                .components()
                .next()
                .and_then(|c| c.as_os_str().to_str())
                .map(|c| c.trim_end_matches(".rs").to_string())
                .expect("a file name");
            let Some(named) = graph.get_mut(&module) else {
                continue;
            };
            let text = std::fs::read_to_string(&path).expect("a source file");
            let code = text.split("#[cfg(test)]").next().unwrap_or_default();
            for line in code.lines() {
                let line = line.split("//").next().unwrap_or_default();
                for (at, _) in line.match_indices("crate::") {
                    let rest = &line[at + "crate::".len()..];
                    let end = rest
                        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
                        .unwrap_or(rest.len());
                    let target = &rest[..end];
                    if !target.is_empty() && target != module {
                        named.insert(target.to_string());
                    }
                }
            }
        }
    }
    graph
}

/// The "Modules" table of docs/design.md: module → the modules it may import.
fn allowed(design: &str) -> BTreeMap<String, BTreeSet<String>> {
    let table = design
        .split("\n## Modules\n")
        .nth(1)
        .expect("docs/design.md has a Modules section");
    table
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|row| {
            let cells: Vec<&str> = row.split('|').map(str::trim).collect();
            let module = cells[1].trim_matches('`').to_string();
            let imports = cells[3]
                .split(',')
                .map(|m| m.trim().trim_matches('`'))
                .filter(|m| !m.is_empty() && *m != "none")
                .map(str::to_string)
                .collect();
            (module, imports)
        })
        .collect()
}

/// The groups of modules that import each other round a circle (strongly connected
/// components of more than one module).
fn circles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<BTreeSet<String>> {
    let reaches = |from: &str| {
        let mut seen = BTreeSet::new();
        let mut todo = vec![from.to_string()];
        while let Some(m) = todo.pop() {
            for next in graph.get(&m).into_iter().flatten() {
                if seen.insert(next.clone()) {
                    todo.push(next.clone());
                }
            }
        }
        seen
    };
    let reach: BTreeMap<&String, BTreeSet<String>> =
        graph.keys().map(|m| (m, reaches(m))).collect();
    let mut out: Vec<BTreeSet<String>> = Vec::new();
    for (m, from_m) in &reach {
        let group: BTreeSet<String> = from_m
            .iter()
            .filter(|o| reach.get(o).is_some_and(|r| r.contains(*m)))
            .cloned()
            .collect();
        if !group.is_empty() && !out.iter().any(|g| g.contains(*m)) {
            out.push(group);
        }
    }
    out
}

#[test]
fn every_module_imports_only_what_the_design_allows_and_no_module_imports_round_a_circle() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let graph = imports(&root.join("src"));
    let design = std::fs::read_to_string(root.join("docs/design.md")).expect("docs/design.md");
    let allowed = allowed(&design);
    let modules: BTreeSet<&String> = graph.keys().collect();
    let listed: BTreeSet<&String> = allowed.keys().collect();
    assert_eq!(modules, listed, "the Modules table lists every module");
    for (module, named) in &graph {
        let extra: Vec<&String> = named.difference(&allowed[module]).collect();
        assert!(
            extra.is_empty(),
            "{module} imports {extra:?}, which its row in docs/design.md does not allow"
        );
    }
    assert_eq!(circles(&graph), Vec::<BTreeSet<String>>::new());
}

#[test]
fn a_circle_is_found_however_long_and_a_chain_is_none() {
    let graph = |edges: &[(&str, &str)]| {
        let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        for (a, b) in edges {
            g.entry(a.to_string()).or_default().insert(b.to_string());
            g.entry(b.to_string()).or_default();
        }
        g
    };
    let chain = graph(&[("a", "b"), ("b", "c"), ("a", "c")]);
    assert!(circles(&chain).is_empty());
    let ring = graph(&[("a", "b"), ("b", "c"), ("c", "a"), ("c", "d")]);
    let expected: BTreeSet<String> = ["a", "b", "c"].iter().map(|s| s.to_string()).collect();
    assert_eq!(circles(&ring), vec![expected]);
}

#[test]
fn the_modules_table_is_read_as_module_and_allowed_imports() {
    let design = "intro\n\n## Modules\n\n| module | owns | may import |\n|---|---|---|\n| `asset` | files | `diagnostics` |\n| `shading` | maths | none |\n\n## Next\n";
    let table = allowed(design);
    assert_eq!(table.len(), 2);
    assert_eq!(table["asset"], BTreeSet::from(["diagnostics".to_string()]));
    assert!(table["shading"].is_empty());
}
