//! `--force`, shared by every command that writes an output.

use crate::output::Policy;
use clap::Args;
use std::path::Path;

#[derive(Args, Debug, Clone, Default)]
pub struct ForceArg {
    /// Replace the output even if it holds files rmapgen did not write, or changed since.
    /// Never the current directory, one of its ancestors, or a directory holding an input of
    /// the command.
    #[arg(long)]
    pub force: bool,
}

impl ForceArg {
    /// The output policy of a command that reads `inputs` (those given).
    pub fn policy(&self, inputs: &[Option<&Path>]) -> Policy {
        inputs
            .iter()
            .fold(Policy::new(self.force), |p, i| p.input(*i))
    }
}
