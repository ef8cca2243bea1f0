//! One file per subcommand; each owns its clap arguments and its `run`.

pub mod bench;
pub mod compare;
pub mod config_args;
pub mod explore;
pub mod fit;
pub mod force;
pub mod fpga;
pub mod generate;
pub mod lint;
pub mod manual;
pub mod map_args;
pub mod maps;
pub mod mutants;
pub mod parse;
pub mod part_args;
pub mod progress;
pub mod prove;
pub mod prove_mult;
pub mod render;
pub mod roms;
pub mod sim;
pub mod stress;
pub mod synth;
pub mod vectors;
pub mod volume;

/// The bounds quoted in the clap help (doc comments cannot interpolate a constant) match the
/// constants that enforce them.
#[cfg(test)]
mod limits_in_help {
    use clap::Args;

    fn help<A: Args>(flag: &str) -> String {
        let cmd = A::augment_args(clap::Command::new("t"));
        let arg = cmd
            .get_arguments()
            .find(|a| a.get_long() == Some(flag))
            .unwrap_or_else(|| panic!("no --{flag}"));
        format!(
            "{} {}",
            arg.get_help().map(|h| h.to_string()).unwrap_or_default(),
            arg.get_long_help()
                .map(|h| h.to_string())
                .unwrap_or_default()
        )
    }

    fn has<A: Args>(flag: &str, want: &str) {
        let h = help::<A>(flag);
        assert!(
            h.contains(want),
            "--{flag} help {h:?} should quote {want:?}"
        );
    }

    #[test]
    fn help_quotes_the_constants() {
        use crate::render::MAX_SIZE;
        use crate::vectors::{MAX_STAGE_VECTORS, MAX_STREAM_VECTORS};
        use crate::volume::cast::options::{MAX_BRICK, MAX_STEP, MIN_STEP};
        has::<super::generate::GenerateArgs>("vectors", &format!("[0..={MAX_STAGE_VECTORS}]"));
        has::<super::fit::FitArgs>("vectors", &format!("[0..={MAX_STAGE_VECTORS}]"));
        has::<super::fit::FitArgs>("size", &format!("[{}..={MAX_SIZE}]", super::fit::MIN_SIZE));
        has::<super::fit::FitArgs>(
            "runners-up",
            &format!("[0..={}]", super::fit::MAX_RUNNERS_UP),
        );
        has::<super::fit::FitArgs>(
            "synth-limit",
            &format!("[1..={}]", super::fit::MAX_SYNTH_LIMIT),
        );
        has::<super::vectors::VectorsArgs>("count", &format!("[0..={MAX_STREAM_VECTORS};"));
        has::<super::stress::StressArgs>(
            "samples",
            &format!("[1..={}, 2^37]", crate::stress::MAX_SAMPLES),
        );
        assert_eq!(crate::stress::MAX_SAMPLES, 1 << 37);
        has::<super::render::RenderArgs>("size", &format!("[1..={MAX_SIZE}]"));
        has::<super::volume::VolumeArgs>("size", &format!("[1..={MAX_SIZE}]"));
        has::<super::volume::VolumeArgs>("step", &format!("[{MIN_STEP}..={MAX_STEP}]"));
        has::<super::volume::VolumeArgs>("brick", &format!("2..={MAX_BRICK}]"));
        has::<super::volume::VolumeArgs>("repeat", &format!("[1..={}]", super::volume::MAX_REPEAT));
        has::<super::bench::BenchArgs>(
            "size",
            &format!("[{}..={MAX_SIZE}]", super::bench::MIN_SIZE),
        );
        has::<super::fpga::FpgaArgs>("freq", &format!("(0, {}]", super::fpga::MAX_FREQ_MHZ));
        has::<super::bench::BenchArgs>("seconds", &format!("(0, {}]", super::bench::MAX_SECONDS));
        has::<super::sim::SimArgs>("stream", &format!("[0..={MAX_STREAM_VECTORS};"));
        has::<super::sim::SimArgs>("tb-stream", &format!("[0..={MAX_STREAM_VECTORS}]"));
    }

    #[test]
    fn doc_figures_match() {
        // Figures quoted in doc comments and docs/USAGE.md.
        assert_eq!(crate::volume::MAX_VOXELS, 214_748_364);
        assert_eq!(crate::volume::MEMORY_BUDGET, 2 << 30);
        assert_eq!(crate::volume::load::MAX_READ_BYTES, 4 << 30);
        assert_eq!(crate::volume::load::MAX_HEADER_BYTES, 1 << 20);
        assert_eq!(crate::vectors::MAX_STAGE_VECTORS, 1_000_000);
        assert_eq!(crate::vectors::MAX_STREAM_VECTORS, 10_000_000_000);
        // compare's help (src/main.rs): "at most 1 GiB each, 16384 pixels a side".
        assert_eq!(crate::cmd::compare::MAX_ALLOC, 1 << 30);
        assert_eq!(crate::cmd::compare::MAX_SIDE, 16384);
    }
}
