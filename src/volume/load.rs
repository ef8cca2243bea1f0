//! Volume files: raw voxel files (dimensions and spacing given by the caller) and NRRD
//! (<http://teem.sourceforge.net/nrrd/format.html>), the usual exchange format for CT data.
//!
//! NRRD support: attached (`.nrrd`) and detached (`.nhdr` with a `data file`) data, `raw`
//! and `gzip` encodings, `byte skip` (including -1 for raw data) and `line skip`, both byte
//! orders, three dimensions. Types: signed/unsigned 8-, 16- and 32-bit integers, `float` and
//! `double`, all converted to f32 (exact for integers up to 2^24). The voxel spacing comes
//! from `spacings` or from the lengths of `space directions`, whose directions give the
//! volume's orientation ([`Volume::axes`]: the camera's view and up are world directions,
//! so a scan renders upright with world +z up). Sheared (non-orthogonal) directions and
//! anything else unsupported are refused with an error naming it.
//!
//! Bounds: the volume must fit [`super::MEMORY_BUDGET`] (checked from the header, before any
//! data is read, with the size it needs); the data is streamed in chunks, never held whole,
//! and everything read from it (line skips, byte skip, voxel data, after decompression)
//! counts against [`MAX_READ_BYTES`]; a header is at most [`MAX_HEADER_BYTES`].

use super::{check_dims, check_spacing, human_bytes, Volume, VolumeInfo};
use anyhow::{bail, Context, Result};
use std::io::{BufRead, BufReader, Read, Seek, SeekFrom};
use std::path::Path;

/// Largest NRRD header read, in bytes (1 MiB): the text before the blank line of an attached
/// file, or a whole detached `.nhdr`. Real headers are a few hundred bytes.
pub const MAX_HEADER_BYTES: usize = 1 << 20;

/// Largest number of bytes read from a volume's data stream, in bytes (4 GiB): skipped lines,
/// `byte skip` and the voxel data together, after decompression for gzip. It bounds the work
/// a small file can ask for (a gzip stream of zeros decompresses 1000 to 1); the largest
/// volume of doubles inside [`super::MAX_VOXELS`] is 1.6 GiB of voxel data.
pub const MAX_READ_BYTES: u64 = 4 << 30;

/// Bytes decoded at a time: the loaders never hold the file's voxel bytes, only this chunk
/// and the f32 values.
const CHUNK: usize = 1 << 20;

