//! The journal of a mutation campaign: every mutant's outcome, appended as it is judged, so
//! a campaign of hours that is stopped (a session's end, a signal, a power loss) goes on
//! where it stopped instead of starting again.
//!
//! An outcome is reused only when it was judged by the same binary (SHA-256 of the running
//! executable), on the same design files (SHA-256 of each), with the same plan (methods,
//! quick, time limit, stream length) and the same draw (every mutant of the run, in order):
//! then the checks would give the same verdicts again. Anything else starts the journal
//! afresh, and says why.
//!
//! The file is line-based: the key (one line of JSON), then one outcome per line. A line cut
//! short by a kill is the last one and is dropped on reading; a malformed line elsewhere means
//! the file is not a journal this code wrote.

use super::{own_binary, Method, Mutant, Outcome, Plan};
use crate::design_dir::DesignDir;
use crate::output::stamp;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The first word of a journal's first line.
const FORMAT: &str = "rmapgen-mutants-journal-1";

/// What a journal's outcomes hold for: the verdicts of these checks on these files.
#[derive(Debug, Serialize, Deserialize, PartialEq)]
pub struct Key {
    pub format: String,
    /// SHA-256 of the rmapgen binary that judged.
    pub binary: String,
    /// Every file of the design and its SHA-256, sorted by name.
    pub files: Vec<(String, String)>,
    pub methods: Vec<Method>,
    pub quick: bool,
    pub timeout_s: u64,
    pub sim_stream: u64,
    pub truth: Method,
    pub truth_stream: u64,
    /// The whole draw (not only the mutants a run selects with `--only`).
    pub draw: Vec<Mutant>,
    /// The formal tools' files and their SHA-256 (every file of the directory of
    /// `run_formal.py`: the script and its harness), when the formal harness judges.
    #[serde(default)]
    pub tools: Vec<(String, String)>,
}

impl Key {
    /// The key of a run of `plan` over `draw` on `design` by this binary.
    pub fn new(design: &DesignDir, plan: &Plan, draw: &[Mutant]) -> Result<Key> {
        let mut files = Vec::new();
        for (name, path) in design.file_names().iter().zip(design.files()) {
            files.push((name.clone(), stamp::digest(&path)?));
        }
        files.sort();
        let mut tools = Vec::new();
        if let Some(f) = &plan.formal {
            let dir = f.script.parent().unwrap_or(Path::new("."));
            for e in
                std::fs::read_dir(dir).with_context(|| format!("cannot read {}", dir.display()))?
            {
                let p = e?.path();
                if p.is_file() {
                    tools.push((p.display().to_string(), stamp::digest(&p)?));
                }
            }
            tools.sort();
        }
        Ok(Key {
            format: FORMAT.to_string(),
            binary: stamp::digest(&own_binary()?)?,
            files,
            methods: plan.methods.clone(),
            quick: plan.quick,
            timeout_s: plan.timeout.as_secs(),
            sim_stream: plan.sim_stream,
            truth: plan.truth,
            truth_stream: plan.truth_stream,
            draw: draw.to_vec(),
            tools,
        })
    }

    /// Why `self` (a journal's key) does not hold for a run of `now`, or None when it does.
    fn differs(&self, now: &Key) -> Option<&'static str> {
        if self.binary != now.binary {
            Some("another rmapgen binary judged them")
        } else if self.files != now.files {
            Some("the design's files have changed")
        } else if self.tools != now.tools {
            Some("the formal tools' files have changed")
        } else if self.draw != now.draw {
            Some("another draw (seed, count or memories)")
        } else if (&self.methods, self.quick, self.timeout_s, self.sim_stream)
            != (&now.methods, now.quick, now.timeout_s, now.sim_stream)
            || (self.truth, self.truth_stream) != (now.truth, now.truth_stream)
        {
            Some("another plan (methods, --quick, --timeout, --sim-stream or --truth)")
        } else {
            None
        }
    }
}

/// An open journal: the outcomes it already held, and the file new ones are appended to.
pub struct Journal {
    path: PathBuf,
    file: Mutex<std::fs::File>,
    /// Outcomes judged by earlier runs, by mutant id.
    pub earlier: BTreeMap<usize, Outcome>,
    /// One line on what was reused or why nothing was.
    pub said: String,
}

