//! Output that appears whole or not at all, and never at the cost of a user's files.
//!
//! Every command writes into a staging directory (or a `.partial` file) beside its target,
//! which replaces the target only when the command succeeds; a failing command leaves the
//! target as it was and removes what it staged. Before anything is replaced, [`Policy`]
//! checks that the target holds only what rmapgen wrote there (the [`stamp`] every output
//! directory carries), that it is not the current directory or one of its ancestors, and that
//! it holds none of the command's inputs. [`signals`] removes staged output on SIGINT,
//! SIGTERM and SIGHUP.

pub mod console;
mod policy;
pub mod signals;
pub mod stamp;

pub use policy::{absolute, Policy};

use anyhow::{Context, Result};
use signals::{Token, Undo};
use std::path::{Path, PathBuf};

/// Marks a staging directory as rmapgen's while it is being written; removed before commit.
const STAGING_MARK: &str = ".rmapgen-staging";

/// The longest name of a directory entry (Linux's NAME_MAX, in bytes).
const NAME_MAX: usize = 255;

/// The hidden names made beside a target named `name`: `.BASE.staging-PID` (and
/// `.BASE.staging-PID.old`, the previous output moved aside) or `.BASE.partial-PID`, with
/// `kind` "staging" or "partial". BASE is `name` when every such name fits [`NAME_MAX`];
/// a longer name is cut (at a character boundary) and ends in `~` and 16 hex digits of its
/// SHA-256, so the names stay within the limit, stay rmapgen's (`.`, `.staging-`/
/// `.partial-`, the process id), and are the same for the same target in every run, which
/// is how [`remove_stale`] finds a killed run's leftovers.
pub fn hidden_prefix(name: &str, kind: &str) -> String {
    // "." + ".KIND-" + a u32 process id + ".old".
    let room = NAME_MAX - (1 + 1 + kind.len() + 1 + u32::MAX.to_string().len() + ".old".len());
    format!(".{}.{kind}-", shortened(name, room))
}

/// `name` if it has at most `room` bytes, else its first bytes, `~` and 16 hex digits of its
/// SHA-256, `room` bytes in all: the same for the same name in every run.
pub fn shortened(name: &str, room: usize) -> String {
    if name.len() <= room {
        return name.to_string();
    }
    use sha2::{Digest, Sha256};
    let hash = Sha256::digest(name.as_bytes());
    let tag: String = hash[..8].iter().map(|b| format!("{b:02x}")).collect();
    let mut cut = room - 1 - tag.len();
    while !name.is_char_boundary(cut) {
        cut -= 1;
    }
    format!("{}~{tag}", &name[..cut])
}

pub struct StagedDir {
    target: PathBuf,
    staging: PathBuf,
    policy: Policy,
    token: Option<Token>,
    created: CreatedParents,
}

