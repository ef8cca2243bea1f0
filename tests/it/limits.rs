//! Bounded resources (issue 12 §2): a request the machine cannot serve is refused up front
//! with one line (exit 2) and nothing written, never an abort, an endless run or a full disk.
//! Every bound of docs/USAGE.md's "Limits" table has a test here; the NRRD and raw loaders are
//! also fed random and mutated input under a counting allocator (tests/it/alloc.rs).

use crate::alloc::peak_during;
use crate::helpers::{self, assert_error};
use proptest::prelude::*;
use rmapgen::config::Config;
use rmapgen::volume::load::{self, RawFormat, VoxelType};
use rmapgen::volume::{Volume, VolumeInfo, MEMORY_BUDGET};
use std::io::Write;
use std::path::Path;
use std::process::Output;

/// Runs a command that must be refused: exit 2, one line naming the problem, and `dir`
/// holding exactly `before` afterwards (no output, no staging directory, no partial file).
fn refused(args: &[&str], needle: &str, dir: &Path, before: &[&str]) -> Output {
    let out = helpers::run(args);
    assert_error(&out, needle);
    assert_eq!(
        crate::helpers::entries(dir),
        before,
        "left behind by {args:?}"
    );
    out
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// An NRRD header (attached data follows the blank line).
fn header(t: &str, sizes: &str, encoding: &str, extra: &str) -> String {
    format!("NRRD0004\ntype: {t}\ndimension: 3\nsizes: {sizes}\nencoding: {encoding}\nendian: little\n{extra}\n")
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    e.write_all(bytes).unwrap();
    e.finish().unwrap()
}

/// A directory with `in/<name>` holding `bytes`; returns (temp dir, input path).
fn input(name: &str, bytes: &[u8]) -> (tempfile::TempDir, std::path::PathBuf) {
    let d = helpers::tempdir();
    std::fs::create_dir(d.path().join("in")).unwrap();
    let p = d.path().join("in").join(name);
    std::fs::write(&p, bytes).unwrap();
    (d, p)
}

// ---- generate --vectors, fit --vectors: MAX_STAGE_VECTORS ----

#[test]
fn generate_vectors_reported_case_is_refused_before_anything() {
    let d = helpers::tempdir();
    let out = d.path().join("rtl");
    let t = std::time::Instant::now();
    refused(
        &["generate", "--vectors", "1000000000000", "--out", s(&out)],
        "--vectors 1000000000000 is more than the limit of 1000000 random vectors per stage",
        d.path(),
        &[],
    );
    assert!(t.elapsed().as_secs() < 10, "refused up front");
    // One above the bound, too.
    refused(
        &["generate", "--vectors", "1000001", "--out", s(&out)],
        "limit of 1000000",
        d.path(),
        &[],
    );
}

#[test]
fn fit_vectors_is_refused_before_the_search() {
    let d = helpers::tempdir();
    let scene = helpers::root().join("scenes/diffuse.toml");
    refused(
        &[
            "fit",
            "--scene",
            s(&scene),
            "--max-error",
            "16",
            "--vectors",
            "1000001",
            "--out",
            s(&d.path().join("fit")),
        ],
        "--vectors 1000001 is more than the limit of 1000000",
        d.path(),
        &[],
    );
}

// ---- vectors --count: MAX_STREAM_VECTORS and the free space ----

#[test]
fn vectors_count_reported_case_is_refused() {
    let d = helpers::tempdir();
    refused(
        &[
            "vectors",
            "--count",
            "18446744073709551615",
            "--out",
            s(&d.path().join("v.hex")),
        ],
        "--count 18446744073709551615 is more than the limit of 10000000000 vectors",
        d.path(),
        &[],
    );
    refused(
        &[
            "vectors",
            "--count",
            "10000000001",
            "--out",
            s(&d.path().join("v.hex")),
        ],
        "limit of 10000000000",
        d.path(),
        &[],
    );
}

#[test]
fn vectors_count_that_does_not_fit_the_disk_is_refused_with_both_sizes() {
    let d = helpers::tempdir();
    let cfg = Config {
        grad_bits: 16,
        color: true,
        ..Config::default()
    };
    let count = rmapgen::vectors::MAX_STREAM_VECTORS;
    let need = rmapgen::vectors::top_stream_bytes(&cfg, count);
    let have = rmapgen::disk::available_space(d.path()).unwrap();
    assert!(
        need > have,
        "this test needs a temp filesystem with less than {need} bytes free (it has {have})"
    );
    let out = refused(
        &[
            "vectors",
            "--grad-bits",
            "16",
            "--color",
            "--count",
            &count.to_string(),
            "--out",
            s(&d.path().join("v.hex")),
        ],
        "needs ",
        d.path(),
        &[],
    );
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains(&rmapgen::volume::human_bytes(need)) && err.contains("available"),
        "{err}"
    );
}

