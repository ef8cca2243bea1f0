//! What an output may replace. rmapgen replaces a directory only when everything in it is
//! what rmapgen wrote there (its stamp lists the file and the bytes are unchanged), or the user
//! said `--force`. Never, not even forced, does it replace the current directory or one of its
//! ancestors, or a directory holding one of the command's inputs that rmapgen did not write.
//! A single output file follows the same rule: it replaces only a file that rmapgen wrote and
//! nobody changed since (its record beside it, [`stamp::record_path`], names it with its
//! SHA-256), unless forced, and never an input.

use super::stamp::{self, Stamp};
use anyhow::{bail, Context, Result};
use std::path::{Component, Path, PathBuf};

/// The rules for one command's outputs: whether the user forced replacement, and the inputs
/// the command reads (made absolute, so they compare with any spelling of the output path).
#[derive(Debug, Clone, Default)]
pub struct Policy {
    force: bool,
    inputs: Vec<PathBuf>,
}

/// Why an entry of an existing output directory keeps it from being replaced.
enum Foreign {
    NotWritten(String),
    Changed(String),
}

impl Policy {
    /// No inputs yet; `force` as the user gave it.
    pub fn new(force: bool) -> Policy {
        Policy {
            force,
            inputs: Vec::new(),
        }
    }

    /// Adds an input file or directory the command reads (if given).
    pub fn input(mut self, path: Option<&Path>) -> Policy {
        if let Some(p) = path {
            self.inputs.push(absolute(p));
        }
        self
    }

    /// Checks that directory `target` may be replaced by a new output (or created).
    pub fn check_dir(&self, target: &Path) -> Result<()> {
        let shown = target.display();
        if target.file_name().is_none() {
            bail!("output path {shown} has no directory name");
        }
        let meta = std::fs::symlink_metadata(target).ok();
        if let Some(m) = &meta {
            if m.file_type().is_symlink() {
                bail!("output directory {shown} is a symbolic link; give the directory itself");
            }
            if !m.is_dir() {
                bail!("output path {shown} exists and is not a directory");
            }
        }
        let abs = absolute(target);
        if let Ok(cwd) = std::env::current_dir().and_then(|c| c.canonicalize()) {
            if cwd.starts_with(&abs) {
                bail!(
                    "will not replace {shown}: it is the current directory or holds it \
                     (not even with --force); give a new or rmapgen-written directory"
                );
            }
        }
        if meta.is_none() {
            return Ok(());
        }
        let stamp = stamp::read(&abs);
        for input in &self.inputs {
            let Ok(rel) = input.strip_prefix(&abs) else {
                continue;
            };
            let rel = slash_path(rel);
            let written = stamp.as_ref().is_some_and(|s| {
                s.contains_key(&rel)
                    || (input.is_dir() && first_foreign(input, &format!("{rel}/"), s).is_none())
            });
            if !written {
                bail!(
                    "will not replace {shown}: it holds {}, an input of this command \
                     (not even with --force); write the output elsewhere",
                    input.display()
                );
            }
        }
        if self.force {
            return Ok(());
        }
        let found = match &stamp {
            Some(s) => first_foreign(&abs, "", s),
            None => stamp::sorted_entries(&abs)
                .with_context(|| format!("cannot read output directory {shown}"))?
                .into_iter()
                .next()
                .map(|(name, ty)| {
                    Foreign::NotWritten(if ty.is_dir() {
                        format!("{name}/")
                    } else {
                        name
                    })
                }),
        };
        match found {
            None => Ok(()),
            Some(Foreign::NotWritten(rel)) => bail!(
                "will not replace {shown}: it holds {rel}, which rmapgen did not write; nothing \
                 was changed (move it, choose another output directory, or use --force)"
            ),
            Some(Foreign::Changed(rel)) => bail!(
                "will not replace {shown}: {rel} was changed since rmapgen wrote it; nothing \
                 was changed (move it, choose another output directory, or use --force)"
            ),
        }
    }