/// Voxel types the loaders convert.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VoxelType {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl VoxelType {
    pub fn bytes(self) -> usize {
        match self {
            VoxelType::I8 | VoxelType::U8 => 1,
            VoxelType::I16 | VoxelType::U16 => 2,
            VoxelType::I32 | VoxelType::U32 | VoxelType::F32 => 4,
            VoxelType::F64 => 8,
        }
    }

    /// The NRRD name of the type.
    pub fn name(self) -> &'static str {
        match self {
            VoxelType::I8 => "signed char",
            VoxelType::U8 => "uchar",
            VoxelType::I16 => "short",
            VoxelType::U16 => "ushort",
            VoxelType::I32 => "int",
            VoxelType::U32 => "uint",
            VoxelType::F32 => "float",
            VoxelType::F64 => "double",
        }
    }

    /// Parses an NRRD type name (every spelling the format allows).
    pub fn from_nrrd(name: &str) -> Result<VoxelType> {
        let t = match name {
            "signed char" | "int8" | "int8_t" => VoxelType::I8,
            "uchar" | "unsigned char" | "uint8" | "uint8_t" => VoxelType::U8,
            "short" | "short int" | "signed short" | "signed short int" | "int16" | "int16_t" => {
                VoxelType::I16
            }
            "ushort" | "unsigned short" | "unsigned short int" | "uint16" | "uint16_t" => {
                VoxelType::U16
            }
            "int" | "signed int" | "int32" | "int32_t" => VoxelType::I32,
            "uint" | "unsigned int" | "uint32" | "uint32_t" => VoxelType::U32,
            "float" => VoxelType::F32,
            "double" => VoxelType::F64,
            "longlong"
            | "long long"
            | "long long int"
            | "signed long long"
            | "signed long long int"
            | "int64"
            | "int64_t"
            | "ulonglong"
            | "unsigned long long"
            | "unsigned long long int"
            | "uint64"
            | "uint64_t" => {
                bail!("unsupported NRRD type '{name}': 64-bit integers are not supported (supported: {SUPPORTED_TYPES})")
            }
            _ => bail!("unsupported NRRD type '{name}' (supported: {SUPPORTED_TYPES})"),
        };
        Ok(t)
    }

    /// Appends packed voxels (a whole number of them) to `out` as f32, without any
    /// temporary. A finite value too large for f32 (a double beyond 3.4e38) is an error
    /// naming it and its voxel, counted from `first` (the index of the first voxel in
    /// `bytes`).
    pub fn decode_into(
        self,
        bytes: &[u8],
        big_endian: bool,
        first: usize,
        out: &mut Vec<f32>,
    ) -> std::result::Result<(), Overflow> {
        macro_rules! conv {
            ($t:ty, $n:expr) => {
                out.extend(bytes.chunks_exact($n).map(|c| {
                    let a: [u8; $n] = c.try_into().expect("whole voxels");
                    (if big_endian {
                        <$t>::from_be_bytes(a)
                    } else {
                        <$t>::from_le_bytes(a)
                    }) as f32
                }))
            };
        }
        match self {
            VoxelType::I8 => out.extend(bytes.iter().map(|&b| b as i8 as f32)),
            VoxelType::U8 => out.extend(bytes.iter().map(|&b| b as f32)),
            VoxelType::I16 => conv!(i16, 2),
            VoxelType::U16 => conv!(u16, 2),
            VoxelType::I32 => conv!(i32, 4),
            VoxelType::U32 => conv!(u32, 4),
            VoxelType::F32 => conv!(f32, 4),
            VoxelType::F64 => {
                for (i, c) in bytes.chunks_exact(8).enumerate() {
                    let a: [u8; 8] = c.try_into().expect("8 bytes");
                    let v = if big_endian {
                        f64::from_be_bytes(a)
                    } else {
                        f64::from_le_bytes(a)
                    };
                    let f = v as f32;
                    if v.is_finite() && !f.is_finite() {
                        return Err(Overflow {
                            index: first + i,
                            value: v,
                        });
                    }
                    out.push(f);
                }
            }
        }
        Ok(())
    }

    /// Converts packed voxels to f32 (a double too large for f32 becomes infinite; the
    /// loaders use [`VoxelType::decode_into`], which refuses it).
    pub fn decode(self, bytes: &[u8], big_endian: bool) -> Vec<f32> {
        let mut out = Vec::with_capacity(bytes.len() / self.bytes());
        if let Err(o) = self.decode_into(bytes, big_endian, 0, &mut out) {
            out.push(f32::INFINITY.copysign(o.value as f32));
            let rest = &bytes[(o.index + 1) * 8..];
            out.extend(self.decode(rest, big_endian));
        }
        out
    }
}

/// A finite voxel value that does not fit in f32.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Overflow {
    /// Index of the voxel, x fastest.
    pub index: usize,
    pub value: f64,
}

impl Overflow {
    /// The message: the value, the voxel position and why.
    pub fn message(&self, what: &str, dims: [usize; 3]) -> String {
        let (x, y, z) = (
            self.index % dims[0],
            self.index / dims[0] % dims[1],
            self.index / (dims[0] * dims[1]),
        );
        format!(
            "{what}: voxel ({x}, {y}, {z}) value {:e} overflows f32 (largest {:e}); rescale the data",
            self.value,
            f32::MAX
        )
    }
}

/// Opens a volume or data file, refusing a directory by name.
fn open_file(path: &Path, what: &str) -> Result<(std::fs::File, u64)> {
    if path.is_dir() {
        bail!("{} is a directory, not a {what}", path.display());
    }
    let f = std::fs::File::open(path)
        .with_context(|| format!("cannot read {what} {}", path.display()))?;
    let len = f
        .metadata()
        .with_context(|| format!("cannot read {what} {}", path.display()))?
        .len();
    Ok((f, len))
}

