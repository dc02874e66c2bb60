//! The source's structure: the CPU twins and the glTF reader's modules import each other in
//! one direction only (no cycles), each taking what it needs from the module that defines it.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// The sibling modules a file names through `super::` (and `crate::<folder path>::`).
fn siblings(text: &str, crate_path: &str, names: &BTreeSet<String>) -> BTreeSet<String> {
    let mut found = BTreeSet::new();
    let ident = |s: &str| s.chars().take_while(|c| c.is_alphanumeric() || *c == '_').collect::<String>();
    for prefix in ["super::".to_string(), format!("{crate_path}::")] {
        for (i, _) in text.match_indices(&prefix) {
            let rest = &text[i + prefix.len()..];
            if let Some(group) = rest.strip_prefix('{') {
                let group = &group[..group.find('}').unwrap_or(group.len())];
                for item in group.split(',') {
                    let item = item.trim();
                    if item.contains("::") {
                        found.insert(ident(item));
                    }
                }
            } else if rest[ident(rest).len()..].starts_with("::") {
                found.insert(ident(rest));
            }
        }
    }
    found.retain(|m| names.contains(m));
    found
}

/// A cycle in the folder's import graph, if any (as the list of modules around it).
fn cycle(folder: &str, crate_path: &str) -> Option<Vec<String>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(folder);
    let mut files = BTreeMap::new();
    for entry in std::fs::read_dir(&dir).expect("source folder") {
        let path = entry.expect("entry").path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.extension().is_some_and(|e| e == "rs") && name != "mod" {
            files.insert(name, std::fs::read_to_string(&path).expect("source"));
        }
    }
    assert!(files.len() > 5, "{folder}: too few modules found");
    let names: BTreeSet<String> = files.keys().cloned().collect();
    let graph: BTreeMap<String, BTreeSet<String>> = files
        .iter()
        .map(|(n, text)| {
            let mut s = siblings(text, crate_path, &names);
            s.remove(n);
            (n.clone(), s)
        })
        .collect();
    // Depth-first search with the path kept: a back edge closes a cycle.
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        path: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(n.to_string(), 1);
        path.push(n.to_string());
        for m in &graph[n] {
            match state.get(m.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = path.iter().position(|p| p == m).unwrap();
                    let mut c = path[start..].to_vec();
                    c.push(m.clone());
                    return Some(c);
                }
                0 => {
                    if let Some(c) = visit(m, graph, state, path) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        path.pop();
        state.insert(n.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for n in graph.keys() {
        if state.get(n.as_str()).copied().unwrap_or(0) == 0
            && let Some(c) = visit(n, &graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

#[test]
fn the_cpu_twins_import_each_other_without_cycles() {
    if let Some(c) = cycle("src/cpu", "crate::cpu") {
        panic!("src/cpu imports in a cycle: {}", c.join(" → "));
    }
}

#[test]
fn the_gltf_reader_imports_without_cycles() {
    if let Some(c) = cycle("src/scene/gltf", "crate::scene::gltf") {
        panic!("src/scene/gltf imports in a cycle: {}", c.join(" → "));
    }
}

/// The check finds a cycle where there is one (so passing means something).
#[test]
fn the_cycle_check_finds_a_planted_cycle() {
    let names: BTreeSet<String> = ["a", "b"].iter().map(|s| s.to_string()).collect();
    assert_eq!(siblings("use super::{b::X, c::Y};", "crate::m", &names), ["b".to_string()].into());
    assert_eq!(siblings("let x = crate::m::a::f();", "crate::m", &names), ["a".to_string()].into());
}