#[test]
fn vector_stream_size_estimate_is_exact() {
    // The free-space check is only as good as the size it checks.
    let d = helpers::tempdir();
    for (flags, cfg) in [
        (vec![], Config::default()),
        (
            vec!["--grad-bits", "16", "--color"],
            Config {
                grad_bits: 16,
                color: true,
                ..Config::default()
            },
        ),
    ] {
        let p = d.path().join("v.hex");
        let mut args = vec!["vectors", "--count", "777", "--out", s(&p)];
        args.extend(flags);
        let out = helpers::run(&args);
        assert!(out.status.success(), "{out:?}");
        let len = std::fs::metadata(&p).unwrap().len();
        assert_eq!(len, rmapgen::vectors::top_stream_bytes(&cfg, 777));
    }
}

// ---- stress --samples: 1..=MAX_SAMPLES ----

#[test]
fn stress_samples_reported_cases_are_refused() {
    let d = helpers::tempdir();
    let json = d.path().join("r.json");
    for (n, needle) in [
        (
            "18446744073709551615",
            "--samples 18446744073709551615 is more than the limit of 137438953472",
        ),
        ("137438953473", "limit of 137438953472"),
        ("0", "--samples 0 checks nothing"),
    ] {
        let t = std::time::Instant::now();
        refused(
            &["stress", "--samples", n, "--json", s(&json)],
            needle,
            d.path(),
            &[],
        );
        assert!(t.elapsed().as_secs() < 10, "refused up front");
    }
}

// ---- volumes: MEMORY_BUDGET / MAX_VOXELS, MAX_READ_BYTES, MAX_HEADER_BYTES ----

fn volume_refused(input: &Path, extra: &[&str], needle: &str, dir: &Path) {
    let mut args = vec!["volume", s(input)];
    args.extend(extra);
    let out = dir.join("out");
    args.extend(["--out", s(&out)]);
    refused(&args, needle, dir, &["in"]);
}

#[test]
fn gzip_nrrd_with_a_huge_byte_skip_is_refused_up_front() {
    let body = gzip(&[0u8; 64]);
    let mut b = header("uchar", "4 4 4", "gzip", "byte skip: 9000000000000000000\n").into_bytes();
    b.extend(&body);
    let (d, p) = input("v.nrrd", &b);
    volume_refused(&p, &[], "more than the read limit of 4.0 GiB", d.path());
    // Just over the limit with the voxel data counted too.
    let skip = rmapgen::volume::load::MAX_READ_BYTES - 63;
    let mut b = header("uchar", "4 4 4", "gzip", &format!("byte skip: {skip}\n")).into_bytes();
    b.extend(&body);
    std::fs::write(&p, b).unwrap();
    volume_refused(&p, &[], "read limit", d.path());
    // A detached header (raw data in a file of its own) is held to the same limit.
    std::fs::write(d.path().join("in/v.raw"), [0u8; 64]).unwrap();
    let nhdr = d.path().join("in/v.nhdr");
    std::fs::write(
        &nhdr,
        header(
            "uchar",
            "4 4 4",
            "raw",
            "byte skip: 9000000000000000000\ndata file: v.raw\n",
        ),
    )
    .unwrap();
    volume_refused(&nhdr, &[], "more than the read limit of 4.0 GiB", d.path());
}