impl StagedDir {
    /// Starts writing directory `target` under `policy`. Fails at once, before any work, if
    /// the policy refuses the target or its parent is not writable.
    pub fn new(target: &Path, policy: &Policy) -> Result<StagedDir> {
        policy.check_dir(target)?;
        let name = target
            .file_name()
            .with_context(|| format!("output path {} has no directory name", target.display()))?
            .to_string_lossy()
            .into_owned();
        let parent = parent_of(target);
        let created = CreatedParents::make(&parent)
            .with_context(|| format!("cannot write output directory {}", target.display()))?;
        let prefix = hidden_prefix(&name, "staging");
        remove_stale(&parent, &prefix);
        let staging = parent.join(format!("{prefix}{}", std::process::id()));
        let token = signals::register(Undo::Remove(staging.clone()));
        let made = std::fs::create_dir(&staging)
            .and_then(|()| std::fs::write(staging.join(STAGING_MARK), b""));
        let dir = StagedDir {
            target: target.to_path_buf(),
            staging,
            policy: policy.clone(),
            token: Some(token),
            created,
        };
        made.with_context(|| format!("cannot write output directory {}", target.display()))?;
        Ok(dir)
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

    /// Writes one file (relative path; parents created). A failure names the file where it
    /// will be (`out/model.png`), not in the hidden staging directory.
    pub fn write_bytes(&self, rel: &str, bytes: &[u8]) -> Result<()> {
        let p = self.staging.join(rel);
        let shown = self.target.join(rel);
        // Held so an interrupt cannot remove the staging directory under a half-made file
        // (create_dir_all would bring it back after the cleanup).
        let _held = signals::hold();
        if let Some(d) = p.parent() {
            std::fs::create_dir_all(d).with_context(|| {
                format!(
                    "cannot create {}",
                    shown.parent().unwrap_or(&shown).display()
                )
            })?;
        }
        std::fs::write(&p, bytes).with_context(|| format!("cannot write {}", shown.display()))
    }

    /// Copies into the staging directory every file of the existing target that this run
    /// has not written, so a command can refresh some files of an output in place.
    pub fn keep_others(&self) -> Result<()> {
        self.policy.check_dir(&self.target)?;
        let Some(old) = stamp::read(&self.target) else {
            return Ok(());
        };
        for rel in old.keys() {
            let to = self.staging.join(rel);
            if !to.exists() {
                let from = self.target.join(rel);
                let bytes = std::fs::read(&from)
                    .with_context(|| format!("cannot read {}", from.display()))?;
                self.write_bytes(rel, &bytes)?;
            }
        }
        Ok(())
    }

    /// Commits the output also when `result` (the work that wrote it) failed, so its logs can
    /// be read, and returns `result` with the committed directory: a failure that names a
    /// path in the staging directory, which is gone once the command ends, names the same
    /// path in the committed one instead (in whatever spelling, relative or absolute, since
    /// only the staging directory's own name is replaced).
    pub fn commit_with<T>(self, result: Result<T>) -> Result<(PathBuf, T)> {
        match result {
            Ok(v) => Ok((self.commit()?, v)),
            Err(e) => Err(self.commit_failed(e)),
        }
    }

    /// [`StagedDir::commit_with`] for work that failed with `e`: the error to report (the
    /// commit's own, if it fails).
    pub fn commit_failed(self, e: anyhow::Error) -> anyhow::Error {
        let (staging, target) = (self.staging.clone(), self.target.clone());
        match self.commit() {
            Ok(_) => named_as_target(e, &staging, &target),
            Err(c) => c,
        }
    }

    /// Replaces the target with the staging directory, stamped with what it holds. The
    /// target is checked again first: files may have appeared in it since [`StagedDir::new`].
    pub fn commit(mut self) -> Result<PathBuf> {
        self.policy.check_dir(&self.target)?;
        let shown = self.target.display().to_string();
        std::fs::remove_file(self.staging.join(STAGING_MARK))
            .with_context(|| format!("cannot finish {shown}"))?;
        seal(&self.staging).with_context(|| format!("cannot finish {shown}"))?;
        // Not with_extension: the staging name's extension is `staging-PID`, and the old
        // output must be found by remove_stale as `<staging>.old`.
        let mut old = self.staging.clone().into_os_string();
        old.push(".old");
        let old = PathBuf::from(old);
        let token = self.token.take().expect("registered until commit");
        {
            // Both renames under one hold: an interrupt sees the old output or the new one.
            let mut held = signals::hold();
            if self.target.exists() {
                if let Err(e) = std::fs::rename(&self.target, &old) {
                    self.token = Some(token);
                    return Err(e).with_context(|| format!("cannot replace {shown}"));
                }
                held.replace(
                    &token,
                    Undo::Restore {
                        from: old.clone(),
                        to: self.target.clone(),
                    },
                );
            }
            if let Err(e) = std::fs::rename(&self.staging, &self.target) {
                if old.exists() {
                    std::fs::rename(&old, &self.target).ok();
                }
                held.replace(&token, Undo::Remove(self.staging.clone()));
                self.token = Some(token);
                return Err(e).with_context(|| format!("cannot move output into {shown}"));
            }
            held.replace(&token, Undo::Remove(old.clone()));
        }
        // The old output passed the policy: everything in it was rmapgen's (or forced).
        if old.exists() {
            std::fs::remove_dir_all(&old).ok();
        }
        token.release();
        self.created.keep();
        Ok(self.target.clone())
    }
}

impl StagedDir {
    /// Puts the directory in place now, before the work that fills it is done, for work that
    /// must write at the final path (jobs of a batch system, which run later, elsewhere, and
    /// write their logs and reports there). The target is checked again first, as by
    /// [`StagedDir::commit`]. Until [`InPlace::keep`] the directory is provisional: dropped
    /// (the work could not start) or interrupted, it is removed, the previous output it
    /// replaced is put back, and the parents made for it are removed.
    pub fn commit_in_place(mut self) -> Result<InPlace> {
        self.policy.check_dir(&self.target)?;
        let shown = self.target.display().to_string();
        std::fs::remove_file(self.staging.join(STAGING_MARK))
            .with_context(|| format!("cannot finish {shown}"))?;
        let mut old = self.staging.clone().into_os_string();
        old.push(".old");
        let old = PathBuf::from(old);
        let token = self.token.take().expect("registered until commit");
        let mut held = signals::hold();
        let had_old = self.target.exists();
        if had_old {
            if let Err(e) = std::fs::rename(&self.target, &old) {
                self.token = Some(token);
                return Err(e).with_context(|| format!("cannot replace {shown}"));
            }
        }
        if let Err(e) = std::fs::rename(&self.staging, &self.target) {
            if had_old {
                std::fs::rename(&old, &self.target).ok();
            }
            self.token = Some(token);
            return Err(e).with_context(|| format!("cannot move output into {shown}"));
        }
        // Undone last first: the new directory removed, then the old one put back.
        let mut tokens = Vec::new();
        if had_old {
            held.replace(
                &token,
                Undo::Restore {
                    from: old.clone(),
                    to: self.target.clone(),
                },
            );
            tokens.push(token);
            tokens.push(held.register(Undo::Remove(self.target.clone())));
        } else {
            held.replace(&token, Undo::Remove(self.target.clone()));
            tokens.push(token);
        }
        drop(held);
        Ok(InPlace {
            target: self.target.clone(),
            old: had_old.then_some(old),
            tokens,
            created: std::mem::replace(&mut self.created, CreatedParents { dirs: Vec::new() }),
        })
    }
}

/// A directory in place whose work is still under way ([`StagedDir::commit_in_place`]):
/// dropped before [`InPlace::keep`], it is taken back.
pub struct InPlace {
    target: PathBuf,
    /// The previous output, moved aside until the new one is kept.
    old: Option<PathBuf>,
    /// What an interrupt undoes; empty once kept.
    tokens: Vec<Token>,
    created: CreatedParents,
}

impl InPlace {
    /// The directory, at its final path.
    pub fn path(&self) -> &Path {
        &self.target
    }

