//! Test vectors written from the model: `vectors/<stage>.hex` for every stage present in a
//! configuration and `vectors/rmap_top.hex` for the whole pipeline.
//!
//! Format (docs/ARCHITECTURE.md, "Vector files"): one vector per line, the stage's fields
//! ([`Vectors::fields`]) in order (inputs, then expected outputs), each in hex zero-padded to
//! its width, separated by single spaces, no header. Line n of a file is vector n, which is
//! what the testbenches print on a mismatch. Each stage supplies its inputs (corner cases
//! first, then seeded random ones) and its expected outputs from the model
//! ([`Vectors::inputs`], [`Vectors::expected`]); this module writes and reads the files.

pub mod field;
pub mod inputs;

use crate::config::Config;
use crate::design::Design;
use crate::hexfile;
pub use crate::model::map_set::{read_maps, MapSet, MAX_MAP_FILE_BYTES};
use crate::model::Model;
use crate::output::StagedDir;
use crate::stages::{self, rmap_top, Vectors, TOP};
use anyhow::{bail, Context, Result};
pub use field::{Dir, Field};
use std::io::Write;
use std::path::Path;

/// Largest number of random vectors per stage file (`generate --vectors`, `fit --vectors`):
/// 1 000 000. Each stage file is built in memory before it is written (about 100 bytes a
/// vector at the peak, so at most about 100 MB a stage), and the testbenches stream it at
/// about 6 000 vectors/s in Icarus, so a million already takes about 3 minutes a stage.
/// Longer runs of the top are what `rmapgen vectors` is for: it streams to disk.
pub const MAX_STAGE_VECTORS: usize = 1_000_000;

/// Largest number of random vectors of a top stream (`vectors --count`): 10^10, about 190 GB
/// at the default widths, about 3 hours to write at the measured 1 million vectors/s and
/// 1.4 hours through the Verilator C++ harness at 2 million vectors/s. The free space of the
/// target's filesystem is checked too, before anything is written.
pub const MAX_STREAM_VECTORS: u64 = 10_000_000_000;

/// Refuses a per-stage vector count above [`MAX_STAGE_VECTORS`], naming `flag`.
pub fn check_stage_vectors(n: usize, flag: &str) -> Result<()> {
    if n > MAX_STAGE_VECTORS {
        bail!(
            "{flag} {n} is more than the limit of {MAX_STAGE_VECTORS} random vectors per stage file; for a longer stream of the top use `rmapgen vectors --count N`"
        );
    }
    Ok(())
}

/// Refuses a top stream count above [`MAX_STREAM_VECTORS`].
pub fn check_stream_vectors(n: u64) -> Result<()> {
    if n > MAX_STREAM_VECTORS {
        bail!("--count {n} is more than the limit of {MAX_STREAM_VECTORS} vectors");
    }
    Ok(())
}

/// Lines of a top stream of `random` random vectors: both parts' corner cases, the random
/// vectors and the repeated swap witness (see [`top_inputs`]).
pub fn top_stream_lines(cfg: &Config, random: u64) -> u64 {
    rmap_top::stream_lines(cfg, random)
}

/// Bytes of one top vector line (every line has the same length: fields are zero-padded).
pub fn top_line_bytes(cfg: &Config) -> u64 {
    let fields = top().fields(cfg);
    let digits: u64 = fields.iter().map(|f| hexfile::digits(f.bits) as u64).sum();
    digits + fields.len() as u64
}

/// The exact size of a top stream file of `random` random vectors (saturating).
pub fn top_stream_bytes(cfg: &Config, random: u64) -> u64 {
    top_stream_lines(cfg, random).saturating_mul(top_line_bytes(cfg))
}

/// The top's vectors (the stream the Verilator C++ harness reads).
fn top() -> &'static dyn Vectors {
    TOP.vectors().expect("the top has vectors")
}

/// One line: every field zero-padded to its width in hex, single spaces.
pub fn format_line(fields: &[Field], values: &[u64], line: &mut String) {
    use std::fmt::Write as _;
    debug_assert_eq!(fields.len(), values.len());
    for (i, (f, v)) in fields.iter().zip(values).enumerate() {
        debug_assert!(
            *v < 1u64 << f.bits,
            "{} = {v:#x} wider than {} bits",
            f.name,
            f.bits
        );
        if i > 0 {
            line.push(' ');
        }
        let w = hexfile::digits(f.bits);
        let _ = write!(line, "{v:0w$x}");
    }
    line.push('\n');
}

