//! `rmapgen fit`: the cheapest configuration whose error on the scene's test image meets a
//! target; prints the decision and writes the chosen design as `generate` does.

use super::map_args::MapArgs;
use super::parse;
use crate::config::Config;
use crate::emit::manifest::VectorsInfo;
use crate::fit::outcome::Outcome;
use crate::fit::target::Target;
use crate::fit::{self, CostKind, Options};
use anyhow::Result;
use clap::Args;
use std::path::PathBuf;

/// Smallest sphere image side `fit` measures on (`--size`): below it too few pixels fall in
/// each map cell for the error to mean much. The largest is [`crate::render::MAX_SIZE`].
pub const MIN_SIZE: u32 = 16;
/// Largest `--runners-up`: each is a passing candidate measured on the whole image, and 100
/// already lists more than anyone reads.
pub const MAX_RUNNERS_UP: usize = 100;
/// Largest `--synth-limit`: each synthesis takes Yosys seconds to a minute.
pub const MAX_SYNTH_LIMIT: usize = 64;

/// The help heading of the searched fields a user may fix.
const FIXED: &str = "Fixed instead of searched";

/// The help of a searched field's fixing flag: `what [min..=max; searched when not given]`,
/// the range from [`crate::config::range_of`].
fn fixed_help(name: &str, what: &str) -> String {
    let (min, max) = crate::config::range_of(name).expect("a configuration field with a range");
    format!("{what} [{min}..={max}; searched when not given]")
}

#[derive(Args, Debug)]
#[command(group(clap::ArgGroup::new("target").required(true).multiple(true).args(["max_error", "rmse"])))]
#[command(mut_arg("scene", |a| a.required(true)
    .help("Scene whose sphere test image the error is measured on (its maps fill the design)")))]