    /// The work has run: the directory stays, recorded ([`seal`]) as every output is, so that
    /// a later run replaces it; the previous output goes, the parents made for it stay.
    pub fn keep(mut self) -> Result<PathBuf> {
        if let Some(old) = self.old.take() {
            std::fs::remove_dir_all(old).ok();
        }
        for t in self.tokens.drain(..) {
            t.release();
        }
        self.created.keep();
        seal(&self.target).with_context(|| format!("cannot finish {}", self.target.display()))?;
        Ok(self.target.clone())
    }
}

impl Drop for InPlace {
    fn drop(&mut self) {
        if self.tokens.is_empty() {
            return;
        }
        {
            let _held = signals::hold();
            std::fs::remove_dir_all(&self.target).ok();
            if let Some(old) = &self.old {
                std::fs::rename(old, &self.target).ok();
            }
        }
        for t in self.tokens.drain(..).rev() {
            t.release();
        }
        // Then `created` drops: the parents made for the directory go, if empty.
    }
}

/// Records directory `dir`, which rmapgen (or work it started) has just written whole, as
/// rmapgen's: its empty directories removed (a directory rmapgen wrote holds a file it wrote:
/// an empty one would count as another's, and the next run would refuse to replace it), then
/// its stamp written.
fn seal(dir: &Path) -> Result<()> {
    remove_empty_dirs(dir)?;
    stamp::write(dir)
}

/// Removes every empty directory below `dir` (not `dir` itself; symbolic links are not
/// followed), deepest first; whether `dir` is left empty.
fn remove_empty_dirs(dir: &Path) -> Result<bool> {
    let mut empty = true;
    for (name, ty) in stamp::sorted_entries(dir)? {
        let p = dir.join(&name);
        if ty.is_dir() && remove_empty_dirs(&p)? {
            std::fs::remove_dir(&p).with_context(|| format!("cannot remove {}", p.display()))?;
        } else {
            empty = false;
        }
    }
    Ok(empty)
}

impl Drop for StagedDir {
    fn drop(&mut self) {
        if let Some(token) = self.token.take() {
            std::fs::remove_dir_all(&self.staging).ok();
            token.release();
        }
    }
}

/// One output file that appears whole or not at all: written as `NAME` inside a staging
/// directory `.NAME.partial-PID` beside the target (marked as rmapgen's like a directory's
/// staging, so a leftover is told from a user's file of that name), and renamed over the
/// target on [`StagedFile::commit`], with its record ([`stamp::record_path`]) beside it.
pub struct StagedFile {
    target: PathBuf,
    dir: PathBuf,
    partial: PathBuf,
    policy: Policy,
    token: Option<Token>,
    created: CreatedParents,
}

impl StagedFile {
    /// Starts writing file `target` under `policy`: a file already there is replaced only if
    /// rmapgen wrote it and it is unchanged since (or with `--force`).
    pub fn new(target: &Path, policy: &Policy) -> Result<StagedFile> {
        policy.check_file(target)?;
        let name = target
            .file_name()
            .with_context(|| format!("output path {} has no file name", target.display()))?
            .to_string_lossy()
            .into_owned();
        let parent = parent_of(target);
        let created = CreatedParents::make(&parent)
            .with_context(|| format!("cannot write {}", target.display()))?;
        let prefix = hidden_prefix(&name, "partial");
        remove_stale(&parent, &prefix);
        let dir = parent.join(format!("{prefix}{}", std::process::id()));
        let token = signals::register(Undo::Remove(dir.clone()));
        let made =
            std::fs::create_dir(&dir).and_then(|()| std::fs::write(dir.join(STAGING_MARK), b""));
        let file = StagedFile {
            target: target.to_path_buf(),
            partial: dir.join(&name),
            dir,
            policy: policy.clone(),
            token: Some(token),
            created,
        };
        made.with_context(|| format!("cannot write {}", target.display()))?;
        // Made now, empty: a place that cannot be written (a read-only file system) fails
        // at once, naming the target, not after the command's work.
        {
            let _held = signals::hold();
            std::fs::File::create(&file.partial)
                .with_context(|| format!("cannot write {}", target.display()))?;
        }
        Ok(file)
    }

