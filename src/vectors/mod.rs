//! Test vectors written from the model: `vectors/<stage>.hex` for every stage present in a
//! configuration and `vectors/rmap_top.hex` for the whole pipeline.
//!
//! Format (docs/ARCHITECTURE.md, "Vector files"): one vector per line, the fields of
//! [`Stage::fields`] in order (inputs, then expected outputs), each in hex zero-padded to its
//! width, separated by single spaces, no header. Line n of a file is vector n, which is what
//! the testbenches print on a mismatch. Hand-picked corner cases come first, then seeded
//! random vectors from a splitmix64 stream per stage, so a file is byte-reproducible from
//! (configuration, maps, random count, seed).
//!
//! Every expected value comes from the model: the stage functions of `crate::model` that
//! [`Model::trace`] calls, and `Model::trace` itself for the top.

pub mod inputs;

use crate::config::{Config, COLOR_BITS};
use crate::hexfile;
use crate::model::{
    color_mul, interpolate, map_lookup, normalise, sort_shift, zero_detect, Maps, Model,
};
use crate::output::StagedDir;
use crate::rng::SplitMix64;
use crate::scene::Scene;
use anyhow::{bail, Context, Result};
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
    (inputs::top_corners(cfg, 0).len() + inputs::top_corners(cfg, 1).len()) as u64 + 1 + random
}

/// Bytes of one top vector line (every line has the same length: fields are zero-padded).
pub fn top_line_bytes(cfg: &Config) -> u64 {
    let fields = Stage::Top.fields(cfg);
    let digits: u64 = fields.iter().map(|f| hexfile::digits(f.bits) as u64).sum();
    digits + fields.len() as u64
}

/// The exact size of a top stream file of `random` random vectors (saturating).
pub fn top_stream_bytes(cfg: &Config, random: u64) -> u64 {
    top_stream_lines(cfg, random).saturating_mul(top_line_bytes(cfg))
}

/// Whether a field drives the module or is checked at its output.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dir {
    In,
    Out,
}

/// One field of a vector line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Field {
    pub name: &'static str,
    pub bits: u32,
    pub dir: Dir,
}

/// A module with its own vector file and testbench.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    ZeroDetect,
    SortShift,
    Normalise,
    AtanRom,
    LinearIndex,
    MapLookup,
    Interpolate,
    ColorMul,
    Top,
}

impl Stage {
    /// Pipeline order; the top last.
    pub const ALL: [Stage; 9] = [
        Stage::ZeroDetect,
        Stage::SortShift,
        Stage::Normalise,
        Stage::AtanRom,
        Stage::LinearIndex,
        Stage::MapLookup,
        Stage::Interpolate,
        Stage::ColorMul,
        Stage::Top,
    ];

