//! The crate's module graph (src/): no module depends on a module that depends back on it.
//! Every way non-test code names a module counts: `crate::`, `self::` and `super::` paths in
//! code and in intra-doc links, each item of a `use` group, and paths through a name a `use`
//! brought in (`use crate::rtl;` then `rtl::tb::x`, or one renamed with `as`). A module's
//! own descendants are not a cycle (it declares them). Cycles are what make one change spread
//! over several places; this keeps them from coming back. (Counted this way on 2026-12-05
//! there were 8 cycles, one of them through 38 modules, all closed by doc links; the scan of
//! code paths alone saw none.)

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

/// The text of a line that can name a module: its code (a string or comment cut off at `//`)
/// and, in a doc comment, its intra-doc links (`[`crate::x::Y`]`, `[text](crate::x)`).
fn scanned(line: &str) -> String {
    let t = line.trim_start();
    if let Some(doc) = t.strip_prefix("///").or_else(|| t.strip_prefix("//!")) {
        let mut out = String::new();
        let mut rest = doc;
        while let Some(i) = rest.find('[') {
            rest = &rest[i + 1..];
            let Some(j) = rest.find(']') else { break };
            out.push_str(&rest[..j]);
            out.push(' ');
            rest = &rest[j + 1..];
            if let Some(target) = rest.strip_prefix('(') {
                out.push_str(target.split(')').next().unwrap_or(""));
                out.push(' ');
            }
        }
        return out.replace('`', " ");
    }
    line.split("//").next().unwrap_or("").to_string()
}

/// The module path a path written in module `from` starts from: `crate::` the root,
/// `self::` the module itself, `super::` (repeated) its ancestors; `None` for other paths.
fn anchored(from: &str, path: &str) -> Option<String> {
    let mut base: Vec<&str> = from.split("::").filter(|p| !p.is_empty()).collect();
    let mut rest = path;
    if let Some(r) = rest.strip_prefix("crate::") {
        return Some(r.to_string());
    }
    if let Some(r) = rest.strip_prefix("self::") {
        rest = r;
    } else if rest.starts_with("super::") {
        while let Some(r) = rest.strip_prefix("super::") {
            base.pop();
            rest = r;
        }
    } else {
        return None;
    }
    base.push(rest);
    Some(base.join("::"))
}

