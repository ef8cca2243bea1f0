//! The configuration flags shared by every command that builds a design: a TOML file, then
//! flags that override single fields. The result is validated once, here.

use super::parse;
use crate::config::Config;
use crate::toml_input;
use anyhow::Result;
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args, Debug, Clone, Default)]
pub struct ConfigArgs {
    /// Configuration TOML (fields as in `Config`); flags below override it.
    #[arg(long, value_name = "FILE")]
    pub config: Option<PathBuf>,
    #[arg(long, value_parser = parse::field("grad_bits"), help = parse::field_help("grad_bits", "Gradient component width, two's complement", ""))]
    pub grad_bits: Option<u32>,
    #[arg(long, value_parser = parse::field("red_bits"), help = parse::field_help("red_bits", "Magnitude width after sort & shift", ", <= grad-bits"))]
    pub red_bits: Option<u32>,
    #[arg(long, value_parser = parse::field("recip_bits"), help = parse::field_help("recip_bits", "Reciprocal ROM entry width", ", >= frac-bits + 1"))]
    pub recip_bits: Option<u32>,
    #[arg(long, value_parser = parse::field("frac_bits"), help = parse::field_help("frac_bits", "Normalised fraction width; 2^frac-bits compensation ROM entries", ""))]
    pub frac_bits: Option<u32>,
    #[arg(long, value_parser = parse::field("index_bits"), help = parse::field_help("index_bits", "Map index bits per component", ""))]
    pub index_bits: Option<u32>,
    #[arg(long, value_parser = parse::field("interp_bits"), help = parse::field_help("interp_bits", "Interpolation fraction bits", ", 0 iff interpolation is off"))]
    pub interp_bits: Option<u32>,
    #[arg(long, value_parser = parse::field("map_bits"), help = parse::field_help("map_bits", "Map entry and output intensity width", ""))]
    pub map_bits: Option<u32>,
    /// Leave out distortion compensation (no atan ROM; linear index).
    #[arg(long)]
    pub no_compensation: bool,
    /// Leave out the interpolator (nearest entry; implies --interp-bits 0).
    #[arg(long)]
    pub no_interpolation: bool,
    /// Add the 8-bit RGB colour multiplier.
    #[arg(long)]
    pub color: bool,
    #[arg(long, value_name = "N", value_parser = parse::field("pipeline_depth"), help = parse::field_help("pipeline_depth", "Pipeline registers: 0 compact (lowest latency), 1 and 2 add registers for clock rate", ""))]
    pub pipeline_depth: Option<u32>,
    /// Valid/ready handshake on the top (backpressure stalls the pipeline) instead of a
    /// plain valid stream.
    #[arg(long)]
    pub handshake: bool,
    #[arg(long, value_name = "P", value_parser = parse::prefix(), help = parse::prefix_help())]
    pub prefix: Option<String>,
    /// Memories for these tools: generic (plain inferred memories, no vendor attributes),
    /// ice40 (Yosys block-RAM attributes, one compensation ROM copy per read port), ecp5 or
    /// gowin (Yosys block-RAM attributes, true dual-port ROMs: two lanes share a reciprocal
    /// ROM) [default: generic].
    #[arg(long, value_enum, value_name = "T")]
    pub target: Option<crate::config::Target>,
    /// AXI4-Stream ports (s_axis_*, m_axis_*; byte-aligned tdata, tlast passed through with
    /// each sample): the top becomes rmap_axis around the handshake top. Needs --handshake.
    #[arg(long)]
    pub axis: bool,
    #[arg(long, value_name = "BITS", value_parser = parse::field("axis_user"), help = parse::field_help("axis_user", "tuser width passed through with each sample (0: no tuser)", ", needs --axis"))]
    pub axis_user: Option<u32>,
    #[arg(long, value_name = "L", value_parser = parse::field("lanes"), help = parse::field_help("lanes", "Parallel lanes: L samples in and L results out per clock (the top becomes rmap_lanes, one rmap_top per lane)", ""))]
    pub lanes: Option<u32>,
    /// Multipliers: tree (adder trees of partial products, for devices without multipliers)
    /// or infer (plain `*` products registered so DSP blocks absorb them) [default: tree].
    #[arg(long, value_enum, value_name = "M")]
    pub mult: Option<crate::config::Mult>,
    /// Compensation table: rom (the atan table, fixed) or ram (loaded by the host with the
    /// maps through the write port, double-buffered, so it can be fitted to each frame's
    /// scene) [default: rom].
    #[arg(long, value_enum, value_name = "T")]
    pub comp_table: Option<crate::config::CompTable>,
    /// A CPU bus slave on top (rmap_bus: the register block rmap_regs on the bus, which
    /// writes the maps and swaps them; docs/SOC.md): none, wishbone (B4 classic, LiteX's) or
    /// axi4-lite [default: none].
    #[arg(long, value_enum, value_name = "B")]
    pub bus: Option<crate::config::Bus>,
}

