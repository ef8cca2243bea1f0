//! Free space of a filesystem, checked before a large file is written.

use anyhow::{bail, Context, Result};
use std::path::Path;

/// Bytes available to an unprivileged writer on the filesystem that holds `path`, or that
/// would hold it: the nearest existing ancestor is asked when `path` does not exist yet.
pub fn available_space(path: &Path) -> Result<u64> {
    let mut p = if path.as_os_str().is_empty() {
        Path::new(".")
    } else {
        path
    };
    while !p.exists() {
        p = match p.parent() {
            Some(q) if !q.as_os_str().is_empty() => q,
            _ if p != Path::new(".") => Path::new("."),
            _ => bail!("cannot find the filesystem of {}", path.display()),
        };
    }
    let st = rustix::fs::statvfs(p)
        .with_context(|| format!("cannot read the free space of {}", p.display()))?;
    Ok(st.f_bavail.saturating_mul(st.f_frsize))
}

/// Refuses a write of `need` bytes into `dir` when its filesystem has less space available,
/// naming both sizes; `what` names the file.
pub fn check_space(dir: &Path, need: u64, what: &str) -> Result<()> {
    let have = available_space(dir)?;
    if need > have {
        bail!(
            "{what} needs {} but the filesystem of {} has {} available",
            crate::volume::human_bytes(need),
            if dir.as_os_str().is_empty() {
                ".".to_string()
            } else {
                dir.display().to_string()
            },
            crate::volume::human_bytes(have)
        );
    }
    Ok(())
}

/// `std::fs::write` whose error names the file (a bare `Read-only file system (os error
/// 30)` says nothing of where).
pub fn write(path: &Path, bytes: impl AsRef<[u8]>) -> Result<()> {
    std::fs::write(path, bytes).with_context(|| format!("cannot write {}", path.display()))
}

/// `std::fs::create_dir_all` whose error names the directory.
pub fn create_dir_all(path: &Path) -> Result<()> {
    std::fs::create_dir_all(path).with_context(|| format!("cannot create {}", path.display()))
}