/// The module each path of `code` (written in module `from`) names: paths from `crate::`,
/// `self::` and `super::`, in code and in intra-doc links, each item of a `use` group, and
/// paths that start with a name a `use` of the module brought in (`use crate::rtl;` then
/// `rtl::tb::x`). A module's own descendants and ancestors are not counted: a module
/// contains its children (it declares them), so only edges between modules where neither
/// contains the other can close a cycle.
fn uses(from: &str, code: &str, names: &BTreeSet<String>) -> BTreeSet<String> {
    let resolve = |path: &str| -> Option<String> {
        let parts: Vec<&str> = path.split("::").filter(|p| !p.is_empty()).collect();
        (1..=parts.len())
            .rev()
            .map(|k| parts[..k].join("::"))
            .find(|c| names.contains(c))
    };
    let is_ident = |c: char| c.is_alphanumeric() || c == '_';
    // Every path of the text: a run of identifier characters and `::`, with `use` groups
    // (`a::{b, c::d}`) expanded, one level deep.
    let paths = |text: &str| -> Vec<String> {
        let mut out = Vec::new();
        let chars: Vec<char> = text.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            if !is_ident(chars[i]) || (i > 0 && (is_ident(chars[i - 1]) || chars[i - 1] == ':')) {
                i += 1;
                continue;
            }
            let mut j = i;
            while j < chars.len() && (is_ident(chars[j]) || chars[j] == ':') {
                j += 1;
            }
            let path: String = chars[i..j].iter().collect();
            let path = path.trim_end_matches(':').to_string();
            if path.contains("::") {
                out.push(path.clone());
            }
            if j < chars.len() && chars[j] == '{' && chars[j - 1] == ':' {
                let group: String = chars[j + 1..].iter().take_while(|&&c| c != '}').collect();
                for item in group.split(',') {
                    let item = item.trim().split(' ').next().unwrap_or("");
                    if !item.is_empty() && item != "self" {
                        out.push(format!("{path}::{item}"));
                    }
                }
            }
            i = j.max(i + 1);
        }
        out
    };
    let text: String = code.lines().map(|l| scanned(l) + "\n").collect();
    // Names that `use` lines bring into scope, to the module paths they stand for.
    let mut alias: BTreeMap<String, String> = BTreeMap::new();
    for line in code.lines() {
        let t = line.trim_start();
        let Some(u) = t
            .strip_prefix("pub use ")
            .or_else(|| t.strip_prefix("use "))
            .or_else(|| t.strip_prefix("pub(crate) use "))
        else {
            continue;
        };
        for p in paths(u) {
            let Some(full) = anchored(from, &p) else {
                continue;
            };
            if names.contains(&full) {
                let last = full.rsplit("::").next().unwrap_or("").to_string();
                alias.insert(last, full);
            }
        }
        // `use crate::a::b as c;`
        if let Some((p, a)) = u.trim_end_matches(';').split_once(" as ") {
            if let Some(full) = anchored(from, p.trim()) {
                if names.contains(&full) {
                    alias.insert(a.trim().to_string(), full);
                }
            }
        }
    }
    let mut out = BTreeSet::new();
    for p in paths(&text) {
        let full = match anchored(from, &p) {
            Some(f) => f,
            None => {
                let (head, rest) = p.split_once("::").unwrap_or((&p, ""));
                match alias.get(head) {
                    Some(m) => format!("{m}::{rest}"),
                    None => continue,
                }
            }
        };
        if let Some(m) = resolve(&full) {
            let nested = from.starts_with(&format!("{m}::")) || m.starts_with(&format!("{from}::"));
            if m != from && !nested {
                out.insert(m);
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
        g["cmd::generate"].contains("emit::dir") && g["emit::tb"].contains("config"),
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

/// The ways a module names another that a scan of `crate::` and `super::` in code alone
/// misses: each closes a cycle here, which must be found.
#[test]
fn cycles_through_doc_links_aliases_and_relative_paths_are_found() {
    let case = |mods: &[(&str, &str)]| {
        let mods: BTreeMap<String, String> = mods
            .iter()
            .map(|(a, b)| (a.to_string(), b.to_string()))
            .collect();
        cycles(&graph(&mods))
    };
    let pair = |a: &str, b: &str| vec![vec![a.to_string(), b.to_string()]];
    // An intra-doc link, in a module's docs or an item's.
    assert_eq!(
        case(&[
            ("config", "//! Packed as [`crate::stages::Packing`] says.\n"),
            ("stages", "use crate::config::Config;\n"),
        ]),
        pair("config", "stages")
    );
    assert_eq!(
        case(&[
            ("a", "/// See [the other](crate::b::f).\nfn g() {}\n"),
            ("b", "use crate::a;\n"),
        ]),
        pair("a", "b")
    );
    // A path through a name a `use` brought in, and through a renamed one.
    assert_eq!(
        case(&[
            ("rtl", ""),
            ("rtl::tb", "use crate::model::Model;\n"),
            ("model", "use crate::rtl;\nfn f() { rtl::tb::write(); }\n"),
        ]),
        pair("model", "rtl::tb")
    );
    assert_eq!(
        case(&[
            ("p", ""),
            ("p::q", "use crate::r as other;\n"),
            ("r", "use crate::p::q as qq;\nfn f() { qq::go(); }\n"),
        ]),
        pair("p::q", "r")
    );
    // `self::` and `super::super::`.
    assert_eq!(
        case(&[
            ("a", ""),
            ("a::b", ""),
            ("a::b::c", "use super::super::d::X;\n"),
            ("a::d", "fn f() { crate::a::b::c::go(); }\n"),
        ]),
        pair("a::b::c", "a::d")
    );
    // A module's own children are contained, not a cycle.
    assert_eq!(
        case(&[("m", "pub use self::n::X;\n"), ("m::n", "use super::Y;\n"),]),
        Vec::<Vec<String>>::new()
    );
}

/// The generator's layers, lowest first: Verilog building blocks, the stages that use them,
/// the design writer above the stages, and the flows and proofs that read a written design.
const LAYERS: [&str; 6] = ["hdl", "stages", "emit", "flow", "prove", "cmd"];

/// What `config` may import: the TOML reader and the family descriptors (data).
const BELOW_CONFIG: [&str; 2] = ["toml_input", "family"];

/// The imports that point upward: a layer of [`LAYERS`] using a later one, `config` using
/// anything but [`BELOW_CONFIG`], `family` (the FPGA families' descriptors, the bottom layer)
/// using anything of rmapgen, or a stage's bit-accurate model (`stages::<stage>::model`, the
/// definition the generator, the vectors and the renders build on) reaching back into any of
/// them or into a stage's generator unit.
fn upward_imports(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    let mut out = Vec::new();
    let top_of = |m: &str| m.split("::").next().unwrap_or("").to_string();
    for d in g.get("config").into_iter().flatten() {
        if !BELOW_CONFIG.contains(&top_of(d).as_str()) {
            out.push(format!("config -> {d}"));
        }
    }
    for (m, deps) in g.iter().filter(|(m, _)| top_of(m) == "family") {
        for d in deps.iter().filter(|d| top_of(d) != "family") {
            out.push(format!("{m} -> {d}"));
        }
    }
    let above = [
        "emit", "flow", "hdl", "vectors", "cmd", "render", "volume", "fit", "bench", "stress",
    ];
    // The layers of the generator: a folder imports only the ones before it.
    for (m, deps) in g {
        let top = m.split("::").next().unwrap_or("");
        let Some(at) = LAYERS.iter().position(|l| *l == top) else {
            continue;
        };
        for d in deps {
            let dtop = d.split("::").next().unwrap_or("");
            if LAYERS[at + 1..].contains(&dtop) {
                out.push(format!("{m} -> {d}"));
            }
        }
    }
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
            "use crate::toml_input;\nuse crate::family::Family;\nuse crate::rtl::ports::Port;\n",
        ),
        ("toml_input", ""),
        ("family", "mod ice40;\n"),
        (
            "family::ice40",
            "use super::Descriptor;\nuse crate::config::Target;\n",
        ),
        ("rtl", ""),
        ("rtl::ports", ""),
        ("hdl", ""),
        ("hdl::ports", "use crate::stages::TOP;\n"),
        ("emit", "use crate::hdl::Port;\nuse crate::stages;\n"),
        ("emit::tb", "/// Read by [`crate::prove::Report`].\n"),
        ("prove", ""),
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
            "family::ice40 -> config",
            "emit::tb -> prove",
            "hdl::ports -> stages",
            "stages::sort_shift::model -> stages::normalise"
        ]
    );
}
/// Command modules (`cmd::<name>` with a `pub fn run`) that use another command's module: a
/// command parses its flags and calls the library; shared flag groups (`config_args`,
/// `force`, ...) and the progress display are not commands.
fn command_to_command(mods: &BTreeMap<String, String>) -> Vec<String> {
    let g = graph(mods);
    let is_command = |m: &str| {
        m.starts_with("cmd::") && mods.get(m).is_some_and(|code| code.contains("pub fn run("))
    };
    let mut out = Vec::new();
    for (m, deps) in &g {
        if !is_command(m) {
            continue;
        }
        for d in deps {
            if is_command(d) {
                out.push(format!("{m} -> {d}"));
            }
        }
    }
    out
}

#[test]
fn no_command_calls_another_commands_module() {
    let mods = modules(&crate::helpers::root().join("src"));
    let commands = mods
        .iter()
        .filter(|(m, c)| m.starts_with("cmd::") && c.contains("pub fn run("))
        .count();
    assert!(commands >= 15, "found {commands} commands");
    assert_eq!(command_to_command(&mods), Vec::<String>::new());
    // Planted: prove_mult reaching into sim's module is found; a shared flag group is not.
    let planted: BTreeMap<String, String> = [
        ("cmd", ""),
        ("cmd::force", "pub struct ForceArg;\n"),
        ("cmd::sim", "use super::force::ForceArg;\npub fn run() {}\n"),
        (
            "cmd::prove_mult",
            "use super::force::ForceArg;\nuse super::sim::generate_row;\npub fn run() {}\n",
        ),
    ]
    .into_iter()
    .map(|(a, b)| (a.to_string(), b.to_string()))
    .collect();
    assert_eq!(
        command_to_command(&planted),
        ["cmd::prove_mult -> cmd::sim"]
    );
}
