//! The Python tests over the extension this very build made, as a cargo test, so that
//! cargo-mutants can judge the mutants of python/src by them (docs/VERIFICATION.md, "The
//! Python package's checks"):
//!
//!     cargo mutants --in-place --profile mutants -p rmapgen-python -- --test pytest --ignored
//!
//! Ignored in plain `cargo test`: `make python-test` runs the same tests over the extension
//! `make test` installs. RMAPGEN_PYTEST selects the test files (default: every one but
//! test_vectors.py, which needs the command line); the venv is the project's `.venv`.

use std::path::Path;
use std::process::Command;

#[test]
#[ignore = "make python-test runs these tests; cargo-mutants runs them with --ignored"]
fn pytest_over_this_builds_extension() {
    let python = Path::new(env!("CARGO_MANIFEST_DIR"));
    let root = python.parent().expect("python/ is in the repository");
    // This test runs from target/<profile>/deps, where `cargo test` leaves the extension it
    // built for it (the `rlib` crate type makes it the test's dependency; only `cargo build`
    // copies it up to target/<profile>/).
    let exe = std::env::current_exe().expect("the test's path");
    let so = exe.with_file_name("lib_rmapgen.so");
    assert!(so.is_file(), "{} is built with the test", so.display());
    // The package beside nothing else: python/rmapgen/__init__.py and this extension.
    let site =
        Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("pytest-{}", std::process::id()));
    let pkg = site.join("rmapgen");
    std::fs::create_dir_all(&pkg).expect("a package folder");
    std::fs::copy(python.join("rmapgen/__init__.py"), pkg.join("__init__.py")).expect("copied");
    std::fs::copy(&so, pkg.join("_rmapgen.abi3.so")).expect("copied");
    let tests = std::env::var("RMAPGEN_PYTEST").unwrap_or_else(|_| {
        "python/tests/test_api.py python/tests/test_refusals.py python/tests/test_quantize.py \
         python/tests/test_readme.py"
            .into()
    });
    let status = Command::new(root.join(".venv/bin/python"))
        .args(["-m", "pytest", "-q", "-x", "-p", "no:cacheprovider"])
        .args(tests.split_whitespace())
        .env("PYTHONPATH", &site)
        .current_dir(root)
        .status()
        .expect("the venv's python runs");
    std::fs::remove_dir_all(&site).expect("the package folder removed");
    assert!(status.success(), "pytest: {status}");
}
