//! `rmapgen explore`: the explorer's page on 127.0.0.1 (src/explore).

use anyhow::Result;
use clap::Args;

#[derive(Args, Debug)]
pub struct ExploreArgs {
    /// Port on 127.0.0.1 to serve the page on (0: a free port, printed) [0..=65535].
    #[arg(long, value_name = "N", default_value_t = 8737)]
    pub port: u16,
}

pub fn run(a: &ExploreArgs) -> Result<()> {
    crate::explore::serve(a.port, |url| {
        crate::outln!("explore: {url} (Ctrl-C stops it)")?;
        Ok(())
    })
}
