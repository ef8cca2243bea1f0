//! Output directories and files (src/output): rmapgen replaces only what it wrote, never the
//! current directory, its ancestors or a directory holding an input, and an interrupted run
//! leaves nothing behind.

use crate::helpers::{self, assert_error, first_difference, run_in, tempdir, tree};
use std::os::unix::process::ExitStatusExt;
use std::path::Path;
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn ok(out: &Output) {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// A user's folder of notes, and a snapshot of it to compare after.
fn notes(dir: &Path) -> std::collections::BTreeMap<String, Vec<u8>> {
    std::fs::create_dir_all(dir.join("sub")).unwrap();
    std::fs::write(dir.join("todo.txt"), "buy solder\n").unwrap();
    std::fs::write(dir.join("sub/plan.md"), "# plan\n").unwrap();
    tree(dir)
}

/// Nothing but `names` in `dir` (no staging directories or partial files beside an output).
fn only(dir: &Path, names: &[&str]) {
    let got = helpers::entries(dir);
    let mut want: Vec<String> = names.iter().map(|s| s.to_string()).collect();
    want.sort();
    assert_eq!(got, want, "entries of {}", dir.display());
}

#[test]
fn foreign_files_in_out_are_never_replaced() {
    let t = tempdir();
    let d = t.path().join("notes");
    let before = notes(&d);
    for args in [
        &["render", "--size", "16", "--out", "notes"][..],
        &["generate", "--out", "notes"],
        &["roms", "--out", "notes"],
        &["volume", "--synthetic", "--size", "16", "--out", "notes"],
        &["bench", "--quick", "--no-yosys", "--out", "notes"],
        &["fpga", "--logs", "notes"],
    ] {
        let out = run_in(t.path(), args);
        assert_error(
            &out,
            "will not replace notes: it holds sub/, which rmapgen did not write",
        );
        assert_eq!(tree(&d), before, "{args:?} changed the folder");
        only(t.path(), &["notes"]);
    }
    // --force is the user's word that the folder may go.
    ok(&run_in(
        t.path(),
        &["render", "--size", "16", "--out", "notes", "--force"],
    ));
    assert!(d.join("model.png").is_file() && !d.join("todo.txt").exists());
}

#[test]
fn generate_without_out_keeps_a_users_file_in_rtl_out() {
    let t = tempdir();
    ok(&run_in(t.path(), &["generate"]));
    std::fs::write(
        t.path().join("rtl_out/my_wrapper.v"),
        "module w;\nendmodule\n",
    )
    .unwrap();
    let before = tree(&t.path().join("rtl_out"));
    let out = run_in(t.path(), &["generate"]);
    assert_error(&out, "it holds my_wrapper.v, which rmapgen did not write");
    assert_eq!(tree(&t.path().join("rtl_out")), before);
}

#[test]
fn own_output_is_replaced_but_an_edited_file_is_not() {
    let t = tempdir();
    ok(&run_in(t.path(), &["render", "--size", "16", "--out", "r"]));
    ok(&run_in(t.path(), &["render", "--size", "20", "--out", "r"]));
    // A file rmapgen wrote but a user changed since counts as theirs.
    std::fs::write(t.path().join("r/metrics.json"), "{}\n").unwrap();
    let out = run_in(t.path(), &["render", "--size", "16", "--out", "r"]);
    assert_error(&out, "metrics.json was changed since rmapgen wrote it");
    assert_eq!(
        std::fs::read(t.path().join("r/metrics.json")).unwrap(),
        b"{}\n"
    );
    // An empty directory of theirs inside counts too.
    std::fs::write(t.path().join("r/metrics.json"), "{}\n").unwrap();
    ok(&run_in(
        t.path(),
        &["render", "--size", "16", "--out", "r", "--force"],
    ));
    std::fs::create_dir(t.path().join("r/keep")).unwrap();
    let out = run_in(t.path(), &["render", "--size", "16", "--out", "r"]);
    assert_error(&out, "it holds keep/, which rmapgen did not write");
    // An empty or absent directory is fine.
    std::fs::create_dir(t.path().join("empty")).unwrap();
    ok(&run_in(
        t.path(),
        &["render", "--size", "16", "--out", "empty"],
    ));
    ok(&run_in(
        t.path(),
        &["render", "--size", "16", "--out", "new/deeper/r"],
    ));
    only(t.path(), &["empty", "new", "r"]);
}

#[test]
fn an_input_inside_out_is_never_replaced_even_forced() {
    let t = tempdir();
    let d = t.path().join("d");
    std::fs::create_dir(&d).unwrap();
    std::fs::copy(
        helpers::root().join("scenes/standard.toml"),
        d.join("my_scene.toml"),
    )
    .unwrap();
    std::fs::write(d.join("cfg.toml"), "index_bits = 4\n").unwrap();
    std::fs::write(d.join("scan.raw"), vec![7u8; 8 * 8 * 8]).unwrap();
    let before = tree(&d);
    for (args, input) in [
        (
            &[
                "render",
                "--scene",
                "d/my_scene.toml",
                "--size",
                "16",
                "--out",
                "d",
            ][..],
            "my_scene.toml",
        ),
        (
            &["generate", "--config", "d/cfg.toml", "--out", "d"],
            "cfg.toml",
        ),
        (
            &[
                "volume",
                "d/scan.raw",
                "--dims",
                "8,8,8",
                "--size",
                "16",
                "--out",
                "d",
            ],
            "scan.raw",
        ),
        (
            &["roms", "--scene", "d/my_scene.toml", "--out", "d"],
            "my_scene.toml",
        ),
    ] {
        for force in [false, true] {
            let mut a = args.to_vec();
            if force {
                a.push("--force");
            }
            let out = run_in(t.path(), &a);
            assert_error(
                &out,
                &format!("d/{input}, an input of this command (not even with --force)"),
            );
            assert_eq!(tree(&d), before, "{a:?}");
        }
    }
    // The same input given through another spelling of the path.
    let abs = d.join("my_scene.toml");
    let out = run_in(
        t.path(),
        &[
            "render",
            "--scene",
            abs.to_str().unwrap(),
            "--size",
            "16",
            "--out",
            "./d/../d",
            "--force",
        ],
    );
    assert_error(&out, "an input of this command");
    only(t.path(), &["d"]);
}

#[test]
fn regenerating_in_place_from_the_written_config_works() {
    let t = tempdir();
    ok(&run_in(
        t.path(),
        &["generate", "--index-bits", "4", "--out", "g"],
    ));
    let first = tree(&t.path().join("g"));
    let out = run_in(
        t.path(),
        &["generate", "--config", "g/tb/config.toml", "--out", "g"],
    );
    ok(&out);
    assert_eq!(tree(&t.path().join("g")), first, "same config, same design");
}

#[test]
fn the_current_directory_and_its_ancestors_are_never_replaced() {
    let t = tempdir();
    let cwd = t.path().join("work");
    std::fs::create_dir(&cwd).unwrap();
    ok(&run_in(&cwd, &["render", "--size", "16", "--out", "r"]));
    // Even a directory of rmapgen's own output, once it is where the user stands.
    let inside = cwd.join("r");
    let parent = t.path().to_str().unwrap().to_string();
    for (dir, out_arg) in [
        (&cwd, cwd.to_str().unwrap().to_string()),
        (&cwd, parent.clone()),
        (&inside, inside.to_str().unwrap().to_string()),
        (&inside, "../r".to_string()),
    ] {
        let before = tree(t.path());
        for force in [false, true] {
            let mut a = vec!["render", "--size", "16", "--out", out_arg.as_str()];
            if force {
                a.push("--force");
            }
            let out = run_in(dir, &a);
            assert_error(&out, "it is the current directory or holds it");
            assert_eq!(tree(t.path()), before, "{a:?} in {}", dir.display());
        }
    }
    for dot in [".", ".."] {
        assert_error(
            &run_in(&inside, &["render", "--out", dot]),
            "has no directory name",
        );
    }
}

#[test]
fn a_symlinked_out_is_refused() {
    let t = tempdir();
    let real = t.path().join("real");
    let before = notes(&real);
    std::os::unix::fs::symlink(&real, t.path().join("link")).unwrap();
    let out = run_in(
        t.path(),
        &["render", "--size", "16", "--out", "link", "--force"],
    );
    assert_error(&out, "is a symbolic link");
    assert_eq!(tree(&real), before);
}

#[test]
fn single_output_files_replace_only_their_own_kind() {
    let t = tempdir();
    std::fs::write(t.path().join("notes.txt"), "my notes\n").unwrap();
    let out = run_in(
        t.path(),
        &["vectors", "--count", "10", "--out", "notes.txt"],
    );
    assert_error(
        &out,
        "will not replace notes.txt: it exists and was not written by rmapgen",
    );
    let out = run_in(
        t.path(),
        &["stress", "--samples", "1000", "--json", "notes.txt"],
    );
    assert_error(&out, "will not replace notes.txt");
    assert!(
        String::from_utf8_lossy(&out.stdout).is_empty(),
        "refused before the run"
    );
    assert_eq!(
        std::fs::read(t.path().join("notes.txt")).unwrap(),
        b"my notes\n"
    );
    // A vector file or report rmapgen wrote is replaced.
    ok(&run_in(
        t.path(),
        &["vectors", "--count", "10", "--out", "v.hex"],
    ));
    ok(&run_in(
        t.path(),
        &["vectors", "--count", "20", "--out", "v.hex"],
    ));
    ok(&run_in(
        t.path(),
        &["stress", "--samples", "1000", "--json", "s.json"],
    ));
    ok(&run_in(
        t.path(),
        &["stress", "--samples", "1000", "--json", "s.json"],
    ));
    // An input is never the output, forced or not.
    std::fs::copy(
        helpers::root().join("scenes/standard.toml"),
        t.path().join("s.toml"),
    )
    .unwrap();
    let out = run_in(
        t.path(),
        &[
            "vectors", "--count", "10", "--scene", "s.toml", "--out", "s.toml", "--force",
        ],
    );
    assert_error(
        &out,
        "will not replace s.toml: it is an input of this command",
    );
    // A directory given as the file names the right problem and leaves nothing.
    std::fs::create_dir(t.path().join("some_dir")).unwrap();
    for p in ["some_dir", "some_dir/", "missing_dir/"] {
        let out = run_in(t.path(), &["vectors", "--count", "10", "--out", p]);
        assert_error(&out, "is a directory; give the name of a file to write");
    }
    only(
        t.path(),
        &[
            ".s.json.rmapgen-sha256",
            ".v.hex.rmapgen-sha256",
            "notes.txt",
            "s.json",
            "s.toml",
            "some_dir",
            "v.hex",
        ],
    );
    assert!(!helpers::nonempty(&t.path().join("some_dir")));
}

#[test]
fn roms_update_refreshes_hex_files_and_keeps_the_rest() {
    let t = tempdir();
    ok(&run_in(t.path(), &["generate", "--out", "g"]));
    let before = tree(&t.path().join("g"));
    // A hex file out of date (as after a change to the ROM maths) is rewritten.
    std::fs::write(t.path().join("g/extra.txt"), "x\n").unwrap();
    assert_error(
        &run_in(t.path(), &["roms", "--update", "g"]),
        "it holds extra.txt, which rmapgen did not write",
    );
    std::fs::remove_file(t.path().join("g/extra.txt")).unwrap();
    ok(&run_in(t.path(), &["roms", "--update", "g"]));
    assert_eq!(
        first_difference(&t.path().join("g"), &t.path().join("g")),
        None
    );
    assert_eq!(tree(&t.path().join("g")), before);
    std::fs::create_dir(t.path().join("plain")).unwrap();
    std::fs::write(t.path().join("plain/a.hex"), "00\n").unwrap();
    assert_error(
        &run_in(t.path(), &["roms", "--update", "plain"]),
        "not a directory rmapgen generated",
    );
}

#[test]
fn leftovers_of_killed_runs_are_cleaned_but_nothing_else() {
    let t = tempdir();
    // A staging directory of a process that no longer exists, with rmapgen's mark…
    let stale = t.path().join(".r.staging-4000000");
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(stale.join(".rmapgen-staging"), "").unwrap();
    std::fs::write(stale.join("model.png"), "x").unwrap();
    // …and a look-alike without it, which is not rmapgen's to remove.
    let lookalike = t.path().join(".r.staging-4000001");
    std::fs::create_dir(&lookalike).unwrap();
    std::fs::write(lookalike.join("mine.txt"), "x").unwrap();
    ok(&run_in(t.path(), &["render", "--size", "16", "--out", "r"]));
    assert!(!stale.exists(), "stale staging removed");
    assert!(
        lookalike.join("mine.txt").is_file(),
        "unmarked look-alike kept"
    );
}

/// Starts rmapgen, waits until `ready` holds (it has started writing), sends `signal` and
/// returns how the process ended.
fn interrupt(
    dir: &Path,
    args: &[&str],
    signal: &str,
    ready: impl Fn() -> bool,
) -> std::process::ExitStatus {
    let mut child = helpers::rmapgen()
        .current_dir(dir)
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .expect("rmapgen starts");
    let t0 = Instant::now();
    while !ready() {
        assert!(
            child.try_wait().unwrap().is_none(),
            "{args:?} ended before it could be interrupted"
        );
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "{args:?} never started writing"
        );
        std::thread::sleep(Duration::from_millis(5));
    }
    let status = Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(status.success());
    child.wait().unwrap()
}