#[test]
fn gzip_nrrd_of_doubles_over_the_memory_budget_is_refused_with_the_size_needed() {
    // 2^28 doubles: inside the old voxel limit, 2 MB of gzip, 2.5 GiB to render.
    let body = gzip(&vec![0u8; 2 << 20]);
    let mut b = header("double", "1024 1024 256", "gzip", "").into_bytes();
    b.extend(&body);
    let (d, p) = input("v.nrrd", &b);
    volume_refused(
        &p,
        &[],
        "1024 x 1024 x 256 voxels need 2.5 GiB (10 bytes a voxel for values and gradients), more than the limit of 2.0 GiB",
        d.path(),
    );
}

#[test]
fn raw_and_synthetic_dims_over_the_memory_budget_are_refused() {
    let (d, p) = input("v.raw", &[0u8; 64]);
    volume_refused(
        &p,
        &["--dims", "1024,1024,256", "--bits", "16"],
        "need 2.5 GiB",
        d.path(),
    );
    let out = d.path().join("out");
    refused(
        &[
            "volume",
            "--synthetic",
            "--dims",
            "2048,2048,2048",
            "--out",
            s(&out),
        ],
        "need 80.0 GiB",
        d.path(),
        &["in"],
    );
}

#[test]
fn overflowing_double_voxel_is_named_as_an_overflow() {
    let mut b = header("double", "2 2 2", "raw", "").into_bytes();
    for i in 0..8 {
        let v = if i == 5 { 1e300 } else { i as f64 };
        b.extend(v.to_le_bytes());
    }
    let (d, p) = input("v.nrrd", &b);
    volume_refused(
        &p,
        &[],
        "voxel (1, 0, 1) value 1e300 overflows f32",
        d.path(),
    );
    // The same through gzip, big-endian.
    let mut b = header("double", "2 2 2", "gzip", "")
        .replace("little", "big")
        .into_bytes();
    let mut raw = Vec::new();
    for i in 0..8 {
        let v = if i == 2 { -1e39 } else { 0.0f64 };
        raw.extend(v.to_be_bytes());
    }
    b.extend(gzip(&raw));
    std::fs::write(&p, b).unwrap();
    volume_refused(
        &p,
        &[],
        "voxel (0, 1, 0) value -1e39 overflows f32",
        d.path(),
    );
    // A real non-finite value is still called non-finite.
    let mut b = header("double", "2 2 2", "raw", "").into_bytes();
    for i in 0..8 {
        b.extend((if i == 3 { f64::NAN } else { 0.0 }).to_le_bytes());
    }
    std::fs::write(&p, b).unwrap();
    volume_refused(&p, &[], "non-finite", d.path());
}

#[test]
fn a_directory_is_not_a_volume_file() {
    let d = helpers::tempdir();
    std::fs::create_dir(d.path().join("in")).unwrap();
    let dir = d.path().join("in");
    volume_refused(&dir, &[], "is a directory, not a volume file", d.path());
    volume_refused(
        &dir,
        &["--dims", "2,2,2"],
        "is a directory, not a volume file",
        d.path(),
    );
    std::fs::create_dir(dir.join("scan.nrrd")).unwrap();
    let out = d.path().join("out");
    let nrrd = dir.join("scan.nrrd");
    let o = helpers::run(&["volume", s(&nrrd), "--out", s(&out)]);
    assert_error(&o, "scan.nrrd is a directory, not a volume file");
    // A detached header whose data file is a directory.
    std::fs::remove_dir(&nrrd).unwrap();
    std::fs::create_dir(dir.join("data")).unwrap();
    let nhdr = dir.join("v.nhdr");
    std::fs::write(&nhdr, header("uchar", "2 2 2", "raw", "data file: data\n")).unwrap();
    let o = helpers::run(&["volume", s(&nhdr), "--out", s(&out)]);
    assert_error(&o, "is a directory, not a data file");
    assert_eq!(crate::helpers::entries(d.path()), ["in"]);
}

#[test]
fn an_endless_header_is_refused() {
    let mut b = b"NRRD0004\ntype: uchar\ndimension: 3\n".to_vec();
    while b.len() <= load::MAX_HEADER_BYTES + 10 {
        b.extend(b"# padding padding padding padding padding padding padding\n");
    }
    let (d, p) = input("v.nrrd", &b);
    volume_refused(
        &p,
        &[],
        "header is longer than the limit of 1.0 MiB",
        d.path(),
    );
}