    /// The Verilog module name, which also names the vector file and the testbench.
    pub fn name(self) -> &'static str {
        match self {
            Stage::ZeroDetect => "zero_detect",
            Stage::SortShift => "sort_shift",
            Stage::Normalise => "normalise",
            Stage::AtanRom => "atan_rom",
            Stage::LinearIndex => "linear_index",
            Stage::MapLookup => "map_lookup",
            Stage::Interpolate => "interpolate",
            Stage::ColorMul => "color_mul",
            Stage::Top => "rmap_top",
        }
    }

    pub fn from_name(name: &str) -> Option<Stage> {
        Stage::ALL.into_iter().find(|s| s.name() == name)
    }

    /// Whether the configuration has this module.
    pub fn present(self, cfg: &Config) -> bool {
        match self {
            Stage::AtanRom => cfg.compensation,
            Stage::LinearIndex => !cfg.compensation,
            Stage::Interpolate => cfg.interpolation,
            Stage::ColorMul => cfg.color,
            _ => true,
        }
    }

    /// `vectors/<module>.hex`, relative to the output directory.
    pub fn vector_file(self) -> String {
        format!("vectors/{}.hex", self.name())
    }

    /// The fields of one vector line, inputs first, in the documented order.
    pub fn fields(self, cfg: &Config) -> Vec<Field> {
        use Dir::{In, Out};
        let f = |name, bits, dir| Field { name, bits, dir };
        let (g, r, fr, pos, m) = (
            cfg.grad_bits,
            cfg.red_bits,
            cfg.frac_bits,
            cfg.pos_bits(),
            cfg.map_bits,
        );
        let w = cfg.weight_bits();
        let grads = |v: &mut Vec<Field>| v.extend([f("gx", g, In), f("gy", g, In), f("gz", g, In)]);
        let mut v = Vec::new();
        match self {
            Stage::ZeroDetect => {
                grads(&mut v);
                v.push(f("zero", 1, Out));
            }
            Stage::SortShift => {
                grads(&mut v);
                v.extend([
                    f("axis", 2, Out),
                    f("s_max", 1, Out),
                    f("s_u", 1, Out),
                    f("s_v", 1, Out),
                ]);
                v.extend([f("m", r, Out), f("a", r, Out), f("b", r, Out)]);
            }
            Stage::Normalise => {
                v.extend([
                    f("m", r, In),
                    f("a", r, In),
                    f("b", r, In),
                    f("u", fr, Out),
                    f("v", fr, Out),
                ]);
            }
            Stage::AtanRom | Stage::LinearIndex => {
                v.extend([
                    f("u", fr, In),
                    f("v", fr, In),
                    f("pu", pos, Out),
                    f("pv", pos, Out),
                ]);
            }
            Stage::MapLookup => {
                v.extend([
                    f("axis", 2, In),
                    f("s_max", 1, In),
                    f("s_u", 1, In),
                    f("s_v", 1, In),
                ]);
                v.extend([
                    f("pu", pos, In),
                    f("pv", pos, In),
                    f("buf", 1, In),
                    f("e00", m, Out),
                ]);
                if cfg.interpolation {
                    v.extend([f("e10", m, Out), f("e01", m, Out), f("e11", m, Out)]);
                    v.extend([f("wu", w, Out), f("wv", w, Out)]);
                }
            }
            Stage::Interpolate => {
                v.extend([
                    f("e00", m, In),
                    f("e10", m, In),
                    f("e01", m, In),
                    f("e11", m, In),
                ]);
                v.extend([f("wu", w, In), f("wv", w, In), f("i", m, Out)]);
            }
            Stage::ColorMul => {
                let c = COLOR_BITS;
                v.extend([f("i", m, In), f("r", c, In), f("g", c, In), f("b", c, In)]);
                v.extend([f("r_o", c, Out), f("g_o", c, Out), f("b_o", c, Out)]);
            }
            Stage::Top => {
                v.push(f("map", 1, In));
                grads(&mut v);
                if cfg.color {
                    let c = COLOR_BITS;
                    v.extend([f("r", c, In), f("g", c, In), f("b", c, In)]);
                }
                v.extend([f("zero", 1, Out), f("i", m, Out)]);
                if cfg.color {
                    let c = COLOR_BITS;
                    v.extend([f("r_o", c, Out), f("g_o", c, Out), f("b_o", c, Out)]);
                }
            }
        }
        v
    }
}

/// The modules of a configuration that have vectors, in pipeline order, the top last.
pub fn stages(cfg: &Config) -> Vec<Stage> {
    Stage::ALL.into_iter().filter(|s| s.present(cfg)).collect()
}

/// The two map buffers the vectors assume: buffer 0 holds the scene's map (the design's
/// initial contents), buffer 1 the second map the testbenches load through the host port.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct MapSet {
    pub scene: Maps,
    pub second: Maps,
}

impl MapSet {
    /// The standard scene's map and the alternate scene's.
    pub fn standard(cfg: &Config) -> MapSet {
        MapSet::from_scenes(cfg, &Scene::standard(), &Scene::alternate())
    }

    pub fn from_scenes(cfg: &Config, scene: &Scene, second: &Scene) -> MapSet {
        MapSet {
            scene: scene.maps(cfg),
            second: second.maps(cfg),
        }
    }

    /// Reads `map_{x,y,z}.hex` and `map2_{x,y,z}.hex` from a generated design directory, so
    /// the vectors match whatever scene the design was generated with.
    pub fn from_dir(cfg: &Config, dir: &Path) -> Result<MapSet> {
        Ok(MapSet {
            scene: read_maps(cfg, dir, "map")?,
            second: read_maps(cfg, dir, "map2")?,
        })
    }

    /// Buffer 0 or 1.
    pub fn buffer(&self, buf: u64) -> &Maps {
        if buf == 0 {
            &self.scene
        } else {
            &self.second
        }
    }
}

/// Largest map file `vectors --maps` reads (16 MiB): the widest configuration's map has
/// 32 768 entries of a few bytes each; a file far beyond that is not a map.
pub const MAX_MAP_FILE_BYTES: u64 = 16 << 20;