fn staged(dir: &Path, prefix: &str) -> bool {
    std::fs::read_dir(dir).is_ok_and(|d| {
        d.flatten()
            .any(|e| e.file_name().to_string_lossy().starts_with(prefix))
    })
}

#[test]
fn an_interrupted_vectors_run_leaves_nothing_and_keeps_the_old_file() {
    let t = tempdir();
    ok(&run_in(
        t.path(),
        &["vectors", "--count", "100", "--out", "v.hex"],
    ));
    let old = std::fs::read(t.path().join("v.hex")).unwrap();
    // The file grows inside its staging directory, `.v.hex.partial-PID/v.hex`.
    let partial_grew = || {
        std::fs::read_dir(t.path()).unwrap().flatten().any(|e| {
            e.file_name()
                .to_string_lossy()
                .starts_with(".v.hex.partial-")
                && std::fs::metadata(e.path().join("v.hex")).is_ok_and(|m| m.len() > 1 << 20)
        })
    };
    let st = interrupt(
        t.path(),
        &["vectors", "--count", "500000000", "--out", "v.hex"],
        "-INT",
        partial_grew,
    );
    assert_eq!(st.signal(), Some(2), "ended by SIGINT: {st:?}");
    only(t.path(), &[".v.hex.rmapgen-sha256", "v.hex"]);
    assert_eq!(std::fs::read(t.path().join("v.hex")).unwrap(), old);
    // Parent directories it made for the output go too.
    let sub = t.path().join("new/sub");
    let st = interrupt(
        t.path(),
        &["vectors", "--count", "500000000", "--out", "new/sub/v.hex"],
        "-TERM",
        || staged(&sub, ".v.hex.partial-"),
    );
    assert_eq!(st.signal(), Some(15), "ended by SIGTERM: {st:?}");
    only(t.path(), &[".v.hex.rmapgen-sha256", "v.hex"]);
    // SIGKILL, which rmapgen cannot catch: its guardian removes the partial file and the
    // parents the run made, within a few seconds, with no later run needed.
    let st = interrupt(
        t.path(),
        &["vectors", "--count", "500000000", "--out", "new/sub/v.hex"],
        "-KILL",
        || staged(&sub, ".v.hex.partial-"),
    );
    assert_eq!(st.signal(), Some(9), "ended by SIGKILL: {st:?}");
    let t0 = Instant::now();
    while t.path().join("new").exists() && t0.elapsed() < Duration::from_secs(5) {
        std::thread::sleep(Duration::from_millis(20));
    }
    only(t.path(), &[".v.hex.rmapgen-sha256", "v.hex"]);
    assert_eq!(std::fs::read(t.path().join("v.hex")).unwrap(), old);
}