// ---- image and run sizes of the other commands ----

#[test]
fn size_and_count_flags_of_every_command_are_bounded() {
    let d = helpers::tempdir();
    let out = d.path().join("o");
    let o = s(&out);
    let scene = helpers::root().join("scenes/diffuse.toml");
    let sc = s(&scene);
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["render", "--size", "4097", "--out", o],
            "allowed 1..=4096",
        ),
        (
            vec!["render", "--shrink", "12", "--out", o],
            "allowed 0..=11",
        ),
        (
            vec!["volume", "--synthetic", "--size", "4097", "--out", o],
            "allowed 1..=4096",
        ),
        (
            vec!["volume", "--synthetic", "--step", "0.01", "--out", o],
            "allowed 0.05..=4",
        ),
        (
            vec!["volume", "--synthetic", "--brick", "128", "--out", o],
            "2..=64",
        ),
        (
            vec![
                "volume",
                "--synthetic",
                "--repeat",
                "101",
                "--timing",
                "--out",
                o,
            ],
            "--repeat 101 is more than the limit of 100",
        ),
        (
            vec!["bench", "--size", "4097", "--out", o],
            "allowed 16..=4096",
        ),
        (
            vec!["bench", "--seconds", "61", "--out", o],
            "allowed (0, 60]",
        ),
        (
            vec![
                "fit",
                "--scene",
                sc,
                "--max-error",
                "16",
                "--size",
                "4097",
                "--out",
                o,
            ],
            "allowed 16..=4096",
        ),
        (
            vec![
                "fit",
                "--scene",
                sc,
                "--max-error",
                "16",
                "--runners-up",
                "18446744073709551615",
                "--out",
                o,
            ],
            "allowed 0..=100",
        ),
        (
            vec![
                "fit",
                "--scene",
                sc,
                "--max-error",
                "16",
                "--synth-limit",
                "65",
                "--out",
                o,
            ],
            "allowed 1..=64",
        ),
    ];
    let cases = cases.into_iter().chain([
        (
            vec!["fpga", "--freq", "1001", "--logs", o],
            "allowed (0, 1000] MHz",
        ),
        (
            vec!["fpga", "--freq", "0", "--logs", o],
            "--freq must be a positive number, not 0",
        ),
        (
            vec!["fpga", "--freq", "NaN", "--logs", o],
            "--freq must be a positive number",
        ),
    ]);
    for (args, needle) in cases {
        let t = std::time::Instant::now();
        refused(&args, needle, d.path(), &[]);
        assert!(t.elapsed().as_secs() < 20, "{args:?} refused up front");
    }
}

// ---- memory of the loaders, measured ----

fn write(dir: &Path, name: &str, bytes: &[u8]) -> std::path::PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, bytes).unwrap();
    p
}

#[test]
fn a_gzip_byte_skip_is_streamed_not_held() {
    // 256 MiB of skipped zeros before 8 voxels: the old loader held all of it.
    let d = helpers::tempdir();
    let skip = 256usize << 20;
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    let zeros = vec![0u8; 1 << 20];
    for _ in 0..skip >> 20 {
        e.write_all(&zeros).unwrap();
    }
    e.write_all(&[1, 2, 3, 4, 5, 6, 7, 8]).unwrap();
    let mut b = header("uchar", "2 2 2", "gzip", &format!("byte skip: {skip}\n")).into_bytes();
    b.extend(e.finish().unwrap());
    let p = write(d.path(), "v.nrrd", &b);
    let (v, peak) = peak_during(|| load::load_nrrd(&p));
    assert_eq!(v.unwrap().data, [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0]);
    assert!(peak < 8 << 20, "peak {peak} bytes for a 256 MiB byte skip");
}