    /// Writes the whole file; a failure names the target.
    pub fn write(&self, bytes: impl AsRef<[u8]>) -> Result<()> {
        std::fs::write(&self.partial, bytes)
            .with_context(|| format!("cannot write {}", self.target.display()))
    }

    /// Where to write the file now.
    pub fn path(&self) -> &Path {
        &self.partial
    }

    /// `e` (of writing [`StagedFile::path`]) naming the target where it named the partial
    /// file, which is gone once the command ends.
    pub fn name_target(&self, e: anyhow::Error) -> anyhow::Error {
        named_as_target(e, &self.partial, &self.target)
    }

    /// Renames the finished file over the target (checked again first) and records its
    /// SHA-256 beside it.
    pub fn commit(mut self) -> Result<PathBuf> {
        self.policy.check_file(&self.target)?;
        let shown = self.target.display().to_string();
        let name = self.target.file_name().expect("checked").to_string_lossy();
        let hash = stamp::digest(&self.partial)?;
        let record = stamp::record_path(&self.target).expect("a file name");
        let staged_record = self.dir.join(".record");
        std::fs::write(&staged_record, stamp::record_text(&name, &hash))
            .with_context(|| format!("cannot write {}", record.display()))?;
        {
            // Both renames under one hold: an interrupt sees the old file and record, or the
            // new ones. (Killed outright in between, the new file and the old record
            // disagree: the file is kept until --force, never lost.)
            let _held = signals::hold();
            std::fs::rename(&self.partial, &self.target)
                .with_context(|| format!("cannot write {shown}"))?;
            std::fs::rename(&staged_record, &record)
                .with_context(|| format!("cannot write {}", record.display()))?;
            std::fs::remove_dir_all(&self.dir).ok();
        }
        if let Some(t) = self.token.take() {
            t.release();
        }
        self.created.keep();
        Ok(self.target.clone())
    }
}

impl Drop for StagedFile {
    fn drop(&mut self) {
        if let Some(token) = self.token.take() {
            std::fs::remove_dir_all(&self.dir).ok();
            token.release();
        }
    }
}

/// A temporary directory (synthesis runs, Verilator builds) that an interrupt removes too.
pub struct Scratch {
    dir: tempfile::TempDir,
    token: Option<Token>,
}

impl Scratch {
    pub fn new() -> Result<Scratch> {
        let dir = tempfile::Builder::new()
            .prefix("rmapgen-")
            .tempdir()
            .context("cannot make a temporary directory")?;
        let token = signals::register(Undo::Remove(dir.path().to_path_buf()));
        Ok(Scratch {
            dir,
            token: Some(token),
        })
    }