#[test]
fn an_interrupted_generate_leaves_nothing_and_keeps_the_old_design() {
    let t = tempdir();
    ok(&run_in(t.path(), &["generate", "--out", "g"]));
    let old = tree(&t.path().join("g"));
    for signal in ["-TERM", "-INT", "-HUP"] {
        let st = interrupt(
            t.path(),
            &["generate", "--vectors", "400000", "--out", "g"],
            signal,
            || staged(t.path(), ".g.staging-"),
        );
        assert!(
            st.signal().is_some(),
            "{signal}: ended by the signal: {st:?}"
        );
        only(t.path(), &["g"]);
        assert_eq!(
            tree(&t.path().join("g")),
            old,
            "{signal}: the previous design is intact"
        );
    }
}

/// A target at the file system's name limit (issue 32 §5): `generate --out` a 250-byte name
/// and `maps --out` a 254-byte one work, twice (the second replaces the first, moving it
/// aside beside it), leaving nothing else; the hidden names beside them stay within NAME_MAX
/// (they were `.NAME.staging-PID`, `File name too long`), and a killed run's leftovers under
/// the shortened names are still recognised and removed.
#[test]
fn outputs_at_the_name_limit() {
    let rtl = helpers::default_design();
    let t = tempdir();
    let dir_name = "d".repeat(250);
    let file_name = "m".repeat(254);
    // Leftovers of a killed run (pid 4000000 is above Linux's pid_max): a marked staging
    // directory, a moved-aside old output and a partial file.
    let staging = rmapgen::output::hidden_prefix(&dir_name, "staging");
    let stale = t.path().join(format!("{staging}4000000"));
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(stale.join(".rmapgen-staging"), "").unwrap();
    let stale_old = t.path().join(format!("{staging}4000000.old"));
    std::fs::create_dir(&stale_old).unwrap();
    std::fs::write(stale_old.join(".rmapgen-staging"), "").unwrap();
    let partial = rmapgen::output::hidden_prefix(&file_name, "partial");
    let stale_partial = t.path().join(format!("{partial}4000000"));
    std::fs::create_dir(&stale_partial).unwrap();
    std::fs::write(stale_partial.join(".rmapgen-staging"), "").unwrap();
    // The single file's record beside it, its name within the limit too.
    let record = rmapgen::output::stamp::record_path(&t.path().join(&file_name)).unwrap();
    let record = record.file_name().unwrap().to_string_lossy().into_owned();
    assert!(record.len() <= 255, "{record}");
    for _ in 0..2 {
        ok(&run_in(
            t.path(),
            &["generate", "--vectors", "10", "--out", &dir_name],
        ));
        ok(&run_in(t.path(), &["maps", &rtl, "--out", &file_name]));
        only(t.path(), &[&dir_name, &file_name, &record]);
    }
    assert!(helpers::nonempty(&t.path().join(&dir_name)));
}