/// Parses one line back into field values, checking the count and every width.
pub fn parse_line(fields: &[Field], line: &str) -> Result<Vec<u64>> {
    let parts: Vec<&str> = line.trim_end_matches('\n').split(' ').collect();
    if parts.len() != fields.len() {
        bail!("{} fields, expected {}", parts.len(), fields.len());
    }
    fields
        .iter()
        .zip(parts)
        .map(|(f, p)| {
            let v = u64::from_str_radix(p, 16)
                .with_context(|| format!("field {} = {p:?} is not hex", f.name))?;
            if v >> f.bits != 0 {
                bail!("field {} = {p} is wider than {} bits", f.name, f.bits);
            }
            Ok(v)
        })
        .collect()
}

/// The text of one stage's vector file.
pub fn stage_text(
    stage: &dyn Vectors,
    model: &Model,
    maps: &MapSet,
    random: usize,
    seed: u64,
) -> String {
    let fields = stage.fields(&model.cfg);
    let mut s = String::new();
    let mut row = Vec::with_capacity(fields.len());
    stage
        .inputs(model, maps, random, seed, &mut |inp| {
            row.clear();
            row.extend_from_slice(inp);
            row.extend(stage.expected(model, maps, inp));
            format_line(&fields, &row, &mut s);
            Ok(())
        })
        .expect("writing into a String cannot fail");
    s
}

/// Writes `vectors/<module>.hex` ([`Vectors::vector_file`]) for every stage present in the
/// design, and `vectors/rmap_top.hex` (each with the configuration's prefix), expecting buffer 0 to hold the design's scene map and buffer 1 its
/// second map.
pub fn write_all(design: &Design, out: &StagedDir, random: usize, seed: u64) -> Result<()> {
    check_stage_vectors(random, "--vectors")?;
    // rmap_lanes reads the top's file: each file is written once.
    let mut written: Vec<String> = Vec::new();
    for stage in stages::checked(design.cfg()) {
        let file = stage.vector_file(design.cfg());
        if written.contains(&file) {
            continue;
        }
        written.push(file);
        out.write_text(
            &stage.vector_file(design.cfg()),
            &stage_text(stage, &design.model, &design.maps, random, seed),
        )?;
    }
    Ok(())
}

/// Writes a top vector stream of `random` random vectors (plus the corner cases, as in
/// `vectors/rmap_top.hex`, which it equals for the same count and seed) to `path`, for the
/// Verilator C++ harness. Returns the number of vectors written.
pub fn write_top_stream(
    cfg: &Config,
    maps: &MapSet,
    path: &Path,
    random: usize,
    seed: u64,
) -> Result<usize> {
    write_top_stream_with_progress(cfg, maps, path, random, seed, &|_| {})
}

/// [`write_top_stream`], calling `progress(n)` after every `n` more lines written.
pub fn write_top_stream_with_progress(
    cfg: &Config,
    maps: &MapSet,
    path: &Path,
    random: usize,
    seed: u64,
    progress: &dyn Fn(u64),
) -> Result<usize> {
    cfg.validate()?;
    check_stream_vectors(random as u64)?;
    let model = Model::new(cfg);
    let top = top();
    let fields = top.fields(cfg);
    if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    let (mut n, mut line, mut row) = (0usize, String::new(), Vec::new());
    top.inputs(&model, maps, random, seed, &mut |inp| {
        row.clear();
        row.extend_from_slice(inp);
        row.extend(top.expected(&model, maps, inp));
        line.clear();
        format_line(&fields, &row, &mut line);
        n += 1;
        if n % (1 << 16) == 0 {
            progress(1 << 16);
        }
        w.write_all(line.as_bytes())
            .with_context(|| format!("cannot write {}", path.display()))
    })?;
    w.flush()
        .with_context(|| format!("cannot write {}", path.display()))?;
    progress(n as u64 % (1 << 16));
    Ok(n)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_fit_every_value_written() {
        let cfg = Config {
            color: true,
            ..Config::default()
        };
        let model = Model::new(&cfg);
        let maps = MapSet::standard(&cfg);
        for stage in stages::checked(&cfg) {
            let fields = stage.fields(&cfg);
            for line in stage_text(stage, &model, &maps, 50, 1).lines() {
                parse_line(&fields, line)
                    .unwrap_or_else(|e| panic!("{}: {line}: {e}", stage.name()));
            }
        }
    }
}