impl Journal {
    /// Opens the journal at `path` for a run keyed `key`: its outcomes are kept when its key
    /// is the same, otherwise it is started afresh. A file there that is not a journal is a
    /// user's and is refused (replaced only with `force`). The mutants in `again` are judged
    /// again (a user who names them wants their logs): their outcomes are not reused.
    pub fn open(path: &Path, key: &Key, again: &[usize], force: bool) -> Result<Journal> {
        let (earlier, said) = match std::fs::read_to_string(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
                (BTreeMap::new(), format!("journal {}: new", path.display()))
            }
            Err(e) => {
                return Err(e).with_context(|| format!("cannot read {}", path.display()));
            }
            Ok(text) => match read(&text, key) {
                Ok(Ok(mut done)) => {
                    done.retain(|id, _| !again.contains(id));
                    let said = if done.is_empty() {
                        format!("journal {}: none judged yet", path.display())
                    } else {
                        format!(
                        "journal {}: {} mutant{} judged already by this binary on these files, not judged again (their logs are not kept)",
                        path.display(),
                        done.len(),
                        if done.len() == 1 { "" } else { "s" }
                    )
                    };
                    (done, said)
                }
                Ok(Err(why)) => (
                    BTreeMap::new(),
                    format!("journal {}: started afresh, {why}", path.display()),
                ),
                Err(e) if force => (
                    BTreeMap::new(),
                    format!("journal {}: replaced (--force): {e}", path.display()),
                ),
                Err(e) => bail!(
                    "{} is not a journal of rmapgen mutants ({e}); move it, or give --force to replace it",
                    path.display()
                ),
            },
        };
        if let Some(d) = path.parent().filter(|d| !d.as_os_str().is_empty()) {
            crate::disk::create_dir_all(d)?;
        }
        let mut text = serde_json::to_string(key)? + "\n";
        for o in earlier.values() {
            text += &(serde_json::to_string(o)? + "\n");
        }
        // Rewritten whole first (a cut last line dropped), then appended to.
        std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))?;
        let file = std::fs::OpenOptions::new()
            .append(true)
            .open(path)
            .with_context(|| format!("cannot write {}", path.display()))?;
        Ok(Journal {
            path: path.to_path_buf(),
            file: Mutex::new(file),
            earlier,
            said,
        })
    }

    /// Appends one judged outcome (one write of one line).
    pub fn record(&self, o: &Outcome) -> Result<()> {
        let line = serde_json::to_string(o)? + "\n";
        let mut f = self.file.lock().unwrap_or_else(|e| e.into_inner());
        f.write_all(line.as_bytes())
            .and_then(|()| f.sync_data())
            .with_context(|| format!("cannot write {}", self.path.display()))
    }
}

/// The outcomes of journal text `text` for a run keyed `key`: `Ok(Ok(outcomes))` when its
/// key is the same, `Ok(Err(why))` when it is a journal of another run, `Err` when it is not
/// a journal.
fn read(text: &str, key: &Key) -> Result<Result<BTreeMap<usize, Outcome>, &'static str>> {
    let mut lines = text.split_inclusive('\n');
    let first = lines.next().unwrap_or("");
    let value: serde_json::Value =
        serde_json::from_str(first).context("its first line is not JSON")?;
    if value.get("format").and_then(|f| f.as_str()) != Some(FORMAT) {
        bail!("its first line is not {FORMAT}");
    }
    let Ok(theirs) = serde_json::from_value::<Key>(value) else {
        return Ok(Err("its key is not this version's"));
    };
    if let Some(why) = theirs.differs(key) {
        return Ok(Err(why));
    }
    let mut done = BTreeMap::new();
    let rest: Vec<&str> = lines.collect();
    for (i, line) in rest.iter().enumerate() {
        match serde_json::from_str::<Outcome>(line) {
            Ok(o) if key.draw.get(o.mutant.id) == Some(&o.mutant) => {
                done.insert(o.mutant.id, o);
            }
            Ok(o) => bail!(
                "line {} is m{}, which is not in its draw",
                i + 2,
                o.mutant.id
            ),
            // A kill can cut the last line only: it never ends with a newline then.
            Err(_) if i + 1 == rest.len() && !line.ends_with('\n') => {}
            Err(e) => bail!("line {}: {e}", i + 2),
        }
    }
    Ok(Ok(done))
}

#[cfg(test)]
mod tests {
    use super::super::{Change, Verdict};
    use super::*;