#[test]
fn doubles_are_decoded_in_chunks() {
    // 2 M doubles (16 MiB of voxel data): the old loader held the data and the f32 values
    // (24 MiB); now only the values (8 MiB) and a chunk are held.
    let d = helpers::tempdir();
    let n = 128 * 128 * 128;
    let mut raw = Vec::with_capacity(8 * n);
    for i in 0..n {
        raw.extend(((i % 1000) as f64).to_le_bytes());
    }
    for gz in [false, true] {
        let mut b =
            header("double", "128 128 128", if gz { "gzip" } else { "raw" }, "").into_bytes();
        b.extend(if gz { gzip(&raw) } else { raw.clone() });
        let p = write(d.path(), "v.nrrd", &b);
        drop(b);
        let (v, peak) = peak_during(|| load::load_nrrd(&p));
        let v = v.unwrap();
        assert_eq!(v.data[1234], 234.0);
        // The values (4n), at most one doubling of them while a gzip stream grows (counted
        // as old and new block side by side), a chunk: below the old loader's 24 MiB.
        assert!(
            peak < 6 * n + (4 << 20),
            "gzip {gz}: peak {peak} bytes for {} bytes of values",
            4 * n
        );
    }
    // Raw files too: 16-bit, 2 M voxels.
    let raw16: Vec<u8> = (0..n).flat_map(|i| (i as u16).to_le_bytes()).collect();
    let p = write(d.path(), "v.raw", &raw16);
    let f16 = RawFormat {
        bits: 16,
        signed: false,
    };
    let (v, peak) = peak_during(|| load::load_raw(&p, [128, 128, 128], [1.0; 3], f16));
    assert_eq!(v.unwrap().data[n - 1], (n - 1) as u16 as f32);
    assert!(peak < 4 * n + (2 << 20), "raw: peak {peak}");
}

#[test]
fn a_small_gzip_file_claiming_many_voxels_allocates_little() {
    // 100 M voxels claimed (inside the budget), 64 bytes of data present.
    let d = helpers::tempdir();
    let mut b = header("uchar", "1000 1000 100", "gzip", "").into_bytes();
    b.extend(gzip(&[7u8; 64]));
    let p = write(d.path(), "v.nrrd", &b);
    let (r, peak) = peak_during(|| load::load_nrrd(&p));
    let e = format!("{:#}", r.unwrap_err());
    assert!(e.contains("holds 64 bytes"), "{e}");
    assert!(peak < 8 << 20, "peak {peak} bytes");
}

// ---- property tests: never a panic, never beyond the budget ----

/// The budget every load must stay inside, with a margin for buffers.
const LOAD_LIMIT: usize = MEMORY_BUDGET as usize + (16 << 20);

fn small_volume() -> Volume {
    let data = (0..4 * 3 * 2).map(|i| (i * 37 % 251) as f32).collect();
    Volume::new(
        [4, 3, 2],
        [1.0, 0.5, 2.0],
        data,
        VolumeInfo {
            source: "t".into(),
            voxel_type: "uchar".into(),
        },
    )
    .unwrap()
}

/// Loads `bytes` as an NRRD file (and, when they parse, checks what came back), measuring
/// the peak; panics propagate to proptest.
fn load_bytes(dir: &Path, name: &str, bytes: &[u8]) -> (Result<Volume, String>, usize) {
    let p = write(dir, name, bytes);
    let (r, peak) = peak_during(|| load::load_nrrd(&p));
    (r.map_err(|e| format!("{e:#}")), peak)
}

fn check(r: &Result<Volume, String>, peak: usize) -> Result<(), TestCaseError> {
    prop_assert!(peak < LOAD_LIMIT, "peak {peak} bytes");
    match r {
        Ok(v) => {
            prop_assert_eq!(v.data.len(), v.dims.iter().product::<usize>());
            prop_assert!(v.data.iter().all(|x| x.is_finite()));
        }
        Err(e) => {
            prop_assert!(!e.is_empty() && !e.contains('\n'), "one line: {e:?}");
        }
    }
    Ok(())
}

/// A header field value: sensible, huge, negative or nonsense.
fn number() -> impl Strategy<Value = String> {
    prop_oneof![
        (0i64..6).prop_map(|n| n.to_string()),
        any::<i64>().prop_map(|n| n.to_string()),
        Just(i64::MAX.to_string()),
        Just("18446744073709551616".to_string()),
        Just("4294967296".to_string()),
        Just("-1".to_string()),
        Just("1e3".to_string()),
        Just(String::new()),
    ]
}

