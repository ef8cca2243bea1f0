//! One file per subcommand; each owns its clap arguments and its `run`.

pub mod config_args;
pub mod roms;