/// Reads exactly the voxel data of `dims` voxels of type `t` from `r` and decodes it in
/// chunks into f32 values, reserved with `try_reserve_exact` (an allocation failure is an
/// error, not an abort). `check_end` marks a stream of unknown length (gzip): its values
/// are reserved as they arrive and it must end after the data. `size_error(have)` builds the error for a stream that ends early (have <
/// want) or goes on (have = want + 1, when `check_end`).
#[allow(clippy::too_many_arguments)]
fn read_voxels(
    r: &mut dyn Read,
    t: VoxelType,
    big_endian: bool,
    dims: [usize; 3],
    what: &str,
    check_end: bool,
    read_error: &dyn Fn(std::io::Error) -> anyhow::Error,
    size_error: &dyn Fn(u64) -> anyhow::Error,
) -> Result<Vec<f32>> {
    let n = dims[0] * dims[1] * dims[2];
    let mut values: Vec<f32> = Vec::new();
    let reserve = |values: &mut Vec<f32>, cap: usize| -> Result<()> {
        values.try_reserve_exact(cap - values.len()).map_err(|_| {
            anyhow::anyhow!(
                "{what}: cannot allocate {} for {n} voxel values",
                human_bytes(4 * n as u64)
            )
        })
    };
    // A stream of known length gets all its values at once; a gzip stream only as its data
    // arrives (doubling, never beyond n), so a small file that claims many voxels allocates
    // no more than it holds.
    if check_end {
        reserve(&mut values, n.min(CHUNK))?;
    } else {
        reserve(&mut values, n)?;
    }
    let want = (n * t.bytes()) as u64;
    let chunk = (CHUNK / t.bytes()) * t.bytes();
    let mut buf = vec![0u8; chunk.min(want as usize)];
    let mut have = 0u64;
    while have < want {
        let len = (want - have).min(buf.len() as u64) as usize;
        let mut got = 0;
        while got < len {
            match r.read(&mut buf[got..len]) {
                Ok(0) => return Err(size_error(have + got as u64)),
                Ok(k) => got += k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(read_error(e)),
            }
        }
        let count = len / t.bytes();
        if values.capacity() - values.len() < count {
            let cap = n.min((2 * values.capacity()).max(values.len() + count));
            reserve(&mut values, cap)?;
        }
        t.decode_into(&buf[..len], big_endian, values.len(), &mut values)
            .map_err(|o| anyhow::anyhow!(o.message(what, dims)))?;
        have += len as u64;
    }
    if check_end {
        let mut one = [0u8; 1];
        loop {
            match r.read(&mut one) {
                Ok(0) => break,
                Ok(_) => return Err(size_error(want + 1)),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                Err(e) => return Err(read_error(e)),
            }
        }
    }
    Ok(values)
}

const SUPPORTED_TYPES: &str = "signed char, uchar, short, ushort, int, uint, float, double";

/// A raw voxel file's layout.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RawFormat {
    /// 8 or 16.
    pub bits: u32,
    pub signed: bool,
}

impl RawFormat {
    pub fn voxel_type(self) -> Result<VoxelType> {
        Ok(match (self.bits, self.signed) {
            (8, false) => VoxelType::U8,
            (8, true) => VoxelType::I8,
            (16, false) => VoxelType::U16,
            (16, true) => VoxelType::I16,
            (b, _) => bail!("raw voxels of {b} bits are not supported; give --bits 8 or --bits 16"),
        })
    }
}

/// Loads a raw file of `dims` voxels, x fastest, 16-bit values little-endian. The file size
/// must match the dimensions exactly.
pub fn load_raw(
    path: &Path,
    dims: [i64; 3],
    spacing: [f64; 3],
    format: RawFormat,
) -> Result<Volume> {
    let what = format!("raw file {}", path.display());
    let t = format.voxel_type()?;
    let dims = check_dims(dims, "--dims")?;
    let spacing = check_spacing(spacing, "--spacing")?;
    let want = dims[0] * dims[1] * dims[2] * t.bytes();
    let (mut file, len) = open_file(path, "volume file")?;
    if len != want as u64 {
        bail!(
            "{what} is {len} bytes but --dims {},{},{} with {}-bit voxels need {want} bytes",
            dims[0],
            dims[1],
            dims[2],
            format.bits
        );
    }
    let data = read_voxels(
        &mut file,
        t,
        false,
        dims,
        &what,
        false,
        &|e| anyhow::anyhow!("cannot read {what}: {e}"),
        &|_| anyhow::anyhow!("{what} changed size while being read"),
    )?;
    let info = VolumeInfo {
        source: path.display().to_string(),
        voxel_type: t.name().to_string(),
    };
    Volume::new(dims, spacing, data, info)
}

