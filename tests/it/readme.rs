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
