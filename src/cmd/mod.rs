//! One file per subcommand; each owns its clap arguments and its `run`.

pub mod bench;
pub mod config_args;
pub mod fit;
pub mod force;
pub mod fpga;
pub mod generate;
pub mod parse;
pub mod render;
pub mod roms;
pub mod stress;
pub mod vectors;
pub mod volume;
