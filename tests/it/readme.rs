//! The README is true where a new user starts (issue 34): its quick start runs as written, and
//! the scene it shows is the scene it names.

use crate::{hdl, helpers};
use rmapgen::scene::Scene;
use std::process::Command;

/// The text between `<!-- start -->`-style markers of the README, inside its code fence.
fn block(readme: &str, start: &str, end: &str) -> String {
    let after = readme
        .split(start)
        .nth(1)
        .unwrap_or_else(|| panic!("README has no {start}"));
    let inside = after
        .split(end)
        .next()
        .unwrap_or_else(|| panic!("README has no {end}"));
    let body = inside
        .split_once("```sh\n")
        .expect("a ```sh fence")
        .1
        .rsplit_once("```")
        .expect("the fence closes")
        .0;
    body.to_string()
}

/// The quick start, run by `sh -e` in an empty directory that holds only what a checkout has
/// there: `scenes/`, and `target/release` (the rmapgen under test, this build's binary).
#[test]
fn the_quick_start_runs_as_written() {
    if !hdl::require("verilator") || !hdl::require("yosys") {
        return;
    }
    let readme = std::fs::read_to_string(helpers::root().join("README.md")).unwrap();
    let script = block(&readme, "<!-- quick start -->", "<!-- end quick start -->");
    assert!(script.contains("rmapgen generate") && script.contains("rmapgen prove"));
    let work = helpers::tempdir();
    let dir = work.path();
    std::os::unix::fs::symlink(helpers::root().join("scenes"), dir.join("scenes")).unwrap();
    std::fs::create_dir(dir.join("target")).unwrap();
    let bin = std::path::PathBuf::from(env!("CARGO_BIN_EXE_rmapgen"));
    std::os::unix::fs::symlink(bin.parent().unwrap(), dir.join("target/release")).unwrap();
    let o = Command::new("sh")
        .args(["-e", "-c", &script])
        .current_dir(dir)
        .output()
        .expect("sh runs");
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr),
    );
    assert!(o.status.success(), "the quick start failed:\n{out}\n{err}");
    // What the README says each step gives.
    assert!(dir.join("my_design/rmap_top.v").is_file());
    assert!(dir.join("my_design/README.md").is_file());
    assert!(out.contains("sim: all passed"), "{out}");
    assert!(
        err.contains("my_scene.toml"),
        "roms --update names the scene: {err}"
    );
    assert!(out.contains("PASSED"), "{out}");
    assert!(
        out.contains(&format!("{} of", 1u64 << 24)),
        "prove drove all 2^24 gradients through the front: {out}"
    );
}

/// The scene file the README shows is `scenes/standard.toml`, field for field.
#[test]
fn the_readme_scene_is_the_standard_scene() {
    let readme = std::fs::read_to_string(helpers::root().join("README.md")).unwrap();
    let text = readme
        .split("```toml\n")
        .nth(1)
        .expect("a ```toml block")
        .split("```")
        .next()
        .unwrap();
    let shown = Scene::from_toml_str(text).expect("the README's scene parses");
    let file = Scene::from_toml_file(&helpers::root().join("scenes/standard.toml")).unwrap();
    assert_eq!(shown.named(""), file.named(""));
}

/// The README's hardware table is the rendering of the committed sweeps that measured it
/// (docs/bench/hardware, issue 60: no figure typed), and they measured the current design:
/// each row's memory bits are those of the configuration it names. `make readme-hardware` runs
/// the sweeps again and writes the table (RMAPGEN_WRITE_README=1 makes this test write it).
#[test]
fn the_readme_hardware_table_is_the_committed_sweeps() {
    use rmapgen::bench::datasheet;
    use rmapgen::config::Config;
    let root = helpers::root();
    let rows = datasheet::load(&root.join(datasheet::DIR)).unwrap();
    assert!(!rows.is_empty(), "no sweep in {}", datasheet::DIR);
    for r in &rows {
        let cfg = Config {
            lanes: r.lanes,
            mult: r.mult,
            ..Config::default()
        }
        .for_target(r.layout.target(r.family));
        let bits: u64 = rmapgen::emit::manifest::memories(&cfg)
            .iter()
            .map(|m| m.bits)
            .sum();
        assert_eq!(
            r.memory_bits,
            bits,
            "the {} row ({} lanes) measured another design: run make readme-hardware",
            r.family.title(),
            r.lanes
        );
    }
    let path = root.join("README.md");
    let readme = std::fs::read_to_string(&path).unwrap();
    let want = datasheet::with_table(&readme, &datasheet::table(&rows)).unwrap();
    if std::env::var_os("RMAPGEN_WRITE_README").is_some() {
        std::fs::write(&path, &want).unwrap();
        return;
    }
    assert!(
        readme == want,
        "README.md's hardware table is not the committed sweeps' (make readme-hardware writes it):\n{}",
        datasheet::table(&rows)
    );
}