/// Issue 32 §4: a single output file is replaced only if rmapgen wrote it and nobody changed
/// it since (its record `.NAME.rmapgen-sha256`), as a directory is by `.rmapgen-files`.
#[test]
fn maps_keeps_a_users_bin_stream_and_an_edited_hex_file() {
    let rtl = helpers::default_design();
    let t = tempdir();
    let d = t.path();
    // A user's own binary stream: the very bytes rmapgen writes, but not written there by it.
    ok(&run_in(
        d,
        &["maps", &rtl, "--format", "bin", "--out", "ours.bin"],
    ));
    let stream = std::fs::read(d.join("ours.bin")).unwrap();
    let mut mine = stream.clone();
    mine[4] ^= 1;
    std::fs::write(d.join("f.bin"), &mine).unwrap();
    let o = run_in(d, &["maps", &rtl, "--format", "bin", "--out", "f.bin"]);
    assert_error(
        &o,
        "will not replace f.bin: it exists and was not written by rmapgen",
    );
    assert_error(&o, "--force");
    assert_eq!(std::fs::read(d.join("f.bin")).unwrap(), mine);
    // rmapgen's own, unchanged: replaced without --force (in any format).
    ok(&run_in(
        d,
        &["maps", &rtl, "--format", "bin", "--out", "ours.bin"],
    ));
    ok(&run_in(
        d,
        &["maps", &rtl, "--format", "hex", "--out", "ours.bin"],
    ));
    // An rmapgen hex file the user edited is kept.
    ok(&run_in(d, &["maps", &rtl, "--out", "f.hex"]));
    let mut edited = std::fs::read_to_string(d.join("f.hex")).unwrap();
    edited.push_str("// my note\n");
    std::fs::write(d.join("f.hex"), &edited).unwrap();
    let o = run_in(d, &["maps", &rtl, "--out", "f.hex"]);
    assert_error(
        &o,
        "will not replace f.hex: it was changed since rmapgen wrote it; nothing was changed \
         (choose another name, or use --force to replace it)",
    );
    assert_eq!(std::fs::read_to_string(d.join("f.hex")).unwrap(), edited);
    // With --force both are replaced, and recorded as rmapgen's.
    ok(&run_in(d, &["maps", &rtl, "--out", "f.hex", "--force"]));
    ok(&run_in(
        d,
        &["maps", &rtl, "--format", "bin", "--out", "f.bin", "--force"],
    ));
    assert_eq!(std::fs::read(d.join("f.bin")).unwrap(), stream);
    ok(&run_in(
        d,
        &["maps", &rtl, "--format", "bin", "--out", "f.bin"],
    ));
    // The record is sha256sum's format: `sha256sum -c` checks the file.
    let check = Command::new("sha256sum")
        .args(["-c", ".f.bin.rmapgen-sha256"])
        .current_dir(d)
        .output()
        .unwrap();
    assert!(check.status.success(), "{check:?}");
    only(
        d,
        &[
            ".f.bin.rmapgen-sha256",
            ".f.hex.rmapgen-sha256",
            ".ours.bin.rmapgen-sha256",
            "f.bin",
            "f.hex",
            "ours.bin",
        ],
    );
}