    pub fn path(&self) -> &Path {
        self.dir.path()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        // TempDir removes the directory after this; the registration goes first so an
        // interrupt never races it.
        if let Some(t) = self.token.take() {
            t.release();
        }
    }
}

/// `e` with the hidden name `staged` (a staging directory or partial file, in whatever
/// spelling of its path) replaced by the name of `target` beside it. A closed standard
/// output, and an error that does not name it, stay as they are.
fn named_as_target(e: anyhow::Error, staged: &Path, target: &Path) -> anyhow::Error {
    let (Some(from), Some(to)) = (staged.file_name(), target.file_name()) else {
        return e;
    };
    let (from, to) = (from.to_string_lossy(), to.to_string_lossy());
    let msg = format!("{e:#}");
    if console::is_stdout_closed(&e) || !msg.contains(from.as_ref()) {
        return e;
    }
    anyhow::anyhow!("{}", msg.replace(from.as_ref(), &to))
}

/// The directory an output goes into ("." for a bare name).
fn parent_of(target: &Path) -> PathBuf {
    match target.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The parent directories an output needed that did not exist, made now and removed again
/// (if still empty) when the command fails or is interrupted.
struct CreatedParents {
    dirs: Vec<(PathBuf, Token)>,
}

impl CreatedParents {
    fn make(parent: &Path) -> std::io::Result<CreatedParents> {
        let mut missing = Vec::new();
        let mut p = Some(parent);
        while let Some(d) = p.filter(|d| !d.as_os_str().is_empty() && !d.exists()) {
            missing.push(d.to_path_buf());
            p = d.parent();
        }
        // The nearest parent that exists must be a directory; a file there fails every
        // `create_dir` below it with an error that names nothing.
        if let Some(d) = p.filter(|d| !d.as_os_str().is_empty() && !d.is_dir()) {
            return Err(not_a_directory(d));
        }
        let mut made = CreatedParents { dirs: Vec::new() };
        for d in missing.into_iter().rev() {
            let token = signals::register(Undo::RemoveIfEmpty(d.clone()));
            match std::fs::create_dir(&d) {
                Ok(()) => made.dirs.push((d, token)),
                // Made since the check by another thread or process (`prove-mult --matrix`
                // starts its rows' logs side by side under one new parent): not ours, so
                // it is neither removed on failure nor an error.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && d.is_dir() => {
                    token.release()
                }
                // Something that `exists()` did not see, such as a dangling symbolic link.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    token.release();
                    return Err(not_a_directory(&d));
                }
                Err(e) => {
                    token.release();
                    return Err(std::io::Error::new(
                        e.kind(),
                        format!("{}: {e}", d.display()),
                    ));
                }
            }
        }
        Ok(made)
    }

    /// The output is in place: its parents stay.
    fn keep(&mut self) {
        for (_, t) in self.dirs.drain(..) {
            t.release();
        }
    }
}

fn not_a_directory(d: &Path) -> std::io::Error {
    std::io::Error::new(
        std::io::ErrorKind::NotADirectory,
        format!("{} is not a directory", d.display()),
    )
}

impl Drop for CreatedParents {
    fn drop(&mut self) {
        for (d, t) in self.dirs.drain(..).rev() {
            std::fs::remove_dir(&d).ok();
            t.release();
        }
    }
}

/// Removes leftovers of runs that were killed outright (SIGKILL, power loss): directories of
/// `parent` named `<prefix><pid>` (or `<prefix><pid>.old`) whose process no longer exists and
/// that carry rmapgen's staging mark (or, a moved-aside old output, its stamp).
fn remove_stale(parent: &Path, prefix: &str) {
    let Ok(entries) = std::fs::read_dir(parent) else {
        return;
    };
    for e in entries.flatten() {
        let name = e.file_name().to_string_lossy().into_owned();
        let Some(rest) = name.strip_prefix(prefix) else {
            continue;
        };
        let pid = rest.strip_suffix(".old").unwrap_or(rest);
        if pid.is_empty() || !pid.bytes().all(|b| b.is_ascii_digit()) || process_alive(pid) {
            continue;
        }
        let p = e.path();
        // Only a directory with rmapgen's mark: a file (a user's `.v.hex.partial-999999`)
        // or an unmarked directory is never rmapgen's to remove.
        match std::fs::symlink_metadata(&p) {
            Ok(m) if m.is_dir() && stamp_or_mark(&p) => {
                std::fs::remove_dir_all(&p).ok();
            }
            _ => {}
        }
    }
}

/// A leftover directory is rmapgen's if it has the staging mark or (a moved-aside old
/// output) a stamp.
fn stamp_or_mark(p: &Path) -> bool {
    p.join(STAGING_MARK).is_file() || stamp::read(p).is_some()
}

