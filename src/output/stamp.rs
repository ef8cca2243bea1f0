//! The stamp file: the record, in every directory rmapgen writes, of each file it wrote there
//! and its SHA-256. It is what lets a later run replace the directory safely: an entry the
//! stamp does not list, or a file whose bytes changed since, was not written by rmapgen.
//!
//! The format is `sha256sum`'s (`<hex digest>  <relative path>`, one file a line, sorted), so a
//! user can check a design with `sha256sum -c .rmapgen-files` inside it.
//!
//! A single output file (`maps --out`, `vectors --out`, `prove --report`, ...) has its record
//! beside it: `.NAME.rmapgen-sha256`, one line in the same format (`sha256sum -c` checks it in
//! that directory). It is what lets a later run replace the file: only a file whose record
//! names it with its current SHA-256 is rmapgen's, unchanged.

use anyhow::{Context, Result};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::io::Read;
use std::path::Path;

/// The stamp's file name, inside the directory it describes.
pub const NAME: &str = ".rmapgen-files";

/// The stamp's largest accepted size: a stamp lists at most a few thousand files, so anything
/// much bigger is not one (and is not read whole into memory).
const MAX_BYTES: u64 = 16 << 20;

/// Relative path ('/'-separated) to hex SHA-256.
pub type Stamp = BTreeMap<String, String>;

/// The record of the single output file `target` ([`record_path`]'s name).
const RECORD_SUFFIX: &str = ".rmapgen-sha256";

/// Where the record of single output file `target` is: `.NAME.rmapgen-sha256` beside it.
pub fn record_path(target: &Path) -> Option<std::path::PathBuf> {
    let name = target.file_name()?.to_string_lossy();
    // Within the file system's name limit, as the staging names are.
    let room = super::NAME_MAX - 1 - RECORD_SUFFIX.len();
    let name = super::shortened(&name, room);
    Some(target.with_file_name(format!(".{name}{RECORD_SUFFIX}")))
}

/// The record's text for a file named `name` with digest `hash`.
pub fn record_text(name: &str, hash: &str) -> String {
    format!("{hash}  {name}\n")
}

/// What the record of `target` holds: Some(Some(hash)) when it is a well-formed record of
/// that file, Some(None) when something else has the record's name, None when nothing has.
pub fn read_record(target: &Path) -> Option<Option<String>> {
    let p = record_path(target)?;
    let meta = std::fs::symlink_metadata(&p).ok()?;
    let name = target.file_name()?.to_string_lossy().into_owned();
    if !meta.is_file() || meta.len() > 4096 {
        return Some(None);
    }
    let text = std::fs::read_to_string(&p).ok();
    Some(text.and_then(|t| {
        let (hash, rest) = t.strip_suffix('\n')?.split_once("  ")?;
        let ok = hash.len() == 64 && hash.bytes().all(|b| b.is_ascii_hexdigit()) && rest == name;
        ok.then(|| hash.to_string())
    }))
}

/// The SHA-256 of a file, as lower-case hex.
pub fn digest(path: &Path) -> Result<String> {
    let mut f =
        std::fs::File::open(path).with_context(|| format!("cannot read {}", path.display()))?;
    let mut h = Sha256::new();
    let mut buf = vec![0u8; 1 << 16];
    loop {
        let n = f
            .read(&mut buf)
            .with_context(|| format!("cannot read {}", path.display()))?;
        if n == 0 {
            break;
        }
        h.update(&buf[..n]);
    }
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
}

/// The stamp of directory `dir`, or None when it has none or it is not a well-formed stamp
/// (then no entry of `dir` counts as written by rmapgen).
pub fn read(dir: &Path) -> Option<Stamp> {
    let p = dir.join(NAME);
    let meta = std::fs::symlink_metadata(&p).ok()?;
    if !meta.is_file() || meta.len() > MAX_BYTES {
        return None;
    }
    let text = std::fs::read_to_string(&p).ok()?;
    let mut stamp = Stamp::new();
    for line in text.lines() {
        let (hash, rel) = line.split_once("  ")?;
        let well_formed = hash.len() == 64
            && hash.bytes().all(|b| b.is_ascii_hexdigit())
            && !rel.is_empty()
            && rel
                .split('/')
                .all(|c| !c.is_empty() && c != "." && c != "..");
        if !well_formed {
            return None;
        }
        stamp.insert(rel.to_string(), hash.to_string());
    }
    Some(stamp)
}

/// Writes the stamp of every file under `dir` (which rmapgen has just written whole).
pub fn write(dir: &Path) -> Result<()> {
    let mut files = Vec::new();
    walk(dir, "", &mut files)?;
    let mut text = String::new();
    for rel in files.iter().filter(|r| r.as_str() != NAME) {
        let hash = digest(&dir.join(rel))?;
        text.push_str(&format!("{hash}  {rel}\n"));
    }
    let p = dir.join(NAME);
    std::fs::write(&p, text).with_context(|| format!("cannot write {}", p.display()))
}

/// Every file under `dir`, relative and '/'-separated, in sorted order.
fn walk(dir: &Path, prefix: &str, out: &mut Vec<String>) -> Result<()> {
    for (name, ty) in sorted_entries(dir)? {
        let rel = format!("{prefix}{name}");
        if ty.is_dir() {
            walk(&dir.join(&name), &format!("{rel}/"), out)?;
        } else {
            out.push(rel);
        }
    }
    Ok(())
}

