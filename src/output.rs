//! Output directories that appear whole or not at all: everything is written into a staging
//! directory beside the target, which replaces the target only when the command succeeds.
//! A failing command leaves the target as it was and removes the staging directory.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};

pub struct StagedDir {
    target: PathBuf,
    staging: PathBuf,
    done: bool,
}

impl StagedDir {
    /// Starts writing `target`. Fails at once (before any work) if its parent is not writable.
    pub fn new(target: &Path) -> Result<StagedDir> {
        let name = target
            .file_name()
            .with_context(|| format!("output path {} has no directory name", target.display()))?
            .to_string_lossy()
            .into_owned();
        let parent = match target.parent() {
            Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if target.exists() && !target.is_dir() {
            anyhow::bail!(
                "output path {} exists and is not a directory",
                target.display()
            );
        }
        let staging = parent.join(format!(".{name}.staging-{}", std::process::id()));
        if staging.exists() {
            std::fs::remove_dir_all(&staging).ok();
        }
        std::fs::create_dir_all(&staging)
            .with_context(|| format!("cannot write output directory {}", target.display()))?;
        Ok(StagedDir {
            target: target.to_path_buf(),
            staging,
            done: false,
        })
    }

    /// Where to write files now.
    pub fn path(&self) -> &Path {
        &self.staging
    }

    /// Writes one file (relative path; parents created), adding a final newline if missing.
    pub fn write_text(&self, rel: &str, text: &str) -> Result<()> {
        let mut t = text.to_string();
        if !t.ends_with('\n') {
            t.push('\n');
        }
        self.write_bytes(rel, t.as_bytes())
    }

    pub fn write_bytes(&self, rel: &str, bytes: &[u8]) -> Result<()> {
        let p = self.staging.join(rel);
        if let Some(d) = p.parent() {
            std::fs::create_dir_all(d).with_context(|| format!("cannot create {}", d.display()))?;
        }
        std::fs::write(&p, bytes).with_context(|| format!("cannot write {}", p.display()))
    }

    /// Replaces the target with the staging directory.
    pub fn commit(mut self) -> Result<PathBuf> {
        let old = self.staging.with_extension("old");
        if self.target.exists() {
            std::fs::rename(&self.target, &old)
                .with_context(|| format!("cannot replace {}", self.target.display()))?;
        }
        std::fs::rename(&self.staging, &self.target)
            .with_context(|| format!("cannot move output into {}", self.target.display()))?;
        if old.exists() {
            std::fs::remove_dir_all(&old).ok();
        }
        self.done = true;
        Ok(self.target.clone())
    }
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if !self.done {
            std::fs::remove_dir_all(&self.staging).ok();
        }
    }
}