/// Whether a path names an NRRD file by its extension (`.nrrd` or `.nhdr`, any case).
pub fn is_nrrd(path: &Path) -> bool {
    path.extension()
        .map(|e| e.eq_ignore_ascii_case("nrrd") || e.eq_ignore_ascii_case("nhdr"))
        .unwrap_or(false)
}

/// The fields of an NRRD header that matter here.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NrrdHeader {
    pub voxel_type: Option<String>,
    pub dimension: Option<String>,
    pub sizes: Option<String>,
    pub encoding: Option<String>,
    pub endian: Option<String>,
    pub spacings: Option<String>,
    pub space_directions: Option<String>,
    pub data_file: Option<String>,
    pub byte_skip: Option<String>,
    pub line_skip: Option<String>,
}

/// Splits an NRRD file into its header fields and the offset of attached data (after the
/// blank line that ends the header; `None` when the file ends with the header).
pub fn parse_header(bytes: &[u8], what: &str) -> Result<(NrrdHeader, Option<usize>)> {
    let mut pos = 0;
    let next_line = |pos: &mut usize| -> Option<&[u8]> {
        if *pos >= bytes.len() {
            return None;
        }
        let end = bytes[*pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| *pos + i);
        let line = &bytes[*pos..end];
        *pos = end + 1;
        Some(line.strip_suffix(b"\r").unwrap_or(line))
    };
    let magic = next_line(&mut pos).unwrap_or_default();
    if !(magic.len() == 8 && magic.starts_with(b"NRRD000") && magic[7].is_ascii_digit()) {
        bail!("{what} is not an NRRD file: it does not start with NRRD000x");
    }
    let mut h = NrrdHeader::default();
    let mut lineno = 1;
    let data = loop {
        let Some(line) = next_line(&mut pos) else {
            break None;
        };
        lineno += 1;
        if line.is_empty() {
            break Some(pos.min(bytes.len()));
        }
        let Ok(line) = std::str::from_utf8(line) else {
            bail!("{what}: header line {lineno} is not text");
        };
        if line.starts_with('#') {
            continue;
        }
        if line.contains(":=") {
            continue; // key/value pairs carry no layout
        }
        let Some((field, value)) = line.split_once(": ") else {
            bail!("{what}: header line {lineno} '{line}' is not 'field: value'");
        };
        let value = Some(value.trim().to_string());
        match field.trim() {
            "type" => h.voxel_type = value,
            "dimension" => h.dimension = value,
            "sizes" => h.sizes = value,
            "encoding" => h.encoding = value,
            "endian" => h.endian = value,
            "spacings" => h.spacings = value,
            "space directions" => h.space_directions = value,
            "data file" | "datafile" => h.data_file = value,
            "byte skip" | "byteskip" => h.byte_skip = value,
            "line skip" | "lineskip" => h.line_skip = value,
            // Orientation, labels, units, ranges, kinds, centerings: not needed to render.
            _ => {}
        }
    };
    Ok((h, data))
}

/// Parses `space directions` into each axis's vector.
fn direction_vectors(v: &str, what: &str) -> Result<Vec<Vec<f64>>> {
    let mut out = Vec::new();
    let mut rest = v.trim();
    while !rest.is_empty() {
        if rest.starts_with("none") {
            bail!("{what}: space directions '{v}' has a non-spatial axis ('none'); a scalar volume needs three spatial axes");
        }
        let Some(r) = rest.strip_prefix('(') else {
            bail!("{what}: cannot read space directions '{v}'");
        };
        let Some(close) = r.find(')') else {
            bail!("{what}: cannot read space directions '{v}'");
        };
        let comps: Result<Vec<f64>, _> = r[..close]
            .split(',')
            .map(|c| c.trim().parse::<f64>())
            .collect();
        let comps =
            comps.map_err(|_| anyhow::anyhow!("{what}: cannot read space directions '{v}'"))?;
        out.push(comps);
        rest = r[close + 1..].trim_start();
    }
    Ok(out)
}