impl ConfigArgs {
    /// The flags that give `cfg` (those that differ from the default; `--interp-bits 0` is
    /// implied by `--no-interpolation`), for `generate` and the other commands that take them.
    pub fn flags(cfg: &Config) -> Vec<String> {
        let d = Config::default();
        let mut f = Vec::new();
        for (name, v) in [
            ("grad_bits", cfg.grad_bits),
            ("red_bits", cfg.red_bits),
            ("recip_bits", cfg.recip_bits),
            ("frac_bits", cfg.frac_bits),
            ("index_bits", cfg.index_bits),
            ("interp_bits", cfg.interp_bits),
            ("map_bits", cfg.map_bits),
        ] {
            let implied = name == "interp_bits" && !cfg.interpolation && v == 0;
            if v != d.field(name) && !implied {
                f.extend([format!("--{}", name.replace('_', "-")), v.to_string()]);
            }
        }
        if cfg.pipeline_depth != d.pipeline_depth {
            f.extend(["--pipeline-depth".into(), cfg.pipeline_depth.to_string()]);
        }
        if cfg.axis_user != d.axis_user {
            f.extend(["--axis-user".into(), cfg.axis_user.to_string()]);
        }
        if cfg.lanes != d.lanes {
            f.extend(["--lanes".into(), cfg.lanes.to_string()]);
        }
        for (on, flag) in [
            (!cfg.compensation, "--no-compensation"),
            (!cfg.interpolation, "--no-interpolation"),
            (cfg.color, "--color"),
            (cfg.handshake, "--handshake"),
            (cfg.axis, "--axis"),
        ] {
            if on {
                f.push(flag.into());
            }
        }
        if !cfg.prefix.is_empty() {
            f.extend(["--prefix".into(), cfg.prefix.clone()]);
        }
        if !cfg.target.is_generic() {
            f.extend(["--target".into(), cfg.target.name().into()]);
        }
        if !cfg.mult.is_tree() {
            f.extend(["--mult".into(), cfg.mult.name().into()]);
        }
        if !cfg.comp_table.is_rom() {
            f.extend(["--comp-table".into(), cfg.comp_table.name().into()]);
        }
        if !cfg.bus.is_none() {
            f.extend(["--bus".into(), cfg.bus.name().into()]);
        }
        f
    }

    /// The configuration file with the flags applied, validated once: a file that is invalid
    /// alone but valid with the flags (`interp_bits = 0` and `--no-interpolation`) is
    /// accepted. An error names where each value it is about came from (a flag, the file's
    /// line and column, or the default).
    pub fn resolve(&self) -> Result<Config> {
        let file = self.file()?;
        let base = file.as_ref().map_or_else(Config::default, |f| f.0.clone());
        let (c, flags) = self.apply(base);
        let Err(e) = c.validate() else {
            return Ok(c);
        };
        let fields = e.fields();
        let flag = |f: &str| flags.iter().find(|x| x.0 == f).map(|x| x.1.clone());
        match &file {
            // Every value involved is the file's: point at the first one in it.
            Some((_, text, what)) if fields.iter().all(|f| flag(f).is_none()) => {
                let key = fields
                    .iter()
                    .find(|f| toml_input::span_of(text, f).is_some())
                    .unwrap_or(&fields[0]);
                Err(toml_input::invalid(
                    text,
                    what,
                    &toml_input::Invalid::new(*key, e.to_string()),
                ))
            }
            _ => {
                let from: Vec<String> = fields
                    .iter()
                    .map(|f| match (flag(f), &file) {
                        (Some(fl), _) => format!("{f} from {fl}"),
                        (None, Some((_, text, what))) => match toml_input::span_of(text, f) {
                            Some(s) => {
                                let (l, col) = toml_input::line_col(text, s.start);
                                format!("{f} from {what}:{l}:{col}")
                            }
                            None => format!("{f} by default"),
                        },
                        (None, None) => format!("{f} by default"),
                    })
                    .collect();
                anyhow::bail!("{e} ({})", from.join(", "))
            }
        }
    }