/// Every command that writes a single file keeps the rule: an edited output, or a file that
/// merely looks like one (a report with rmapgen's format name), is refused without --force;
/// the refusal names the file and --force, exits 2, and writes nothing.
#[test]
fn every_single_file_output_keeps_an_edited_or_foreign_file() {
    let t = tempdir();
    let d = t.path();
    crate::hdl::generate_config(&d.join("g"), &rmapgen::grid::narrowest(), 5);
    // Written by rmapgen, then edited.
    for args in [
        vec!["vectors", "--count", "10", "--out", "v.hex"],
        vec!["stress", "--samples", "1000", "--json", "s.json"],
    ] {
        ok(&run_in(d, &args));
        ok(&run_in(d, &args)); // unchanged: replaced
        let out = args[args.len() - 1];
        let mut text = std::fs::read(d.join(out)).unwrap();
        text.push(b'\n');
        std::fs::write(d.join(out), &text).unwrap();
        let o = run_in(d, &args);
        assert_error(
            &o,
            &format!("will not replace {out}: it was changed since rmapgen wrote it"),
        );
        assert_eq!(std::fs::read(d.join(out)).unwrap(), text);
        let mut forced = args.clone();
        forced.push("--force");
        ok(&run_in(d, &forced));
    }
    // Reports that look like rmapgen's but that it did not write there.
    std::fs::write(d.join("p.json"), "{\"format\": \"rmapgen-prove-2\"}\n").unwrap();
    std::fs::write(d.join("m.json"), "{\"format\": \"rmapgen-mutants-1\"}\n").unwrap();
    for (args, out) in [
        (
            vec!["prove", "--report", "p.json", "--build", "B", "g"],
            "p.json",
        ),
        (
            vec!["mutants", "--report", "m.json", "--build", "B", "g"],
            "m.json",
        ),
    ] {
        let before = helpers::entries(d);
        let o = run_in(d, &args);
        assert_error(
            &o,
            &format!("will not replace {out}: it exists and was not written by rmapgen"),
        );
        assert_error(&o, "use --force to replace it");
        assert_eq!(helpers::entries(d), before, "{args:?} wrote nothing");
    }
}