/// The spacing (lengths) and unit world directions of three `space directions` vectors;
/// refuses vectors that are not 3-D, not finite, zero or not orthogonal (a sheared grid,
/// which the caster's axis-aligned cells cannot represent).
pub fn spacing_and_axes(vs: &[Vec<f64>], what: &str) -> Result<([f64; 3], [[f64; 3]; 3])> {
    if vs.len() != 3 {
        bail!(
            "{what}: space directions has {} vectors for dimension 3",
            vs.len()
        );
    }
    let mut spacing = [0.0; 3];
    let mut axes = [[0.0; 3]; 3];
    for (a, v) in vs.iter().enumerate() {
        let Ok(v) = <[f64; 3]>::try_from(v.as_slice()) else {
            bail!(
                "{what}: space direction {} has {} components; rmapgen needs 3-D space directions",
                a + 1,
                v.len()
            );
        };
        let len = v.iter().map(|c| c * c).sum::<f64>().sqrt();
        let len = check_spacing([len; 3], what)?[0];
        spacing[a] = len;
        axes[a] = v.map(|c| c / len);
    }
    for (i, j) in [(0, 1), (0, 2), (1, 2)] {
        let d: f64 = (0..3).map(|k| axes[i][k] * axes[j][k]).sum();
        if d.abs() > 1e-6 {
            bail!(
                "{what}: space directions {} and {} are not orthogonal (at {:.3} degrees); a sheared grid is not supported",
                i + 1,
                j + 1,
                d.clamp(-1.0, 1.0).acos().to_degrees()
            );
        }
    }
    Ok((spacing, axes))
}