pub struct FitArgs {
    #[command(flatten)]
    pub map: MapArgs,
    /// Largest absolute error allowed on any output, in its LSBs (intensity: map-bits wide;
    /// colour channels: 8 bits).
    #[arg(long, value_name = "E", value_parser = parse::at_least::<u32>(0))]
    pub max_error: Option<u32>,
    /// Largest RMS intensity error allowed, in output LSBs.
    #[arg(long, value_name = "R", value_parser = parse::non_negative())]
    pub rmse: Option<f64>,
    /// What "cheapest" means: ROM + map bits, or cells of Yosys synthesis.
    #[arg(long, value_enum, default_value_t = CostKind::Bits)]
    pub cost: CostKind,
    /// The part the design must fit. Given any of --family, --device and --package, every
    /// passing configuration is synthesised and packed into the part (nextpnr --pack-only)
    /// before it is chosen, and one that needs more logic cells, block RAMs or DSP blocks
    /// than the part has is not (pins are not counted: a core's ports are nets inside the
    /// design it goes into). The family's synthesis also counts --cost cells.
    #[command(flatten)]
    pub part: super::part_args::PartArgs,
    /// Output directory for the chosen design, as `generate` writes it, plus fit.json
    /// (replaced whole on success; nothing is written on failure).
    #[arg(long, value_name = "DIR", default_value = "out/fit")]
    pub out: PathBuf,
    #[command(flatten)]
    pub force: super::force::ForceArg,
    /// Gradient component width of the source (fixed, not searched) [8..=16].
    #[arg(long, value_name = "G", default_value_t = 12, value_parser = parse::field("grad_bits"))]
    pub grad_bits: u32,
    /// Output intensity (map entry) width: the error target's LSB (fixed, not searched)
    /// [6..=12].
    #[arg(long, value_name = "M", default_value_t = 8, value_parser = parse::field("map_bits"))]
    pub map_bits: u32,
    /// Pipeline depth of the generated design (does not change the error) [0..=2, default
    /// as generate: 2].
    #[arg(long, value_name = "N", value_parser = parse::field("pipeline_depth"))]
    pub pipeline_depth: Option<u32>,
    /// Valid/ready handshake on the generated top.
    #[arg(long)]
    pub handshake: bool,
    /// Parallel lanes of the generated design (fixed, not searched; the error is the same
    /// for every lane, and --cost cells counts the cells of all of them) [1..=8, default 1].
    #[arg(long, value_name = "L", value_parser = parse::field("lanes"))]
    pub lanes: Option<u32>,
    #[arg(long, value_name = "P", value_parser = parse::prefix(), help = parse::prefix_help())]
    pub prefix: Option<String>,
    /// Side of the sphere test image [16..=4096].
    #[arg(long, value_name = "N", default_value_t = 512, value_parser = parse::count::<u32>())]
    pub size: u32,
    /// Passing configurations listed after the choice [0..=100].
    #[arg(long, value_name = "K", default_value_t = 3, value_parser = parse::count::<usize>())]
    pub runners_up: usize,
    /// How many passing configurations to synthesise: with --cost cells, shared equally by
    /// the four combinations of compensation and interpolation (the cheapest passing ones in
    /// bits of each); with a part and --cost bits, the cheapest passing ones in bits, until
    /// one fits [1..=64].
    #[arg(long, value_name = "S", default_value_t = 8, value_parser = parse::count::<usize>())]
    pub synth_limit: usize,
    /// Seeded random vectors per stage in the written design (as generate --vectors)
    /// [0..=1000000].
    #[arg(long, value_name = "N", default_value_t = 2000, value_parser = parse::count::<usize>())]
    pub vectors: usize,
    #[arg(long, value_name = "R", value_parser = parse::field("red_bits"), help_heading = FIXED,
        help = fixed_help("red_bits", "Fix the reduced width instead of searching it (with the other flags here: search only what is left free, for example the map around a chosen front end)"))]
    pub red_bits: Option<u32>,
    #[arg(long, value_name = "F", value_parser = parse::field("frac_bits"), help_heading = FIXED,
        help = fixed_help("frac_bits", "Fix the fraction width"))]
    pub frac_bits: Option<u32>,
    #[arg(long, value_name = "W", value_parser = parse::field("recip_bits"), help_heading = FIXED,
        help = fixed_help("recip_bits", "Fix the reciprocal width"))]
    pub recip_bits: Option<u32>,
    #[arg(long, value_name = "I", value_parser = parse::field("index_bits"), help_heading = FIXED,
        help = fixed_help("index_bits", "Fix the index bits (map entries per face: (2^I + 1)^2)"))]
    pub index_bits: Option<u32>,
    #[arg(long, value_name = "P", value_parser = parse::field("interp_bits"), help_heading = FIXED,
        help = fixed_help("interp_bits", "Fix the interpolation fraction bits (0: no interpolator)"))]
    pub interp_bits: Option<u32>,
    /// Fix the distortion compensation on or off.
    #[arg(long, value_name = "on|off", value_parser = ["on", "off"], help_heading = FIXED)]
    pub compensation: Option<String>,
    /// Seed of the random vectors.
    #[arg(long, value_name = "S", default_value_t = 1, value_parser = parse::at_least::<u64>(0))]
    pub seed: u64,
}