    fn key(binary: &str, seed: usize) -> Key {
        Key {
            format: FORMAT.into(),
            binary: binary.into(),
            files: vec![("a.v".into(), "00".into())],
            methods: vec![Method::Prove],
            quick: false,
            timeout_s: 900,
            sim_stream: 10,
            truth: Method::Direct,
            truth_stream: 0,
            draw: (0..3)
                .map(|id| Mutant {
                    id,
                    change: Change::Memory {
                        file: "recip_rom.hex".into(),
                        entry: id + seed,
                        xor: 1,
                    },
                })
                .collect(),
            tools: Vec::new(),
        }
    }

    fn outcome(k: &Key, id: usize) -> Outcome {
        Outcome {
            mutant: k.draw[id].clone(),
            verdicts: vec![
                (Method::Direct, Verdict::Failed),
                (Method::Prove, Verdict::Failed),
            ],
            seconds: 1.5,
        }
    }

    /// Outcomes written by a run come back to a run with the same key, a line cut by a kill
    /// is dropped, another key starts afresh (saying why), and a file that is not a journal
    /// is refused unless forced.
    #[test]
    fn a_journal_resumes_its_own_run_only() {
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("d.journal");
        let k = key("b1", 0);
        let j = Journal::open(&path, &k, &[], false).unwrap();
        assert!(
            j.earlier.is_empty() && j.said.ends_with("new"),
            "{}",
            j.said
        );
        j.record(&outcome(&k, 2)).unwrap();
        j.record(&outcome(&k, 0)).unwrap();
        drop(j);
        // A kill in the middle of the next line.
        let cut = serde_json::to_string(&outcome(&k, 1)).unwrap();
        let mut f = std::fs::OpenOptions::new()
            .append(true)
            .open(&path)
            .unwrap();
        f.write_all(&cut.as_bytes()[..20]).unwrap();
        drop(f);

        let j = Journal::open(&path, &k, &[], false).unwrap();
        assert_eq!(j.earlier.keys().copied().collect::<Vec<_>>(), vec![0, 2]);
        assert_eq!(j.earlier[&2], outcome(&k, 2));
        assert!(j.said.contains("2 mutants judged already"), "{}", j.said);
        j.record(&outcome(&k, 1)).unwrap();
        drop(j);
        assert_eq!(
            Journal::open(&path, &k, &[], false).unwrap().earlier.len(),
            3
        );
        // Named again: judged again, and its new outcome is the one kept.
        let j = Journal::open(&path, &k, &[1], false).unwrap();
        assert_eq!(j.earlier.keys().copied().collect::<Vec<_>>(), vec![0, 2]);
        let mut again = outcome(&k, 1);
        again.seconds = 9.0;
        j.record(&again).unwrap();
        drop(j);
        assert_eq!(
            Journal::open(&path, &k, &[], false).unwrap().earlier[&1],
            again
        );

        for (other, why) in [
            (key("b2", 0), "another rmapgen binary"),
            (key("b1", 5), "another draw"),
            (
                Key {
                    quick: true,
                    ..key("b1", 0)
                },
                "another plan",
            ),
            (
                Key {
                    truth: Method::Stream,
                    ..key("b1", 0)
                },
                "another plan",
            ),
            (
                Key {
                    files: vec![("a.v".into(), "01".into())],
                    ..key("b1", 0)
                },
                "files have changed",
            ),
            (
                Key {
                    tools: vec![("formal/run_formal.py".into(), "02".into())],
                    ..key("b1", 0)
                },
                "formal tools' files have changed",
            ),
        ] {
            // Written afresh under `other`, then read back under `k`: nothing kept.
            let j = Journal::open(&path, &other, &[], false).unwrap();
            assert!(j.earlier.is_empty() && j.said.contains(why), "{}", j.said);
            drop(j);
            let j = Journal::open(&path, &k, &[], false).unwrap();
            assert!(j.earlier.is_empty(), "{}", j.said);
            j.record(&outcome(&k, 0)).unwrap();
        }

        // A user's file, and a journal edited in the middle, are not journals.
        for text in ["my notes\n".to_string(), {
            let mut t = std::fs::read_to_string(&path).unwrap();
            t.push_str("garbage\n");
            t.push_str(&(serde_json::to_string(&outcome(&k, 1)).unwrap() + "\n"));
            t
        }] {
            std::fs::write(&path, &text).unwrap();
            let e = Journal::open(&path, &k, &[], false).err().unwrap();
            assert!(format!("{e:#}").contains("is not a journal"), "{e:#}");
            assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
            let j = Journal::open(&path, &k, &[], true).unwrap();
            assert!(j.earlier.is_empty() && j.said.contains("replaced (--force)"));
        }
    }
}