fn float() -> impl Strategy<Value = String> {
    prop_oneof![
        Just("1".to_string()),
        Just("0".to_string()),
        Just("1e308".to_string()),
        Just("-1e-320".to_string()),
        Just("nan".to_string()),
        Just("inf".to_string()),
        any::<f64>().prop_map(|f| f.to_string()),
        Just("x".to_string()),
    ]
}

/// A header built from fields, each valid or mutated, with a body.
fn mutated_header() -> impl Strategy<Value = Vec<u8>> {
    let types = prop::sample::select(vec![
        "uchar",
        "signed char",
        "short",
        "ushort",
        "int",
        "uint",
        "float",
        "double",
        "int64",
        "block",
        "",
    ]);
    let encodings = prop::sample::select(vec!["raw", "gzip", "gz", "ascii", "bzip2", "hex", ""]);
    let endians = prop::sample::select(vec!["little", "big", "middle", ""]);
    (
        types,
        prop::collection::vec(number(), 0..5),
        encodings,
        endians,
        prop::option::of(number()),
        prop::option::of(number()),
        prop::option::of(prop::collection::vec(float(), 0..10)),
        prop::option::of(prop::collection::vec(float(), 0..4)),
        prop::collection::vec(any::<u8>(), 0..300),
        any::<bool>(),
    )
        .prop_map(
            |(t, sizes, enc, endian, byte_skip, line_skip, dirs, spacings, body, gz)| {
                let mut h = format!(
                    "NRRD0004\ntype: {t}\ndimension: 3\nsizes: {}\nencoding: {enc}\nendian: {endian}\n",
                    sizes.join(" ")
                );
                if let Some(b) = byte_skip {
                    h += &format!("byte skip: {b}\n");
                }
                if let Some(l) = line_skip {
                    h += &format!("line skip: {l}\n");
                }
                if let Some(d) = dirs {
                    let v: Vec<String> = d
                        .chunks(3)
                        .map(|c| format!("({})", c.join(",")))
                        .collect();
                    h += &format!("space directions: {}\n", v.join(" "));
                }
                if let Some(sp) = spacings {
                    h += &format!("spacings: {}\n", sp.join(" "));
                }
                h.push('\n');
                let mut b = h.into_bytes();
                b.extend(if gz { gzip(&body) } else { body });
                b
            },
        )
}

/// Byte-level damage: flip, insert or delete bytes at random places.
#[derive(Clone, Debug)]
enum Edit {
    Flip(usize, u8),
    Insert(usize, Vec<u8>),
    Delete(usize, usize),
}

fn edits() -> impl Strategy<Value = Vec<Edit>> {
    prop::collection::vec(
        prop_oneof![
            (any::<usize>(), 1u8..=255).prop_map(|(i, m)| Edit::Flip(i, m)),
            (
                any::<usize>(),
                prop_oneof![
                    prop::collection::vec(any::<u8>(), 1..8),
                    Just(b"\n".to_vec()),
                    Just(b"99999999999999999999".to_vec()),
                    Just(b"\nbyte skip: 4000000000\n".to_vec()),
                    Just(b"\nline skip: 9223372036854775807\n".to_vec()),
                ]
            )
                .prop_map(|(i, b)| Edit::Insert(i, b)),
            (any::<usize>(), 1usize..16).prop_map(|(i, n)| Edit::Delete(i, n)),
        ],
        0..6,
    )
}