/// Issue 32 §4: a leftover is removed only if it carries rmapgen's mark: a user's file named
/// like a partial file of a dead process is kept; a marked staging directory of one goes.
#[test]
fn a_users_file_named_like_a_partial_file_is_kept() {
    let t = tempdir();
    let d = t.path();
    std::fs::write(d.join(".v.hex.partial-999999"), "mine\n").unwrap();
    std::fs::create_dir(d.join(".v.hex.partial-4000000")).unwrap();
    std::fs::write(d.join(".v.hex.partial-4000000/notes"), "mine too\n").unwrap();
    let stale = d.join(".v.hex.partial-4000001");
    std::fs::create_dir(&stale).unwrap();
    std::fs::write(stale.join(".rmapgen-staging"), "").unwrap();
    std::fs::write(stale.join("v.hex"), "0 1\n").unwrap();
    ok(&run_in(d, &["vectors", "--count", "10", "--out", "v.hex"]));
    assert_eq!(
        std::fs::read_to_string(d.join(".v.hex.partial-999999")).unwrap(),
        "mine\n"
    );
    assert!(d.join(".v.hex.partial-4000000/notes").is_file());
    assert!(!stale.exists(), "rmapgen's marked leftover is removed");
    only(
        d,
        &[
            ".v.hex.partial-4000000",
            ".v.hex.partial-999999",
            ".v.hex.rmapgen-sha256",
            "v.hex",
        ],
    );
}