    /// Checks that file `target` may be replaced (or created): it is absent, or rmapgen wrote
    /// it and it is unchanged since (its record holds its SHA-256), or the user forced it.
    pub fn check_file(&self, target: &Path) -> Result<()> {
        let shown = target.display();
        let ends_in_slash = target.as_os_str().to_string_lossy().ends_with('/');
        if ends_in_slash || target.is_dir() {
            bail!("output {shown} is a directory; give the name of a file to write");
        }
        if target.file_name().is_none() {
            bail!("output path {shown} has no file name");
        }
        let record = stamp::record_path(target).expect("a file name");
        let recorded = stamp::read_record(target);
        let Ok(meta) = std::fs::symlink_metadata(target) else {
            // Nothing to replace; but the record's name must not be someone else's file.
            if matches!(recorded, Some(None)) && !self.force {
                bail!(
                    "will not replace {}: it is not rmapgen's record of {shown}; nothing was \
                     changed (move it, or use --force to replace it)",
                    record.display()
                );
            }
            return Ok(());
        };
        if meta.file_type().is_symlink() {
            bail!("output file {shown} is a symbolic link; give the file itself");
        }
        if !meta.is_file() {
            bail!("output path {shown} exists and is not a regular file");
        }
        let abs = absolute(target);
        if self.inputs.contains(&abs) {
            bail!(
                "will not replace {shown}: it is an input of this command (not even with --force)"
            );
        }
        if self.force {
            return Ok(());
        }
        let Some(Some(hash)) = recorded else {
            bail!(
                "will not replace {shown}: it exists and was not written by rmapgen (no record \
                 {}); nothing was changed (choose another name, or use --force to replace it)",
                record.display()
            );
        };
        if stamp::digest(target)? != hash {
            bail!(
                "will not replace {shown}: it was changed since rmapgen wrote it; nothing was \
                 changed (choose another name, or use --force to replace it)"
            );
        }
        Ok(())
    }
}

/// The first entry under `dir` (whose path relative to the stamped directory starts with
/// `prefix`) that the stamp does not vouch for.
fn first_foreign(dir: &Path, prefix: &str, stamp: &Stamp) -> Option<Foreign> {
    let entries = match stamp::sorted_entries(dir) {
        Ok(e) => e,
        Err(_) => {
            return Some(Foreign::NotWritten(
                prefix.trim_end_matches('/').to_string(),
            ))
        }
    };
    for (name, ty) in entries {
        let rel = format!("{prefix}{name}");
        if rel == stamp::NAME {
            continue;
        }
        if ty.is_dir() {
            let sub = format!("{rel}/");
            // A directory rmapgen made holds at least one file it wrote.
            if !stamp
                .range(sub.clone()..)
                .next()
                .is_some_and(|(k, _)| k.starts_with(&sub))
            {
                return Some(Foreign::NotWritten(format!("{rel}/")));
            }
            if let Some(f) = first_foreign(&dir.join(&name), &sub, stamp) {
                return Some(f);
            }
        } else if !ty.is_file() {
            return Some(Foreign::NotWritten(rel));
        } else {
            match stamp.get(&rel) {
                None => return Some(Foreign::NotWritten(rel)),
                Some(hash) => {
                    if stamp::digest(&dir.join(&name)).ok().as_ref() != Some(hash) {
                        return Some(Foreign::Changed(rel));
                    }
                }
            }
        }
    }
    None
}

/// `p` made absolute, with symbolic links of its existing part resolved and `.`/`..` of the
/// rest applied, so two spellings of one place compare equal.
pub fn absolute(p: &Path) -> PathBuf {
    if let Ok(c) = p.canonicalize() {
        return c;
    }
    let base = std::env::current_dir().unwrap_or_default();
    let full = base.join(p);
    // The longest existing ancestor, canonicalised, then the remaining components.
    let mut existing = full.as_path();
    let mut rest = Vec::new();
    while let Some(parent) = existing.parent() {
        if let Some(name) = existing.components().next_back() {
            rest.push(name);
        }
        existing = parent;
        if existing.exists() {
            break;
        }
    }
    let mut out = existing
        .canonicalize()
        .unwrap_or_else(|_| existing.to_path_buf());
    for c in rest.into_iter().rev() {
        match c {
            Component::ParentDir => {
                out.pop();
            }
            Component::CurDir => {}
            other => out.push(other),
        }
    }
    out
}

fn slash_path(rel: &Path) -> String {
    rel.components()
        .map(|c| c.as_os_str().to_string_lossy())
        .collect::<Vec<_>>()
        .join("/")
}