fn apply(mut b: Vec<u8>, edits: &[Edit]) -> Vec<u8> {
    for e in edits {
        match e {
            Edit::Flip(i, m) if !b.is_empty() => {
                let i = i % b.len();
                b[i] ^= m;
            }
            Edit::Insert(i, x) => {
                let i = i % (b.len() + 1);
                b.splice(i..i, x.iter().copied());
            }
            Edit::Delete(i, n) if !b.is_empty() => {
                let i = i % b.len();
                let end = (i + n).min(b.len());
                b.drain(i..end);
            }
            _ => {}
        }
    }
    b
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn random_bytes_never_panic(
        prefix in prop::sample::select(vec!["", "NRRD0004\n", "NRRD0005\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: gzip\n\n"]),
        bytes in prop::collection::vec(any::<u8>(), 0..600),
    ) {
        let d = helpers::tempdir();
        let mut b = prefix.as_bytes().to_vec();
        b.extend(bytes);
        let (r, peak) = load_bytes(d.path(), "v.nrrd", &b);
        check(&r, peak)?;
        prop_assert!(load::parse_header(&b, "t").is_ok() || r.is_err());
    }

    #[test]
    fn mutated_headers_never_panic(b in mutated_header(), e in edits()) {
        let d = helpers::tempdir();
        let b = apply(b, &e);
        let (r, peak) = load_bytes(d.path(), "v.nrrd", &b);
        check(&r, peak)?;
        // Detached: the same header with its data in a file of its own.
        let (r, peak) = load_bytes(d.path(), "v.nhdr", &apply(b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 2 2\nencoding: raw\ndata file: v.nrrd\n".to_vec(), &e));
        check(&r, peak)?;
    }

    #[test]
    fn mutated_valid_files_never_panic(gz in any::<bool>(), t in prop::sample::select(vec![VoxelType::U8, VoxelType::I16, VoxelType::F32, VoxelType::F64]), e in edits()) {
        let d = helpers::tempdir();
        let v = small_volume();
        let good = load::nrrd_bytes(&v, t, gz).unwrap();
        if e.is_empty() {
            let (r, _) = load_bytes(d.path(), "v.nrrd", &good);
            prop_assert_eq!(r.unwrap().data, v.data.clone());
        }
        let (r, peak) = load_bytes(d.path(), "v.nrrd", &apply(good, &e));
        check(&r, peak)?;
    }

    #[test]
    fn raw_files_never_panic(
        dims in prop::array::uniform3(prop_oneof![-3i64..6, Just(i64::MAX), Just(1i64 << 31), any::<i64>()]),
        bits in prop::sample::select(vec![8u32, 16, 12, 0]),
        signed in any::<bool>(),
        len in 0usize..400,
    ) {
        let d = helpers::tempdir();
        let p = write(d.path(), "v.raw", &vec![3u8; len]);
        let (r, peak) = peak_during(|| load::load_raw(&p, dims, [1.0; 3], RawFormat { bits, signed }));
        check(&r.map_err(|e| format!("{e:#}")), peak)?;
    }
}

#[test]
fn usage_limits_table_quotes_the_constants() {
    let usage = std::fs::read_to_string(helpers::root().join("docs/USAGE.md")).unwrap();
    let table = usage
        .split("## Limits")
        .nth(1)
        .expect("docs/USAGE.md has a Limits section")
        .split("\n## ")
        .next()
        .unwrap();
    let max = rmapgen::render::MAX_SIZE;
    for want in [
        format!("`0..={}` per stage", rmapgen::vectors::MAX_STAGE_VECTORS),
        format!("`0..={}`", rmapgen::vectors::MAX_STREAM_VECTORS),
        format!("`1..={}` (2^37)", rmapgen::stress::MAX_SAMPLES),
        format!("`<= {}`", rmapgen::stress::exhaustive::MAX_GRAD_BITS),
        format!("`1..={max}`"),
        format!("`{}..={max}`", rmapgen::cmd::bench::MIN_SIZE),
        format!("`{}..={max}`", rmapgen::cmd::fit::MIN_SIZE),
        format!("`(0, {}]`", rmapgen::cmd::bench::MAX_SECONDS),
        format!("`0..={}`", rmapgen::cmd::fit::MAX_RUNNERS_UP),
        format!("`1..={}`", rmapgen::cmd::fit::MAX_SYNTH_LIMIT),
        format!("`{}` voxels", rmapgen::volume::MAX_VOXELS),
        format!(
            "`{}` pixels a side, `{}` decoded",
            rmapgen::cmd::compare::MAX_SIDE,
            rmapgen::volume::human_bytes(rmapgen::cmd::compare::MAX_ALLOC).replace(".0", "")
        ),
        format!(
            "`{}`",
            rmapgen::volume::human_bytes(rmapgen::volume::load::MAX_READ_BYTES).replace(".0", "")
        ),
        format!(
            "`{}`",
            rmapgen::volume::human_bytes(rmapgen::volume::load::MAX_HEADER_BYTES as u64)
                .replace(".0", "")
        ),
        format!(
            "`{}..={}` voxels",
            rmapgen::volume::cast::options::MIN_STEP,
            rmapgen::volume::cast::options::MAX_STEP
        ),
        format!("`2..={}`", rmapgen::volume::cast::options::MAX_BRICK),
        format!("`(0, {}]`", rmapgen::volume::cast::options::MAX_ZOOM),
        format!("`1..={}`", rmapgen::cmd::volume::MAX_REPEAT),
        format!("`(0, {}]` MHz", rmapgen::cmd::fpga::MAX_FREQ_MHZ),
        format!("`{}` bytes each", rmapgen::vectors::MAX_MAP_FILE_BYTES),
        format!("`{}` bytes | a configuration", rmapgen::explore::MAX_BODY),
        format!(
            "`{}..={}` pixels, `{}` lights",
            rmapgen::explore::MIN_SIZE,
            rmapgen::explore::MAX_SIZE,
            rmapgen::explore::MAX_LIGHTS
        ),
        format!("the last `{}`", rmapgen::explore::KEPT),
        format!(
            "a head of `{}` bytes, `{}` connections at once, `{}` s",
            rmapgen::explore::http::MAX_HEAD,
            rmapgen::explore::http::MAX_CONNECTIONS,
            rmapgen::explore::http::REQUEST_DEADLINE.as_secs()
        ),
        format!(
            "predicted at most `{}` core-seconds and `{}` MiB; cancelled past `{}` s or `{}` MiB",
            rmapgen::explore::cost::CORE_SECONDS,
            rmapgen::explore::cost::BYTES >> 20,
            rmapgen::explore::LIMITS.seconds.as_secs(),
            rmapgen::explore::LIMITS.memory >> 20
        ),
    ] {
        assert!(
            table.contains(&want),
            "docs/USAGE.md's Limits table should quote {want}"
        );
    }
    assert!(table.contains(&format!(
        "{} at the bound",
        rmapgen::volume::human_bytes(rmapgen::volume::MEMORY_BUDGET).replace(".0", "")
    )));
}

#[test]
fn an_oversized_or_directory_map_file_is_refused() {
    let d = helpers::tempdir();
    let maps = d.path().join("maps");
    std::fs::create_dir(&maps).unwrap();
    let f = std::fs::File::create(maps.join("map_x.hex")).unwrap();
    f.set_len(rmapgen::vectors::MAX_MAP_FILE_BYTES + 1).unwrap();
    let v = d.path().join("v.hex");
    refused(
        &[
            "vectors",
            "--maps",
            s(&maps),
            "--count",
            "10",
            "--out",
            s(&v),
        ],
        "more than the limit of 16777216",
        d.path(),
        &["maps"],
    );
    std::fs::remove_file(maps.join("map_x.hex")).unwrap();
    std::fs::create_dir(maps.join("map_x.hex")).unwrap();
    refused(
        &[
            "vectors",
            "--maps",
            s(&maps),
            "--count",
            "10",
            "--out",
            s(&v),
        ],
        "is a directory, not a map file",
        d.path(),
        &["maps"],
    );
}

/// A file at a single output's record name (`.NAME.rmapgen-sha256`) or at a directory's stamp
/// name (`.rmapgen-files`) is judged from its size before it is read: one larger than such a
/// file can be is "not rmapgen's" without being read into memory (a 64 MiB sparse file, under
/// the counting allocator).
#[test]
fn a_large_file_at_a_record_or_stamp_name_is_not_read() {
    use rmapgen::output::stamp;
    let d = helpers::tempdir();
    let target = d.path().join("maps.hex");
    let rec = stamp::record_path(&target).unwrap();
    std::fs::File::create(&rec)
        .unwrap()
        .set_len(64 << 20)
        .unwrap();
    let (r, peak) = peak_during(|| stamp::read_record(&target));
    assert_eq!(r, Some(None), "a 64 MiB file is not a record");
    assert!(peak < 1 << 20, "read_record allocated {peak} bytes");
    std::fs::File::create(d.path().join(stamp::NAME))
        .unwrap()
        .set_len(64 << 20)
        .unwrap();
    let (r, peak) = peak_during(|| stamp::read(d.path()));
    assert!(r.is_none(), "a 64 MiB file is not a stamp");
    assert!(peak < 1 << 20, "stamp::read allocated {peak} bytes");
}