/// The record's rename can only replace rmapgen's own record: a user's file that has the
/// record's name (`.f.bin.rmapgen-sha256`), with or without `f.bin` beside it, is never
/// overwritten without --force, and the refused run writes nothing.
#[test]
fn a_users_file_at_the_records_name_is_kept() {
    let rtl = helpers::default_design();
    let t = tempdir();
    let d = t.path();
    let mine = "my notes, not a record\n";
    std::fs::write(d.join(".f.bin.rmapgen-sha256"), mine).unwrap();
    let o = run_in(d, &["maps", &rtl, "--format", "bin", "--out", "f.bin"]);
    assert_error(&o, "it is not rmapgen's record of f.bin");
    only(d, &[".f.bin.rmapgen-sha256"]);
    // With a file of the user's at the target too.
    std::fs::write(d.join("f.bin"), "theirs").unwrap();
    let o = run_in(d, &["maps", &rtl, "--format", "bin", "--out", "f.bin"]);
    assert_error(&o, "will not replace f.bin");
    only(d, &[".f.bin.rmapgen-sha256", "f.bin"]);
    assert_eq!(
        std::fs::read_to_string(d.join(".f.bin.rmapgen-sha256")).unwrap(),
        mine
    );
    assert_eq!(std::fs::read_to_string(d.join("f.bin")).unwrap(), "theirs");
}