/// Reads the three `$readmemh` files `<prefix>_{x,y,z}.hex` (logical address order).
pub fn read_maps(cfg: &Config, dir: &Path, prefix: &str) -> Result<Maps> {
    let mut data = Vec::with_capacity(3 * cfg.map_entries() as usize);
    for axis in ["x", "y", "z"] {
        let p = dir.join(format!("{prefix}_{axis}.hex"));
        if p.is_dir() {
            bail!("map {} is a directory, not a map file", p.display());
        }
        if let Ok(m) = std::fs::metadata(&p) {
            if m.len() > MAX_MAP_FILE_BYTES {
                bail!(
                    "map {} is {} bytes, more than the limit of {MAX_MAP_FILE_BYTES} for a map file",
                    p.display(),
                    m.len()
                );
            }
        }
        let text = std::fs::read_to_string(&p)
            .with_context(|| format!("cannot read map {}", p.display()))?;
        let before = data.len();
        for (n, line) in text.lines().enumerate() {
            let t = line.split("//").next().unwrap_or("").trim();
            if t.is_empty() {
                continue;
            }
            let v = u32::from_str_radix(t, 16)
                .with_context(|| format!("{}:{}: not a hex entry: {t:?}", p.display(), n + 1))?;
            if v > cfg.map_max() {
                bail!(
                    "{}:{}: entry {v:#x} is wider than map_bits = {}",
                    p.display(),
                    n + 1,
                    cfg.map_bits
                );
            }
            data.push(v);
        }
        let got = data.len() - before;
        if got != cfg.map_entries() as usize {
            bail!(
                "{} has {got} entries; the configuration needs {}",
                p.display(),
                cfg.map_entries()
            );
        }
    }
    Ok(Maps::from_data(cfg, data))
}