pub fn run(a: &FitArgs) -> Result<()> {
    crate::vectors::check_stage_vectors(a.vectors, "--vectors")?;
    let scene = a.map.scene_or(|| anyhow::bail!("fit needs --scene FILE"))?;
    let scene_file = a.map.input().unwrap_or(std::path::Path::new("")).display();
    let base = Config {
        grad_bits: a.grad_bits,
        map_bits: a.map_bits,
        pipeline_depth: a.pipeline_depth.unwrap_or(Config::default().pipeline_depth),
        handshake: a.handshake,
        lanes: a.lanes.unwrap_or(Config::default().lanes),
        color: scene.color.is_some(),
        prefix: a.prefix.clone().unwrap_or_default(),
        // A fitted table is loaded with the maps: every candidate holds it in RAM.
        comp_table: if scene.map_fit == crate::model::map_fit::MapFit::Table {
            crate::config::CompTable::Ram
        } else {
            crate::config::CompTable::Rom
        },
        ..Config::default()
    };
    base.validate()?;
    // The part is checked (nextpnr knows the device and package) before the search.
    let part = a.part.options()?;
    if a.part.given() {
        crate::flow::fpga::check(None, &part)?;
    }
    let max_size = crate::render::MAX_SIZE;
    anyhow::ensure!(
        (MIN_SIZE..=max_size).contains(&a.size),
        "size {} is out of range; allowed {MIN_SIZE}..={max_size}",
        a.size
    );
    anyhow::ensure!(
        (1..=MAX_SYNTH_LIMIT).contains(&a.synth_limit),
        "synth-limit {} is out of range; allowed 1..={MAX_SYNTH_LIMIT}",
        a.synth_limit
    );
    anyhow::ensure!(
        a.runners_up <= MAX_RUNNERS_UP,
        "runners-up {} is out of range; allowed 0..={MAX_RUNNERS_UP}",
        a.runners_up
    );
    let opts = Options {
        base,
        size: a.size,
        target: Target {
            max_error: a.max_error,
            rmse: a.rmse,
        },
        cost: a.cost,
        part,
        check_part: a.part.given(),
        runners_up: a.runners_up,
        synth_limit: a.synth_limit,
        map_fit: scene.map_fit,
        fixed: fit::space::Fixed {
            red_bits: a.red_bits,
            frac_bits: a.frac_bits,
            recip_bits: a.recip_bits,
            index_bits: a.index_bits,
            interp_bits: a.interp_bits,
            compensation: a.compensation.as_deref().map(|c| c == "on"),
        },
    };
    // A progress bar, shown on a terminal once the search has run for a second.
    let bar = super::progress::Progress::tasks("fit", 1);
    let outcome = fit::search(&scene, &opts, &|done, total, msg| {
        bar.task(done as u64, total as u64, msg)
    });
    drop(bar);
    let d = match outcome? {
        Outcome::Found(d) => d,
        Outcome::Unreachable(u) => anyhow::bail!(u.message(&scene_file.to_string())),
    };
    let json = serde_json::to_string_pretty(&d)?;
    let cfg = &d.chosen.config;
    let (p, manifest) = crate::emit::dir::write_dir(
        cfg,
        &scene,
        &a.out,
        &a.force.policy(&[a.map.input()]),
        VectorsInfo {
            random: a.vectors,
            seed: a.seed,
        },
        &[("fit.json".to_string(), json)],
        crate::emit::dir::Keep::Nothing,
    )?;
    crate::outln!(
        "fit: {} ({}), {}x{} sphere ({} pixels), maps {}; target {}; cost {}",
        scene_file,
        d.scene_terms,
        d.image_size,
        d.image_size,
        d.pixels,
        d.map_fit.name(),
        d.target.describe(),
        match d.cost {
            CostKind::Bits => "ROM + map bits".to_string(),
            CostKind::Cells if d.family == Default::default() => "Yosys cells".to_string(),
            CostKind::Cells => format!("Yosys cells ({} synthesis)", d.family.title()),
        }
    )?;
    if !d.fixed.is_empty() {
        crate::outln!(
            "fit: fixed {}; the other fields searched",
            d.fixed.describe()
        )?;
    }
    match d.cost {
        CostKind::Bits => crate::outln!(
            "fit: {} configurations, {} measured in {:.1} s; every one cheaper than the choice ({}) measured and rejected",
            d.space, d.measured, d.seconds, d.cheaper_rejected
        )?,
        CostKind::Cells => crate::outln!(
            "fit: {} configurations, {} measured in {:.1} s; the {} cheaper in bits than the cheapest passing one measured and rejected; cells of the {} synthesised (per combination of compensation and interpolation, its cheapest passing configurations in bits)",
            d.space,
            d.measured,
            d.seconds,
            d.cheaper_rejected,
            d.synthesised
        )?,
    }
    if let Some(p) = &d.part {
        crate::outln!(
            "fit: the {} {} ({}): {} passing configurations synthesised and packed, {} do not fit{}",
            p.family.title(),
            p.device,
            p.package,
            d.synthesised,
            p.too_big,
            p.first_too_big
                .as_ref()
                .map_or(String::new(), |c| format!(
                    "; the first, {}: {}",
                    c.summary,
                    c.shortage.as_deref().unwrap_or_default()
                ))
        )?;
    }
    crate::out!("{}", d.table())?;
    let modules: Vec<&str> = manifest.modules.iter().map(|m| m.name.as_str()).collect();
    crate::outln!(
        "fit: wrote {} ({} memory bits; modules {}) to {}",
        cfg.summary(),
        manifest.memory_bits,
        modules.join(" "),
        p.display()
    )?;
    Ok(())
}
