//! The crate's module graph (src/): no module depends, through `crate::` or `super::` paths in
//! its non-test code, on a module that depends back on it. Cycles are what make one change
//! spread over several places; this keeps them from coming back.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Module path (`model::color_mul`) to its source text, test modules cut off.
fn modules(src: &Path) -> BTreeMap<String, String> {
    fn walk(dir: &Path, base: &Path, out: &mut BTreeMap<String, String>) {
        for e in std::fs::read_dir(dir).expect("src readable") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                walk(&p, base, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(base).unwrap().with_extension("");
                let mut parts: Vec<String> = rel
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                if parts.last().is_some_and(|l| l == "mod") {
                    parts.pop();
                }
                if parts == ["lib"] || parts == ["main"] {
                    continue;
                }
                let text = std::fs::read_to_string(&p).expect("source readable");
                let code = match text.find("#[cfg(test)]") {
                    Some(i) => text[..i].to_string(),
                    None => text,
                };
                out.insert(parts.join("::"), code);
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(src, src, &mut out);
    out
}

/// The module each `crate::`/`super::` path of `code` (written in module `from`) names.
fn uses(from: &str, code: &str, names: &BTreeSet<String>) -> BTreeSet<String> {
    let resolve = |path: &str| -> Option<String> {
        let parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
        (1..=parts.len())
            .rev()
            .map(|k| parts[..k].join("::"))
            .find(|c| names.contains(c))
    };
    let parent = from.rsplit_once("::").map_or("", |(p, _)| p);
    let mut out = BTreeSet::new();
    for line in code.lines() {
        let line = line.split("//").next().unwrap_or("");
        for (prefix, base) in [("crate::", String::new()), ("super::", parent.to_string())] {
            let mut rest = line;
            while let Some(i) = rest.find(prefix) {
                rest = &rest[i + prefix.len()..];
                let path: String = rest
                    .chars()
                    .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
                    .collect();
                let path = path.trim_end_matches(':');
                let mut targets = vec![path.to_string()];
                // `crate::model::{fast, Maps}`: each item of the group.
                if let Some(group) = rest[path.len()..].strip_prefix("::{") {
                    let group = group.split('}').next().unwrap_or("");
                    targets.extend(
                        group
                            .split(',')
                            .map(|t| t.trim().split(' ').next().unwrap_or(""))
                            .filter(|t| !t.is_empty() && *t != "self")
                            .map(|t| format!("{path}::{t}")),
                    );
                }
                for t in targets {
                    let full = if base.is_empty() {
                        t
                    } else {
                        format!("{base}::{t}")
                    };
                    if let Some(m) = resolve(&full) {
                        let nested = from.starts_with(&format!("{m}::"))
                            || m.starts_with(&format!("{from}::"));
                        if m != from && !nested {
                            out.insert(m);
                        }
                    }
                }
            }
        }
    }
    out
}

/// Every pair of modules that use each other directly or through others (the strongly
/// connected components with more than one module).
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    // Reachability by repeated search: the crate has ~100 modules, so this is instant.
    let reach = |start: &str| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut todo = vec![start.to_string()];
        while let Some(m) = todo.pop() {
            for n in graph.get(&m).into_iter().flatten() {
                if seen.insert(n.clone()) {
                    todo.push(n.clone());
                }
            }
        }
        seen
    };
    let reaches: BTreeMap<&String, BTreeSet<String>> =
        graph.keys().map(|m| (m, reach(m))).collect();
    let mut out: Vec<Vec<String>> = Vec::new();
    for (m, r) in &reaches {
        if !r.contains(*m) || out.iter().any(|c| c.contains(m)) {
            continue;
        }
        let comp: Vec<String> = r
            .iter()
            .filter(|n| reaches[n].contains(*m))
            .cloned()
            .collect();
        out.push(comp);
    }
    out
}

fn graph(mods: &BTreeMap<String, String>) -> BTreeMap<String, BTreeSet<String>> {
    let names: BTreeSet<String> = mods.keys().cloned().collect();
    mods.iter()
        .map(|(m, code)| (m.clone(), uses(m, code, &names)))
        .collect()
}

#[test]
fn the_module_graph_has_no_cycles() {
    let mods = modules(&crate::helpers::root().join("src"));
    assert!(mods.len() > 50, "found {} modules", mods.len());
    let g = graph(&mods);
    assert!(
        g["cmd::generate"].contains("rtl") && g["rtl::tb"].contains("config"),
        "the reader sees the crate's imports: {:?}",
        g["cmd::generate"]
    );
    assert_eq!(cycles(&g), Vec::<Vec<String>>::new(), "module cycles");
}

#[test]
fn a_planted_cycle_is_found() {
    let mods: BTreeMap<String, String> = [
        ("config", "use crate::model::color_mul::constants;\n"),
        ("model", ""),
        (
            "model::color_mul",
            "use crate::config::{Config, COLOR_BITS};\n",
        ),
        (
            "scene",
            "use super::model::Maps;\n// crate::config is only a comment here\n",
        ),
        ("scene::transfer", "use super::Scene;\n"),
    ]
    .into_iter()
    .map(|(a, b)| (a.to_string(), b.to_string()))
    .collect();
    let g = graph(&mods);
    assert_eq!(
        cycles(&g),
        vec![vec!["config".to_string(), "model::color_mul".to_string()]]
    );
    assert!(!g["scene"].contains("config"), "comments are not uses");
    assert!(g["scene"].contains("model"));
}

/// The imports that point upward: `config` using anything but `toml_input`, or a stage's
/// bit-accurate model (`stages::<stage>::model`, the definition the generator, the vectors and
/// the renders build on) reaching back into any of them or into a stage's generator unit.
fn upward_imports(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let mut out = Vec::new();
    for d in g.get("config").into_iter().flatten() {
        if d != "toml_input" {
            out.push(format!("config -> {d}"));
        }
    }
    let above = [
        "rtl", "vectors", "cmd", "render", "volume", "fit", "bench", "stress",
    ];
    for (m, deps) in g {
        if !(m.starts_with("stages::") && m.ends_with("::model")) {
            continue;
        }
        for d in deps {
            let top = d.split("::").next().unwrap_or("");
            let unit = d.starts_with("stages::") && !d.ends_with("::model");
            if above.contains(&top) || unit {
                out.push(format!("{m} -> {d}"));
            }
        }
    }
    out
}

#[test]
fn config_and_the_stage_models_import_nothing_above_them() {
    let g = graph(&modules(&crate::helpers::root().join("src")));
    let models = g
        .keys()
        .filter(|m| m.starts_with("stages::") && m.ends_with("::model"))
        .count();
    assert!(models >= 9, "found {models} stage models");
    assert_eq!(upward_imports(&g), Vec::<String>::new());
}

#[test]
fn planted_upward_imports_are_found() {
    let mods: BTreeMap<String, String> = [
        (
            "config",
            "use crate::toml_input;\nuse crate::rtl::ports::Port;\n",
        ),
        ("toml_input", ""),
        ("rtl", ""),
        ("rtl::ports", ""),
        ("stages", ""),
        ("stages::normalise", "use crate::rtl::ports::Port;\n"),
        ("stages::normalise::model", "use crate::config::Config;\n"),
        ("stages::sort_shift", ""),
        (
            "stages::sort_shift::model",
            "use crate::stages::normalise::Plan;\n",
        ),
    ]
    .into_iter()
    .map(|(a, b)| (a.to_string(), b.to_string()))
    .collect();
    assert_eq!(
        upward_imports(&graph(&mods)),
        [
            "config -> rtl::ports",
            "stages::sort_shift::model -> stages::normalise"
        ]
    );
}