/// The entries of a directory with their types (symbolic links not followed), sorted by name.
pub fn sorted_entries(dir: &Path) -> Result<Vec<(String, std::fs::FileType)>> {
    let mut v = Vec::new();
    for e in std::fs::read_dir(dir).with_context(|| format!("cannot read {}", dir.display()))? {
        let e = e.with_context(|| format!("cannot read {}", dir.display()))?;
        let ty = e
            .file_type()
            .with_context(|| format!("cannot read {}", e.path().display()))?;
        v.push((e.file_name().to_string_lossy().into_owned(), ty));
    }
    v.sort_by(|a, b| a.0.cmp(&b.0));
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_lists_every_file_with_its_digest() {
        let d = tempfile::tempdir().unwrap();
        std::fs::create_dir(d.path().join("tb")).unwrap();
        std::fs::write(d.path().join("a.v"), "module a;\n").unwrap();
        std::fs::write(d.path().join("tb/b.hex"), "00\n").unwrap();
        write(d.path()).unwrap();
        let s = read(d.path()).expect("a stamp");
        assert_eq!(s.keys().collect::<Vec<_>>(), ["a.v", "tb/b.hex"]);
        // sha256("00\n")
        assert_eq!(
            s["tb/b.hex"],
            "d9b2aefb1febe2dd6e403f634e18917a8c0dd1a440c976e9fe126b465ae9fc8d"
        );
    }

    /// A record is read back as its file's; anything else at the record's name is not one.
    #[test]
    fn a_record_names_its_file_with_its_digest_and_nothing_else_is_a_record() {
        let d = tempfile::tempdir().unwrap();
        let target = d.path().join("maps.hex");
        let rec = record_path(&target).unwrap();
        assert_eq!(rec, d.path().join(".maps.hex.rmapgen-sha256"));
        assert_eq!(read_record(&target), None, "no record yet");
        let hash = "0123456789abcdef".repeat(4);
        std::fs::write(&rec, record_text("maps.hex", &hash)).unwrap();
        assert_eq!(
            std::fs::read_to_string(&rec).unwrap(),
            format!("{hash}  maps.hex\n")
        );
        assert_eq!(read_record(&target), Some(Some(hash.clone())));
        for bad in [
            record_text("other.hex", &hash),
            record_text("maps.hex", &hash[1..]),
            record_text("maps.hex", &format!("{}g", &hash[1..])),
            format!("{hash}  maps.hex"),
            format!("{hash} maps.hex\n"),
        ] {
            std::fs::write(&rec, &bad).unwrap();
            assert_eq!(read_record(&target), Some(None), "{bad:?}");
        }
        // Longer than a record can be, though well-formed at its start.
        let mut long = record_text("maps.hex", &hash).into_bytes();
        long.resize(4097, b'\n');
        std::fs::write(&rec, &long).unwrap();
        assert_eq!(read_record(&target), Some(None));
        std::fs::remove_file(&rec).unwrap();
        std::fs::create_dir(&rec).unwrap();
        assert_eq!(read_record(&target), Some(None), "a directory");
        // A name too long for its record's name is shortened to fit the limit.
        let long_name = "m".repeat(super::super::NAME_MAX);
        let p = record_path(&d.path().join(&long_name)).unwrap();
        let n = p.file_name().unwrap().len();
        assert!(
            n <= super::super::NAME_MAX && n > super::super::NAME_MAX - 8,
            "{n}"
        );
        assert!(p.to_str().unwrap().ends_with(RECORD_SUFFIX));
    }

    /// A stamp is read up to its bound, exactly; one byte more is no stamp.
    #[test]
    fn a_stamp_is_read_up_to_its_bound() {
        let d = tempfile::tempdir().unwrap();
        // Lines of 128 bytes: 64 hex digits, two spaces, a name of 61, a newline.
        let line = |i: u64| format!("{}  {:0>61}\n", "a".repeat(64), i);
        let lines = MAX_BYTES / 128;
        let mut text: String = (0..lines).map(line).collect();
        assert_eq!(text.len() as u64, MAX_BYTES);
        std::fs::write(d.path().join(NAME), &text).unwrap();
        assert_eq!(read(d.path()).map(|s| s.len() as u64), Some(lines));
        // The last name one character longer: still well-formed, one byte over.
        text.pop();
        text.push_str("0\n");
        assert_eq!(text.len() as u64, MAX_BYTES + 1);
        std::fs::write(d.path().join(NAME), &text).unwrap();
        assert!(read(d.path()).is_none());
    }

    /// A stamp written over a directory that holds one does not list itself; a directory at
    /// the stamp's name is no stamp.
    #[test]
    fn a_stamp_does_not_list_itself() {
        let d = tempfile::tempdir().unwrap();
        std::fs::write(d.path().join("a.v"), "x").unwrap();
        write(d.path()).unwrap();
        write(d.path()).unwrap();
        let s = read(d.path()).unwrap();
        assert_eq!(s.keys().collect::<Vec<_>>(), ["a.v"]);
        let e = tempfile::tempdir().unwrap();
        std::fs::create_dir(e.path().join(NAME)).unwrap();
        assert!(read(e.path()).is_none());
    }

    #[test]
    fn a_malformed_stamp_is_no_stamp() {
        let d = tempfile::tempdir().unwrap();
        for bad in [
            "notes about my design\n",
            "abc  a.v\n",
            &format!("{}  ../x\n", "0".repeat(64)),
            &format!("{}  ./x\n", "0".repeat(64)),
            &format!("{}  a//x\n", "0".repeat(64)),
            &format!("{}  \n", "0".repeat(64)),
            &format!("{}  a.v\n", "g".repeat(64)),
            &format!("{}  a.v\n", "0".repeat(63)),
            &format!("{} a.v\n", "0".repeat(64)),
        ] {
            std::fs::write(d.path().join(NAME), bad).unwrap();
            assert!(read(d.path()).is_none(), "{bad:?}");
        }
    }
}