/// The expected outputs of a stage for one input vector, from the model.
pub fn expected(stage: Stage, model: &Model, maps: &MapSet, inp: &[u64]) -> Vec<u64> {
    let cfg = &model.cfg;
    let u = |i: usize| inp[i] as u32;
    let g = |i: usize| inputs::dec_grad(cfg, inp[i]);
    match stage {
        Stage::ZeroDetect => vec![zero_detect::eval([g(0), g(1), g(2)]) as u64],
        Stage::SortShift => {
            let s = sort_shift::eval(cfg, [g(0), g(1), g(2)]);
            [s.axis, s.s_max, s.s_u, s.s_v, s.m, s.a, s.b]
                .map(u64::from)
                .to_vec()
        }
        Stage::Normalise => {
            let n = normalise::eval(cfg, &model.recip, u(0), u(1), u(2));
            vec![n.u as u64, n.v as u64]
        }
        Stage::AtanRom | Stage::LinearIndex => {
            vec![model.position(u(0)) as u64, model.position(u(1)) as u64]
        }
        Stage::MapLookup => {
            let l = map_lookup::eval(cfg, maps.buffer(inp[6]), u(0), u(1), u(2), u(3), u(4), u(5));
            if cfg.interpolation {
                [l.e[0], l.e[1], l.e[2], l.e[3], l.w_u, l.w_v]
                    .map(u64::from)
                    .to_vec()
            } else {
                vec![l.e[0] as u64]
            }
        }
        Stage::Interpolate => {
            vec![interpolate::eval(cfg, [u(0), u(1), u(2), u(3)], u(4), u(5)) as u64]
        }
        Stage::ColorMul => color_mul::eval(cfg, [u(1), u(2), u(3)], u(0))
            .map(u64::from)
            .to_vec(),
        Stage::Top => {
            let rgb = if cfg.color {
                [u(4), u(5), u(6)]
            } else {
                [0; 3]
            };
            let o = model.shade(maps.buffer(inp[0]), [g(1), g(2), g(3)], rgb);
            let mut v = vec![o.zero as u64, o.intensity as u64];
            if cfg.color {
                v.extend(o.rgb.map(u64::from));
            }
            v
        }
    }
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

/// Whether `head` (the first bytes of a file) looks like a vector stream rmapgen wrote: lines
/// of space-separated lower-case hex fields, so `rmapgen vectors` may replace the file.
pub fn is_vector_stream(head: &[u8]) -> bool {
    let Ok(text) =
        std::str::from_utf8(head).or_else(|e| std::str::from_utf8(&head[..e.valid_up_to()]))
    else {
        return false;
    };
    // The last line may be cut where the head ends.
    let complete = match text.rfind('\n') {
        Some(i) => &text[..i],
        None => return text.is_empty(),
    };
    complete.lines().all(|l| {
        !l.is_empty()
            && l.bytes()
                .all(|b| matches!(b, b'0'..=b'9' | b'a'..=b'f' | b' '))
    })
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

/// The input vectors of a non-top stage: corners, then `random` random ones.
pub fn stage_inputs(
    stage: Stage,
    model: &Model,
    maps: &MapSet,
    random: usize,
    seed: u64,
) -> Vec<Vec<u64>> {
    assert!(
        stage != Stage::Top,
        "the top's vectors come from top_inputs"
    );
    let mut v = inputs::corners(stage, model, &maps.scene);
    let mut rng = SplitMix64::for_stream(seed, stage.name());
    v.extend((0..random).map(|_| inputs::random(stage, &model.cfg, &mut rng)));
    v
}

/// The top's inputs, in two parts: with map 0 the corners, the first half of the random
/// vectors (rounded up) and the swap witness; then with map 1 the witness again, the other
/// corners and the rest of the random vectors. The witness is the first corner gradient whose
/// result differs between the two maps, so the vectors on both sides of the swap tell the
/// buffers apart: the testbench swaps with the first map-1 vector. Calls `emit` per vector so
/// a large stream never sits in memory.
pub fn top_inputs(
    model: &Model,
    maps: &MapSet,
    random: usize,
    seed: u64,
    mut emit: impl FnMut(&[u64]) -> Result<()>,
) -> Result<()> {
    let cfg = &model.cfg;
    let mut rng = SplitMix64::for_stream(seed, Stage::Top.name());
    let first = random.div_ceil(2);
    let mut corners1 = inputs::top_corners(cfg, 1);
    let witness = corners1
        .iter()
        .position(|c| {
            expected(Stage::Top, model, maps, c)
                != expected(Stage::Top, model, maps, &[&[0], &c[1..]].concat())
        })
        .unwrap_or(0);
    let w1 = corners1.remove(witness);
    let mut w0 = w1.clone();
    w0[0] = 0;
    for c in inputs::top_corners(cfg, 0) {
        emit(&c)?;
    }
    for _ in 0..first {
        emit(&inputs::top_random(cfg, &mut rng, 0))?;
    }
    emit(&w0)?;
    emit(&w1)?;
    for c in corners1 {
        emit(&c)?;
    }
    for _ in first..random {
        emit(&inputs::top_random(cfg, &mut rng, 1))?;
    }
    Ok(())
}

/// The text of one stage's vector file.
pub fn stage_text(stage: Stage, model: &Model, maps: &MapSet, random: usize, seed: u64) -> String {
    let fields = stage.fields(&model.cfg);
    let mut s = String::new();
    let mut row = Vec::with_capacity(fields.len());
    let mut line = |inp: &[u64], s: &mut String| {
        row.clear();
        row.extend_from_slice(inp);
        row.extend(expected(stage, model, maps, inp));
        format_line(&fields, &row, s);
    };
    if stage == Stage::Top {
        top_inputs(model, maps, random, seed, |inp| {
            line(inp, &mut s);
            Ok(())
        })
        .expect("writing into a String cannot fail");
    } else {
        for inp in stage_inputs(stage, model, maps, random, seed) {
            line(&inp, &mut s);
        }
    }
    s
}

/// Writes `vectors/<stage>.hex` for every stage present in `cfg`, and `vectors/rmap_top.hex`,
/// with the standard scene's map in buffer 0 and the alternate scene's in buffer 1.
pub fn write_all(cfg: &Config, out: &StagedDir, random: usize, seed: u64) -> Result<()> {
    write_all_with_maps(cfg, out, random, seed, &MapSet::standard(cfg))
}

/// [`write_all`] for a design generated with other maps (another scene).
pub fn write_all_with_maps(
    cfg: &Config,
    out: &StagedDir,
    random: usize,
    seed: u64,
    maps: &MapSet,
) -> Result<()> {
    cfg.validate()?;
    check_stage_vectors(random, "--vectors")?;
    let model = Model::new(cfg);
    for stage in stages(cfg) {
        out.write_text(
            &stage.vector_file(),
            &stage_text(stage, &model, maps, random, seed),
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
    let fields = Stage::Top.fields(cfg);
    if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
    }
    let file =
        std::fs::File::create(path).with_context(|| format!("cannot write {}", path.display()))?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    let (mut n, mut line, mut row) = (0usize, String::new(), Vec::new());
    top_inputs(&model, maps, random, seed, |inp| {
        row.clear();
        row.extend_from_slice(inp);
        row.extend(expected(Stage::Top, &model, maps, inp));
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
        for stage in stages(&cfg) {
            let fields = stage.fields(&cfg);
            for line in stage_text(stage, &model, &maps, 50, 1).lines() {
                parse_line(&fields, line)
                    .unwrap_or_else(|e| panic!("{}: {line}: {e}", stage.name()));
            }
        }
    }

    #[test]
    fn stages_follow_the_config() {
        let names = |c: &Config| {
            stages(c)
                .iter()
                .map(|s| s.name())
                .collect::<Vec<_>>()
                .join(" ")
        };
        assert_eq!(
            names(&Config::default()),
            "zero_detect sort_shift normalise atan_rom map_lookup interpolate rmap_top"
        );
        let c = Config {
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            color: true,
            ..Config::default()
        };
        assert_eq!(
            names(&c),
            "zero_detect sort_shift normalise linear_index map_lookup color_mul rmap_top"
        );
    }
}