fn process_alive(pid: &str) -> bool {
    // Where /proc is missing, assume alive: never remove what might still be in use.
    !Path::new("/proc/self").exists() || Path::new("/proc").join(pid).exists()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Barrier;

    /// Outputs written side by side under one new parent (`prove-mult --matrix` proves rows
    /// on several threads, each into `logs/<row>`): every one must start, whichever thread
    /// makes the shared parent. Each round starts 8 threads at once on a fresh parent two
    /// levels deep, so the check-then-create window is hit.
    #[test]
    fn siblings_started_at_once_under_a_new_parent_all_start() {
        let tmp = tempfile::tempdir().unwrap();
        let policy = Policy::new(false);
        for round in 0..40 {
            let parent = tmp.path().join(format!("r{round}")).join("logs");
            let barrier = Barrier::new(8);
            let results: Vec<Result<StagedDir>> = std::thread::scope(|s| {
                let handles: Vec<_> = (0..8)
                    .map(|i| {
                        let (parent, barrier, policy) = (&parent, &barrier, &policy);
                        s.spawn(move || {
                            barrier.wait();
                            StagedDir::new(&parent.join(format!("row{i}")), policy)
                        })
                    })
                    .collect();
                handles.into_iter().map(|h| h.join().unwrap()).collect()
            });
            for (i, r) in results.into_iter().enumerate() {
                let dir = r.unwrap_or_else(|e| panic!("round {round}, row{i}: {e:#}"));
                dir.commit().unwrap();
            }
            for i in 0..8 {
                assert!(parent.join(format!("row{i}")).is_dir());
            }
        }
    }

    /// Staging and partial names (and the old output's) fit NAME_MAX for every target name
    /// that fits it, keep rmapgen's marks, and are the same for the same target.
    #[test]
    fn hidden_names_fit_the_name_limit() {
        for bytes in [1, 200, 230, 231, 232, 250, 254, 255] {
            // One-byte characters, and two-byte ones (plus one byte when odd), so a cut
            // may fall inside a character.
            let wide = "é".repeat(bytes / 2) + &"a".repeat(bytes % 2);
            for name in ["a".repeat(bytes), wide] {
                assert_eq!(name.len(), bytes);
                for kind in ["staging", "partial"] {
                    let p = hidden_prefix(&name, kind);
                    let longest = format!("{p}{}.old", u32::MAX);
                    assert!(
                        longest.len() <= NAME_MAX,
                        "{} bytes: {longest}",
                        longest.len()
                    );
                    assert!(p.starts_with('.') && p.ends_with(&format!(".{kind}-")));
                    assert_eq!(p, hidden_prefix(&name, kind));
                    // Up to 231 bytes the name is kept whole, as before.
                    assert_eq!(p == format!(".{name}.{kind}-"), bytes <= 231, "{p}");
                }
            }
        }
        // A cut that falls inside a character moves back to its start: 33 bytes of room
        // before the tag is 16 whole two-byte characters.
        let s = shortened(&"é".repeat(100), 50);
        assert_eq!(s.len(), 49, "{s}");
        assert!(
            s.starts_with(&"é".repeat(16)) && s.as_bytes()[32] == b'~',
            "{s}"
        );
        assert_eq!(shortened("abc", 3), "abc");
        // Two long names that differ only at the end get different prefixes.
        let (a, b) = ("x".repeat(254) + "a", "x".repeat(254) + "b");
        assert_ne!(hidden_prefix(&a, "staging"), hidden_prefix(&b, "staging"));
    }

    /// An error naming a staging directory or partial file names the target instead, in
    /// any spelling of the path; a closed standard output stays what it is.
    #[test]
    fn errors_name_the_target_not_the_hidden_name() {
        let staged = Path::new("/a/b/.out.partial-123");
        let target = Path::new("/a/b/out");
        let e =
            anyhow::anyhow!("No space left on device").context("cannot write b/.out.partial-123");
        assert_eq!(
            format!("{:#}", named_as_target(e, staged, target)),
            "cannot write b/out: No space left on device"
        );
        let e = anyhow::Error::new(console::StdoutClosed).context("x .out.partial-123");
        assert!(console::is_stdout_closed(&named_as_target(
            e, staged, target
        )));
    }

    /// Every entry under `dir`, as sorted relative paths (hidden ones included).
    fn tree(dir: &Path) -> Vec<String> {
        let mut out = Vec::new();
        let mut stack = vec![dir.to_path_buf()];
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).unwrap().flatten() {
                let p = e.path();
                out.push(p.strip_prefix(dir).unwrap().display().to_string());
                if p.is_dir() {
                    stack.push(p);
                }
            }
        }
        out.sort();
        out
    }

    /// An output dropped before its commit (an error or an early return) leaves nothing: not
    /// its hidden staging directory or partial file, not the parents it made, and a file
    /// already at the target is untouched.
    #[test]
    fn an_output_dropped_before_its_commit_leaves_nothing() {
        let tmp = tempfile::tempdir().unwrap();
        let policy = Policy::new(false);
        let deep = tmp.path().join("a").join("b");
        let dir = StagedDir::new(&deep.join("out"), &policy).unwrap();
        dir.write_text("x/y.v", "module m; endmodule").unwrap();
        assert!(deep.is_dir());
        drop(dir);
        assert_eq!(tree(tmp.path()), Vec::<String>::new());

        let file = StagedFile::new(&deep.join("report.json"), &policy).unwrap();
        file.write("{}").unwrap();
        drop(file);
        assert_eq!(tree(tmp.path()), Vec::<String>::new());

        // Under a parent that was there: the parent and the user's file stay as they were.
        std::fs::write(tmp.path().join("report.json"), b"mine").unwrap();
        let file = StagedFile::new(&tmp.path().join("report.json"), &Policy::new(true)).unwrap();
        file.write("{}").unwrap();
        drop(file);
        assert_eq!(tree(tmp.path()), vec!["report.json".to_string()]);
        assert_eq!(
            std::fs::read(tmp.path().join("report.json")).unwrap(),
            b"mine"
        );
    }

    /// Text files end with exactly one newline whether or not the text has it.
    #[test]
    fn text_files_end_with_one_newline() {
        let tmp = tempfile::tempdir().unwrap();
        let dir = StagedDir::new(&tmp.path().join("out"), &Policy::new(false)).unwrap();
        dir.write_text("a.txt", "a").unwrap();
        dir.write_text("b.txt", "b\n").unwrap();
        dir.write_text("c.txt", "").unwrap();
        let out = dir.commit().unwrap();
        let read = |n: &str| std::fs::read_to_string(out.join(n)).unwrap();
        assert_eq!(
            (read("a.txt"), read("b.txt"), read("c.txt")),
            ("a\n".into(), "b\n".into(), "\n".into())
        );
    }

    /// A refresh in place (`generate` over its own design, `roms --update`): the files this
    /// run writes are the new ones, every other file of the old output is kept as it was; and
    /// a single file commits the bytes written, with its record.
    #[test]
    fn a_refresh_keeps_the_files_it_does_not_write_and_a_file_holds_what_was_written() {
        let tmp = tempfile::tempdir().unwrap();
        let policy = Policy::new(false);
        let target = tmp.path().join("out");
        let dir = StagedDir::new(&target, &policy).unwrap();
        dir.write_text("a.hex", "old a").unwrap();
        dir.write_text("sub/b.v", "old b").unwrap();
        dir.commit().unwrap();

        let dir = StagedDir::new(&target, &policy).unwrap();
        dir.write_text("a.hex", "new a").unwrap();
        dir.keep_others().unwrap();
        dir.commit().unwrap();
        let read = |n: &str| std::fs::read_to_string(target.join(n)).unwrap();
        assert_eq!(
            (read("a.hex"), read("sub/b.v")),
            ("new a\n".into(), "old b\n".into())
        );
        // Both are rmapgen's, unchanged: a third run may replace them without --force.
        assert!(StagedDir::new(&target, &policy).is_ok());

        let f = tmp.path().join("v.hex");
        let file = StagedFile::new(&f, &policy).unwrap();
        file.write("0a\n").unwrap();
        file.commit().unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"0a\n");
        let again = StagedFile::new(&f, &policy).unwrap();
        again.write("0b\n").unwrap();
        again.commit().unwrap();
        assert_eq!(std::fs::read(&f).unwrap(), b"0b\n");
    }

    /// A leftover is removed only if it is a directory with rmapgen's mark, left by a
    /// process that is gone: a live process's (this one's), a user's file of the same name
    /// and an unmarked directory stay.
    #[test]
    fn only_marked_leftovers_of_dead_processes_are_removed() {
        let tmp = tempfile::tempdir().unwrap();
        let p = tmp.path();
        let prefix = hidden_prefix("out", "staging");
        let dead = p.join(format!("{prefix}4000000"));
        let dead_old = p.join(format!("{prefix}4000001.old"));
        let live = p.join(format!("{prefix}{}", std::process::id()));
        let unmarked = p.join(format!("{prefix}4000002"));
        let file = p.join(format!("{prefix}4000003"));
        // Marked, but no process id follows the prefix: not a name rmapgen gives.
        let not_a_pid = p.join(format!("{prefix}4000004x"));
        for d in [&dead, &dead_old, &live, &not_a_pid] {
            std::fs::create_dir(d).unwrap();
            std::fs::write(d.join(STAGING_MARK), b"").unwrap();
        }
        std::fs::create_dir(&unmarked).unwrap();
        std::fs::write(&file, b"mine").unwrap();
        remove_stale(p, &prefix);
        assert!(!dead.exists() && !dead_old.exists());
        assert!(live.is_dir() && unmarked.is_dir() && file.is_file() && not_a_pid.is_dir());
        assert!(process_alive(&std::process::id().to_string()));
        assert!(!process_alive("4000000"));
    }

    /// A directory put in place before its work: dropped, it goes with the parents made for
    /// it, or the previous output comes back as it was; kept, it stays, stamped, without its
    /// empty directories, and a later run replaces it.
    #[test]
    fn a_directory_in_place_is_taken_back_unless_kept() {
        let tmp = tempfile::tempdir().unwrap();
        let policy = Policy::new(false);
        let target = tmp.path().join("a").join("b").join("jobs");
        let dir = StagedDir::new(&target, &policy).unwrap();
        dir.write_text("job.sh", "true").unwrap();
        let job = dir.commit_in_place().unwrap();
        assert_eq!(job.path(), target);
        assert_eq!(
            tree(tmp.path()),
            ["a", "a/b", "a/b/jobs", "a/b/jobs/job.sh"],
            "in place, unmarked, unstamped"
        );
        std::fs::create_dir_all(target.join("logs")).unwrap();
        drop(job);
        assert_eq!(tree(tmp.path()), Vec::<String>::new(), "taken back whole");

        // Kept: the empty directories (at any depth) go, the rest is stamped.
        let dir = StagedDir::new(&target, &policy).unwrap();
        dir.write_text("job.sh", "true").unwrap();
        let job = dir.commit_in_place().unwrap();
        for d in ["logs", "status/a/b", "reports"] {
            std::fs::create_dir_all(target.join(d)).unwrap();
        }
        std::fs::write(target.join("reports").join("r.json"), "{}").unwrap();
        assert_eq!(job.keep().unwrap(), target);
        assert_eq!(
            tree(&target),
            [".rmapgen-files", "job.sh", "reports", "reports/r.json"]
        );
        assert_eq!(
            stamp::read(&target).unwrap().keys().collect::<Vec<_>>(),
            ["job.sh", "reports/r.json"]
        );
        let kept = tree(tmp.path());

        // Over that output: dropped, it is back byte for byte; kept, it is replaced.
        let dir = StagedDir::new(&target, &policy).unwrap();
        dir.write_text("job.sh", "false").unwrap();
        let job = dir.commit_in_place().unwrap();
        assert_eq!(std::fs::read(target.join("job.sh")).unwrap(), b"false\n");
        drop(job);
        assert_eq!(tree(tmp.path()), kept);
        assert_eq!(std::fs::read(target.join("job.sh")).unwrap(), b"true\n");
        let dir = StagedDir::new(&target, &policy).unwrap();
        dir.write_text("job.sh", "false").unwrap();
        dir.commit_in_place().unwrap().keep().unwrap();
        assert_eq!(tree(&target), [".rmapgen-files", "job.sh"]);
        assert_eq!(
            tree(target.parent().unwrap()),
            ["jobs", "jobs/.rmapgen-files", "jobs/job.sh"]
        );
        assert_eq!(std::fs::read(target.join("job.sh")).unwrap(), b"false\n");
        // A committed output loses its empty directories too (the next run may replace it).
        let dir = StagedDir::new(&target, &policy).unwrap();
        std::fs::create_dir_all(dir.path().join("empty").join("deeper")).unwrap();
        dir.write_text("x/y.v", "").unwrap();
        dir.commit().unwrap();
        assert_eq!(tree(&target), [".rmapgen-files", "x", "x/y.v"]);
        assert!(StagedDir::new(&target, &policy).is_ok());
    }

    /// A parent that exists as a file is still an error (only a directory made meanwhile is
    /// accepted), and nothing is left behind.
    #[test]
    fn a_parent_that_is_a_file_is_refused() {
        let tmp = tempfile::tempdir().unwrap();
        let file = tmp.path().join("logs");
        std::fs::write(&file, b"mine").unwrap();
        let r = StagedDir::new(&file.join("row"), &Policy::new(false));
        assert!(r.is_err());
        assert_eq!(std::fs::read(&file).unwrap(), b"mine");
    }
}