/// Loads an NRRD volume (`.nrrd` with attached data or `.nhdr` with a detached data file).
pub fn load_nrrd(path: &Path) -> Result<Volume> {
    let what = format!("NRRD file {}", path.display());
    let (mut file, len) = open_file(path, "volume file")?;
    // The header only: at most MAX_HEADER_BYTES, cut at a line end.
    let mut head = Vec::new();
    (&mut file)
        .take(MAX_HEADER_BYTES as u64)
        .read_to_end(&mut head)
        .with_context(|| format!("cannot read {what}"))?;
    let truncated = (head.len() as u64) < len;
    if truncated {
        let end = head.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1);
        head.truncate(end);
    }
    let (h, attached) = parse_header(&head, &what)?;
    if truncated && attached.is_none() {
        bail!(
            "{what}: the header is longer than the limit of {} (no blank line ends it)",
            human_bytes(MAX_HEADER_BYTES as u64)
        );
    }
    let need = |f: &Option<String>, name: &str| -> Result<String> {
        f.clone()
            .with_context(|| format!("{what}: header has no '{name}' field"))
    };

    let t = VoxelType::from_nrrd(&need(&h.voxel_type, "type")?).with_context(|| what.clone())?;
    let dimension = need(&h.dimension, "dimension")?;
    if dimension != "3" {
        bail!("{what}: NRRD dimension {dimension} is not supported; rmapgen volume reads 3-dimensional scalar volumes");
    }
    let sizes: Vec<i64> = need(&h.sizes, "sizes")?
        .split_whitespace()
        .map(|s| {
            s.parse::<i64>()
                .map_err(|_| anyhow::anyhow!("{what}: size '{s}' is not an integer"))
        })
        .collect::<Result<_>>()?;
    if sizes.len() != 3 {
        bail!("{what}: sizes has {} entries for dimension 3", sizes.len());
    }
    let dims = check_dims([sizes[0], sizes[1], sizes[2]], &format!("{what}: sizes"))?;

    let encoding = need(&h.encoding, "encoding")?;
    let gzip = match encoding.as_str() {
        "raw" => false,
        "gzip" | "gz" => true,
        e => bail!("{what}: unsupported NRRD encoding '{e}' (supported: raw, gzip)"),
    };
    let big_endian = match h.endian.as_deref() {
        Some("little") => false,
        Some("big") => true,
        None if t.bytes() == 1 => false,
        None => bail!("{what}: header has no 'endian' field for {} data", t.name()),
        Some(e) => bail!("{what}: endian '{e}' is neither little nor big"),
    };

    let mut axes = super::camera::IDENTITY;
    let spacing = if let Some(sd) = &h.space_directions {
        let (s, a) = spacing_and_axes(&direction_vectors(sd, &what)?, &what)?;
        axes = a;
        s
    } else if let Some(sp) = &h.spacings {
        let s: Vec<f64> = sp
            .split_whitespace()
            .map(|s| match s.parse::<f64>() {
                Ok(v) if v.is_nan() => Ok(1.0),
                Ok(v) => Ok(v.abs()),
                Err(_) => Err(anyhow::anyhow!("{what}: spacing '{s}' is not a number")),
            })
            .collect::<Result<_>>()?;
        if s.len() != 3 {
            bail!("{what}: spacings has {} entries for dimension 3", s.len());
        }
        [s[0], s[1], s[2]]
    } else {
        [1.0; 3]
    };
    let spacing = check_spacing(spacing, &what)?;

    let skip_num = |f: &Option<String>, name: &str| -> Result<i64> {
        match f {
            None => Ok(0),
            Some(s) => match s.parse::<i64>() {
                Ok(v) if v >= -1 => Ok(v),
                _ => bail!("{what}: {name} '{s}' is not an integer >= -1"),
            },
        }
    };
    let byte_skip = skip_num(&h.byte_skip, "byte skip")?;
    let line_skip = skip_num(&h.line_skip, "line skip")?;
    if line_skip < 0 {
        bail!("{what}: line skip must not be negative");
    }
    if byte_skip == -1 && gzip {
        bail!("{what}: byte skip -1 is only allowed with raw encoding");
    }

    // The data: attached after the header, or in the data file named by the header. It is
    // read as a stream, never whole: line skips, byte skip and voxel data count against
    // MAX_READ_BYTES, and only the f32 values are kept.
    let (data, data_len, start, source) = match &h.data_file {
        Some(f) => {
            if f.starts_with("LIST") || (f.contains('%') && f.split_whitespace().count() > 1) {
                bail!("{what}: data file '{f}' is a list or pattern of files, which is not supported; give one data file");
            }
            let p = path.parent().unwrap_or(Path::new(".")).join(f);
            let (df, dlen) = open_file(&p, "data file").with_context(|| what.clone())?;
            (df, dlen, 0u64, format!("data file {}", p.display()))
        }
        None => match attached {
            Some(off) => (file, len, off as u64, what.clone()),
            None => bail!("{what}: header has no 'data file' field and no data follows it"),
        },
    };
    let want = (dims[0] * dims[1] * dims[2] * t.bytes()) as u64;
    let skip = byte_skip.max(0) as u64;
    let size_error = |have: u64| {
        anyhow::anyhow!(
            "{what}: the {source} holds {have} bytes of voxel data but sizes {} {} {} of {} need {want} bytes",
            dims[0],
            dims[1],
            dims[2],
            t.name()
        )
    };
    let limit_error = |n: u128| {
        anyhow::anyhow!(
            "{what}: reading it means {n} bytes (line skip, byte skip {byte_skip} and {want} bytes of voxel data{}), more than the read limit of {}",
            if gzip { ", decompressed" } else { "" },
            human_bytes(MAX_READ_BYTES)
        )
    };
    if skip as u128 + want as u128 > MAX_READ_BYTES as u128 {
        return Err(limit_error(skip as u128 + want as u128));
    }
    let read_error = |e: std::io::Error| anyhow::anyhow!("{what}: cannot read the {source}: {e}");
    let mut r = BufReader::with_capacity(1 << 16, data);
    r.seek(SeekFrom::Start(start)).map_err(read_error)?;
    let mut pos = start;
    for _ in 0..line_skip {
        loop {
            let buf = r.fill_buf().map_err(read_error)?;
            if buf.is_empty() {
                bail!("{what}: line skip {line_skip} passes the end of the {source}");
            }
            let n = buf.iter().position(|&b| b == b'\n').map(|i| i + 1);
            let k = n.unwrap_or(buf.len());
            r.consume(k);
            pos += k as u64;
            if n.is_some() {
                break;
            }
        }
    }
    let read = (pos - start) as u128 + skip as u128 + want as u128;
    if read > MAX_READ_BYTES as u128 {
        return Err(limit_error(read));
    }
    let values = if gzip {
        let gz_error = |e: std::io::Error| {
            anyhow::anyhow!("{what}: cannot decompress the gzip data of the {source}: {e}")
        };
        let mut dec = flate2::bufread::MultiGzDecoder::new(r);
        let skipped =
            std::io::copy(&mut (&mut dec).take(skip), &mut std::io::sink()).map_err(gz_error)?;
        if skipped < skip {
            return Err(size_error(0));
        }
        read_voxels(
            &mut dec,
            t,
            big_endian,
            dims,
            &what,
            true,
            &gz_error,
            &size_error,
        )?
    } else {
        let remaining = data_len.saturating_sub(pos);
        if byte_skip == -1 {
            if remaining < want {
                return Err(size_error(remaining));
            }
            r.seek(SeekFrom::Start(data_len - want))
                .map_err(read_error)?;
        } else {
            if remaining < skip {
                return Err(size_error(0));
            }
            if remaining - skip != want {
                return Err(size_error(remaining - skip));
            }
            r.seek_relative(skip as i64).map_err(read_error)?;
        }
        read_voxels(
            &mut r,
            t,
            big_endian,
            dims,
            &what,
            false,
            &read_error,
            &size_error,
        )?
    };
    let info = VolumeInfo {
        source: path.display().to_string(),
        voxel_type: t.name().to_string(),
    };
    let mut v = Volume::new(dims, spacing, values, info)?;
    v.axes = axes;
    Ok(v)
}