    /// The configuration of the generated design `dir` (its manifest's, `design`) for a
    /// command given that design: a design is read, never re-described. Configuration flags
    /// (and `--config`) may be given only if they agree with it; a flag or file that
    /// contradicts the manifest is refused in one line naming both.
    pub fn for_design(&self, design: &Config, dir: &Path) -> Result<Config> {
        let file = self.file()?;
        let base = file
            .as_ref()
            .map_or_else(|| design.clone(), |f| f.0.clone());
        let (c, flags) = self.apply(base);
        let (want, have) = (serde_json::to_value(&c)?, serde_json::to_value(design)?);
        let keys = |v: &serde_json::Value| -> Vec<String> {
            v.as_object()
                .map_or_else(Vec::new, |o| o.keys().cloned().collect())
        };
        let mut fields: Vec<String> = keys(&want);
        fields.extend(keys(&have));
        fields.sort();
        fields.dedup();
        let shown = |v: Option<&serde_json::Value>| match v {
            None => "its default".to_string(),
            Some(serde_json::Value::String(s)) => format!("{s:?}"),
            Some(v) => v.to_string(),
        };
        let diffs: Vec<String> = fields
            .iter()
            .filter(|f| want.get(f.as_str()) != have.get(f.as_str()))
            .map(|f| {
                let from = match (flags.iter().find(|x| x.0 == f.as_str()), &file) {
                    (Some(fl), _) => fl.1.clone(),
                    (None, Some((_, _, what))) => what.clone(),
                    (None, None) => "the flags".into(),
                };
                format!(
                    "{from} sets {f} {}, the design has {}",
                    shown(want.get(f.as_str())),
                    shown(have.get(f.as_str()))
                )
            })
            .collect();
        if !diffs.is_empty() {
            anyhow::bail!(
                "{}: {} (its {}); a command given a design takes the design's configuration: drop the contradicting flags, or generate the design again",
                dir.display(),
                diffs.join("; "),
                crate::emit::manifest::FILE
            );
        }
        Ok(design.clone())
    }

    /// Whether any configuration flag or `--config` was given.
    pub fn any(&self) -> bool {
        self.config.is_some() || !self.apply(Config::default()).1.is_empty()
    }

    /// `--config`, read and parsed: the configuration, the text and how messages name it.
    fn file(&self) -> Result<Option<(Config, String, String)>> {
        let Some(p) = &self.config else {
            return Ok(None);
        };
        let text = toml_input::read(p, "config")?;
        let what = format!("config {}", p.display());
        let c: Config = toml_input::parse(&text, &what)?;
        Ok(Some((c, text, what)))
    }

    /// `c` with the flags applied, and the fields they set, each with its flag.
    fn apply(&self, mut c: Config) -> (Config, Vec<(&'static str, String)>) {
        // The fields set by a flag, with the flag.
        let mut flags: Vec<(&'static str, String)> = Vec::new();
        macro_rules! set {
            ($($f:ident),*) => { $( if let Some(v) = self.$f {
                c.$f = v;
                flags.push((stringify!($f), format!("--{} {v}", stringify!($f).replace('_', "-"))));
            } )* };
        }
        set!(
            grad_bits,
            red_bits,
            recip_bits,
            frac_bits,
            index_bits,
            map_bits,
            pipeline_depth,
            axis_user,
            lanes
        );
        if self.no_compensation {
            c.compensation = false;
            flags.push(("compensation", "--no-compensation".into()));
        }
        if self.no_interpolation {
            c.interpolation = false;
            c.interp_bits = 0;
            flags.push(("interpolation", "--no-interpolation".into()));
            flags.push(("interp_bits", "--no-interpolation".into()));
        }
        if let Some(p) = self.interp_bits {
            c.interp_bits = p;
            flags.retain(|f| f.0 != "interp_bits");
            flags.push(("interp_bits", format!("--interp-bits {p}")));
        }
        if self.color {
            c.color = true;
            flags.push(("color", "--color".into()));
        }
        if self.handshake {
            c.handshake = true;
            flags.push(("handshake", "--handshake".into()));
        }
        if self.axis {
            c.axis = true;
            flags.push(("axis", "--axis".into()));
        }
        if let Some(p) = &self.prefix {
            c.prefix = p.clone();
            flags.push(("prefix", format!("--prefix {p}")));
        }
        if let Some(t) = self.target {
            c.target = t;
            flags.push(("target", format!("--target {}", t.name())));
        }
        if let Some(m) = self.mult {
            c.mult = m;
            flags.push(("mult", format!("--mult {}", m.name())));
        }
        if let Some(t) = self.comp_table {
            c.comp_table = t;
            flags.push(("comp_table", format!("--comp-table {}", t.name())));
        }
        if let Some(b) = self.bus {
            c.bus = b;
            flags.push(("bus", format!("--bus {}", b.name())));
        }
        (c, flags)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(Parser)]
    struct Cli {
        #[command(flatten)]
        cfg: ConfigArgs,
    }

    fn resolve(flags: &[String]) -> Config {
        let cli = Cli::try_parse_from(std::iter::once("t".to_string()).chain(flags.to_vec()))
            .unwrap_or_else(|e| panic!("{flags:?}: {e}"));
        cli.cfg.resolve().unwrap()
    }

    #[test]
    fn flags_give_back_the_configuration() {
        assert!(ConfigArgs::flags(&Config::default()).is_empty());
        let mut configs: Vec<Config> = crate::grid::rows().into_iter().map(|r| r.config).collect();
        configs.push(crate::grid::narrowest());
        for c in configs {
            assert_eq!(resolve(&ConfigArgs::flags(&c)), c);
        }
    }
}
