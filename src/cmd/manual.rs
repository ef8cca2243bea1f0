//! `rmapgen man` and `rmapgen completions`: the manual pages and the shell completions, made
//! from the same clap definitions that parse the command line (so they cannot disagree with
//! `--help`). `make man` writes both into build/man, `make install` installs them.

use crate::output::{Policy, StagedDir};
use anyhow::{Context, Result};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct ManArgs {
    /// Where to write `rmapgen.1` and one page per command (`rmapgen-generate.1`, ...).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
}

#[derive(Args, Debug)]
pub struct CompletionsArgs {
    /// The shell the script is for.
    #[arg(value_enum)]
    pub shell: clap_complete::Shell,
}

/// Writes the manual pages of `cmd` (the whole command line) into `a.out`: staged, so a
/// directory holding anything rmapgen did not write there is refused, and nothing is left
/// half-written.
pub fn man(cmd: clap::Command, a: &ManArgs) -> Result<()> {
    let policy: Policy = a.force.policy(&[]);
    let staged = StagedDir::new(&a.out, &policy)?;
    let n = pages(cmd, staged.path())?;
    let out = staged.commit()?;
    crate::errln!("rmapgen: wrote {n} manual pages to {}", out.display());
    Ok(())
}

/// The pages of `cmd` and of each of its subcommands into `dir`; how many.
fn pages(cmd: clap::Command, dir: &Path) -> Result<usize> {
    let cmd = cmd.name("rmapgen");
    let mut n = 0;
    let mut write = |name: &str, page: clap::Command| -> Result<()> {
        let mut text = Vec::new();
        clap_mangen::Man::new(page)
            .render(&mut text)
            .with_context(|| format!("cannot render the page of {name}"))?;
        crate::disk::write(&dir.join(format!("{name}.1")), text)?;
        n += 1;
        Ok(())
    };
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        let name = format!("rmapgen-{}", sub.get_name());
        write(&name, sub.clone().name(name.clone()))?;
    }
    write("rmapgen", cmd)?;
    Ok(n)
}

/// The completion script of `shell` on stdout.
pub fn completions(cmd: clap::Command, a: &CompletionsArgs) -> Result<()> {
    let mut cmd = cmd;
    let mut text = Vec::new();
    clap_complete::generate(a.shell, &mut cmd, "rmapgen", &mut text);
    crate::out!("{}", String::from_utf8_lossy(&text))?;
    Ok(())
}
