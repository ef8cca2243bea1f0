use clap::{Parser, Subcommand};
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

#[derive(Subcommand, Debug)]
enum Command {
    /// Write the ROM and map contents as $readmemh hex files.
    Roms(cmd::roms::RomsArgs),
}

fn run(cli: Cli) -> anyhow::Result<()> {
    match cli.command {
        Command::Roms(a) => cmd::roms::run(&a),
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            // One line, the whole cause chain.
            eprintln!("rmapgen: error: {e:#}");
            ExitCode::from(2)
        }
    }
}
