//! The library's top-level modules form no dependency cycle
//! (docs/architecture.md, "Layers"): reads every file under src/ (the
//! command line excepted) for `crate::MODULE` paths and looks for a cycle
//! in the graph of top-level modules.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

fn rust_files(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Top-level module → the top-level modules its code names.
fn dependencies() -> BTreeMap<String, BTreeSet<String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for file in files {
        let rel = file.strip_prefix(&src).unwrap();
        let top = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        let top = top.trim_end_matches(".rs").to_string();
        if matches!(top.as_str(), "cli" | "main" | "lib") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for line in text.lines() {
            let code = line.split("//").next().unwrap_or_default();
            for (at, _) in code.match_indices("crate::") {
                let name: String = code[at + 7..]
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_')
                    .collect();
                // Root re-exports name the module they come from.
                let module = match name.as_str() {
                    "Error" => "error".to_string(),
                    "PointSet" => "points".to_string(),
                    _ => name,
                };
                if module != top {
                    graph.entry(top.clone()).or_default().insert(module);
                }
            }
        }
    }
    graph
}

#[test]
fn top_level_modules_form_no_cycle() {
    let graph = dependencies();
    assert!(graph.len() > 10, "read too few modules: {graph:?}");
    for (from, targets) in &graph {
        for to in targets {
            // Is `from` reachable from `to`? Then from → to → … → from.
            let mut stack = vec![(to.clone(), vec![from.clone(), to.clone()])];
            let mut seen = BTreeSet::new();
            while let Some((node, path)) = stack.pop() {
                assert!(node != *from, "module cycle: {}", path.join(" → "));
                if seen.insert(node.clone()) {
                    for next in graph.get(&node).into_iter().flatten() {
                        let mut p = path.clone();
                        p.push(next.clone());
                        stack.push((next.clone(), p));
                    }
                }
            }
        }
    }
}

#[test]
fn samplers_and_the_optimizer_do_not_name_the_registry() {
    let graph = dependencies();
    for module in ["samplers", "optimize", "optimized"] {
        let names = graph.get(module).cloned().unwrap_or_default();
        if module != "optimized" {
            assert!(
                !names.contains("optimized"),
                "{module} names the optimized sampler"
            );
        }
        assert!(
            !names.contains("registry"),
            "{module} depends on the registry"
        );
    }
}

/// With `autotests = false` a test file runs only if tests/suite.rs declares
/// it (or Cargo.toml names it as its own binary): a file added without
/// either would compile nowhere and never run, silently.
#[test]
fn every_test_file_is_part_of_a_test_binary() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let suite = std::fs::read_to_string(root.join("tests/suite.rs")).unwrap();
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let declared: BTreeSet<String> = suite
        .lines()
        .filter_map(|l| l.trim().strip_prefix("mod "))
        .map(|m| m.trim_end_matches(';').trim().to_string())
        .collect();
    let mut orphans = Vec::new();
    for entry in std::fs::read_dir(root.join("tests")).unwrap() {
        let path = entry.unwrap().path();
        let Some(stem) = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .filter(|_| path.extension().is_some_and(|e| e == "rs"))
        else {
            continue;
        };
        let own_binary = manifest.contains(&format!("path = \"tests/{stem}.rs\""));
        if stem != "suite" && !own_binary && !declared.contains(&stem) {
            orphans.push(stem);
        }
    }
    assert!(
        orphans.is_empty(),
        "tests/{{{}}}.rs: declare each in tests/suite.rs (mod NAME;) or as a [[test]] in Cargo.toml",
        orphans.join(",")
    );
    assert!(
        declared.len() > 30,
        "tests/suite.rs declares {} modules",
        declared.len()
    );
}