/// An attached NRRD file (raw or gzip encoding) of a volume, little-endian: what
/// [`load_nrrd`] reads back to the same values for integer types up to 16 bits.
pub fn nrrd_bytes(vol: &Volume, t: VoxelType, gzip: bool) -> Result<Vec<u8>> {
    use std::io::Write;
    let mut header = format!(
        "NRRD0004\n# written by rmapgen {}\ntype: {}\ndimension: 3\nsizes: {} {} {}\nspacings: {} {} {}\nencoding: {}\n",
        env!("CARGO_PKG_VERSION"),
        t.name(),
        vol.dims[0],
        vol.dims[1],
        vol.dims[2],
        vol.spacing[0],
        vol.spacing[1],
        vol.spacing[2],
        if gzip { "gzip" } else { "raw" }
    );
    if t.bytes() > 1 {
        header.push_str("endian: little\n");
    }
    header.push('\n');
    let mut body = Vec::with_capacity(vol.data.len() * t.bytes());
    for &v in &vol.data {
        match t {
            VoxelType::I8 => body.push(v as i8 as u8),
            VoxelType::U8 => body.push(v as u8),
            VoxelType::I16 => body.extend((v as i16).to_le_bytes()),
            VoxelType::U16 => body.extend((v as u16).to_le_bytes()),
            VoxelType::I32 => body.extend((v as i32).to_le_bytes()),
            VoxelType::U32 => body.extend((v as u32).to_le_bytes()),
            VoxelType::F32 => body.extend(v.to_le_bytes()),
            VoxelType::F64 => body.extend((v as f64).to_le_bytes()),
        }
    }
    let mut out = header.into_bytes();
    if gzip {
        let mut enc = flate2::write::GzEncoder::new(out, flate2::Compression::fast());
        enc.write_all(&body)?;
        out = enc.finish()?;
    } else {
        out.extend(body);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn small() -> Volume {
        let data = (0..4 * 3 * 2).map(|i| (i * 1000 % 65536) as f32).collect();
        Volume::new(
            [4, 3, 2],
            [1.0, 0.5, 2.0],
            data,
            VolumeInfo {
                source: "t".into(),
                voxel_type: "ushort".into(),
            },
        )
        .unwrap()
    }

    #[test]
    fn nrrd_round_trip_raw_and_gzip() {
        let d = tempfile::tempdir().unwrap();
        let v = small();
        for gzip in [false, true] {
            let p = d.path().join(format!("v{gzip}.nrrd"));
            std::fs::write(&p, nrrd_bytes(&v, VoxelType::U16, gzip).unwrap()).unwrap();
            let back = load_nrrd(&p).unwrap();
            assert_eq!(
                (back.dims, back.spacing, &back.data),
                (v.dims, v.spacing, &v.data)
            );
            assert_eq!(back.info.voxel_type, "ushort");
        }
    }

    #[test]
    fn detached_header_big_endian_skips_and_directions() {
        let d = tempfile::tempdir().unwrap();
        // 2x2x2 signed shorts, big-endian, after 3 junk bytes and one junk line.
        let vals: [i16; 8] = [-1000, 0, 5, 7, 300, -2, 1, 32767];
        let mut data = b"junk line\nabc".to_vec();
        for v in vals {
            data.extend(v.to_be_bytes());
        }
        std::fs::write(d.path().join("v.raw"), &data).unwrap();
        let hdr = "NRRD0005\n# comment\ntype: int16\ndimension: 3\nsizes: 2 2 2\nendian: big\nencoding: raw\n\
                   line skip: 1\nbyte skip: 3\nspace directions: (0.5,0,0) (0,0.5,0) (0,0,1.25)\nspace: RAS\n\
                   units:=mm\ndata file: v.raw\n";
        let p = d.path().join("v.nhdr");
        std::fs::write(&p, hdr).unwrap();
        let v = load_nrrd(&p).unwrap();
        assert_eq!(v.spacing, [0.5, 0.5, 1.25]);
        assert_eq!(v.data, vals.map(|x| x as f32).to_vec());
        // byte skip -1: the last bytes of the file.
        std::fs::write(
            &p,
            hdr.replace("line skip: 1\nbyte skip: 3\n", "byte skip: -1\n"),
        )
        .unwrap();
        assert_eq!(load_nrrd(&p).unwrap().data, vals.map(|x| x as f32).to_vec());
    }

    #[test]
    fn refusals_name_the_problem() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("v.nrrd");
        let base = "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\n\n";
        let err = |hdr: &str, body: &[u8]| {
            let mut b = hdr.as_bytes().to_vec();
            b.extend(body);
            std::fs::write(&p, b).unwrap();
            format!("{:#}", load_nrrd(&p).unwrap_err())
        };
        load_nrrd(&{
            let mut b = base.as_bytes().to_vec();
            b.extend([0u8; 8]);
            std::fs::write(&p, b).unwrap();
            p.clone()
        })
        .unwrap();
        assert!(err(base, &[0; 7]).contains("holds 7 bytes"));
        assert!(err(base, &[0; 9]).contains("holds 9 bytes"));
        assert!(err(&base.replace("raw", "bzip2"), &[0; 8])
            .contains("unsupported NRRD encoding 'bzip2'"));
        assert!(err(&base.replace("raw", "ascii"), &[0; 8])
            .contains("unsupported NRRD encoding 'ascii'"));
        assert!(err(&base.replace("uchar", "int64"), &[0; 64])
            .contains("unsupported NRRD type 'int64'"));
        assert!(
            err(&base.replace("uchar", "block"), &[0; 8]).contains("unsupported NRRD type 'block'")
        );
        assert!(err(&base.replace("uchar", "ushort"), &[0; 16]).contains("no 'endian'"));
        assert!(err(&base.replace("dimension: 3", "dimension: 4"), &[0; 8]).contains("dimension 4"));
        assert!(
            err(&base.replace("2 2 2", "2 0 2"), &[]).contains("size 0 along y is not positive")
        );
        assert!(err(&base.replace("2 2 2", "2 -2 2"), &[]).contains("not positive"));
        assert!(err("NRRD0004\ntype: uchar\n", &[]).contains("no 'dimension'"));
        assert!(err("PNG\n", &[]).contains("not an NRRD file"));
        assert!(err(&base.replace("encoding: raw", "encoding: gzip"), &[0; 8]).contains("gzip"));
        let list = base.replace("encoding: raw\n", "encoding: raw\ndata file: LIST\n");
        assert!(err(&list, b"a.raw\n").contains("list or pattern"));
    }

    #[test]
    fn raw_size_must_match() {
        let d = tempfile::tempdir().unwrap();
        let p = d.path().join("v.raw");
        std::fs::write(&p, [1u8, 0, 2, 0, 3, 0, 4, 0, 5, 0, 6, 0, 7, 0, 8, 1]).unwrap();
        let f16 = RawFormat {
            bits: 16,
            signed: false,
        };
        let v = load_raw(&p, [2, 2, 2], [1.0; 3], f16).unwrap();
        assert_eq!(v.data[7], 264.0);
        let e = load_raw(&p, [2, 2, 3], [1.0; 3], f16)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("is 16 bytes") && e.contains("need 24 bytes"),
            "{e}"
        );
        let v8 = load_raw(
            &p,
            [2, 2, 4],
            [1.0; 3],
            RawFormat {
                bits: 8,
                signed: true,
            },
        )
        .unwrap();
        assert_eq!(v8.data[..2], [1.0, 0.0]);
        assert!(load_raw(&p, [2, 0, 4], [1.0; 3], f16)
            .unwrap_err()
            .to_string()
            .contains("not positive"));
        assert!(load_raw(
            &p,
            [2, 2, 4],
            [1.0; 3],
            RawFormat {
                bits: 12,
                signed: false
            }
        )
        .is_err());
    }
}
