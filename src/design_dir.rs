//! A design directory that `rmapgen generate` wrote, read back for the commands that check it
//! (`rmapgen sim`, `synth`, `lint`): the top module, configuration and design files its
//! `manifest.json` lists, and the testbenches in its `tb/`.

use crate::config::Config;
use crate::emit::manifest::{self, VectorsInfo};
use crate::scene::Scene;
use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};

/// A generated design directory, checked to be one.
#[derive(Clone, Debug)]
pub struct DesignDir {
    /// Absolute.
    path: PathBuf,
    /// The top module.
    pub top: String,
    pub config: Config,
    /// The design's Verilog files (names in the directory), in the manifest's order.
    files: Vec<String>,
    /// The scene whose maps the design holds, named (absent from a manifest written
    /// before rmapgen recorded it).
    pub scene: Option<Scene>,
    /// The test vectors it holds.
    pub vectors: Option<VectorsInfo>,
}

impl DesignDir {
    /// Opens `dir`. Anything but a directory with a readable manifest naming a valid
    /// configuration and existing design files is an error that says which.
    pub fn open(dir: &Path) -> Result<DesignDir> {
        let shown = dir.display();
        let meta = std::fs::metadata(dir).with_context(|| format!("design directory {shown}"))?;
        if !meta.is_dir() {
            bail!(
                "{shown} is not a directory; give a design directory (rmapgen generate --out DIR)"
            );
        }
        let file = dir.join(manifest::FILE);
        if !file.is_file() {
            bail!(
                "{shown} is not a design rmapgen generated (no {}); generate one with `rmapgen generate --out {shown}`",
                manifest::FILE
            );
        }
        let text = std::fs::read_to_string(&file)
            .with_context(|| format!("cannot read {}", file.display()))?;
        let m: serde_json::Value = serde_json::from_str(&text)
            .with_context(|| format!("{} is not JSON", file.display()))?;
        let top = m["top"]
            .as_str()
            .with_context(|| format!("{} names no top module", file.display()))?
            .to_string();
        let config: Config = serde_json::from_value(m["config"].clone())
            .with_context(|| format!("{}: config", file.display()))?;
        config
            .validate()
            .with_context(|| format!("{}: config", file.display()))?;
        let files: Vec<String> = m["modules"]
            .as_array()
            .with_context(|| format!("{} lists no modules", file.display()))?
            .iter()
            .map(|x| x["file"].as_str().map(String::from))
            .collect::<Option<_>>()
            .with_context(|| format!("{}: a module without a file", file.display()))?;
        if let Some(f) = files.iter().find(|f| !dir.join(f).is_file()) {
            bail!("{shown}: {f} is missing (listed in {})", manifest::FILE);
        }
        let scene = match m.get("scene") {
            None => None,
            Some(v) => {
                let mut scene: Scene = serde_json::from_value(v.clone())
                    .with_context(|| format!("{}: scene", file.display()))?;
                scene.name = m["scene_name"].as_str().unwrap_or_default().to_string();
                Some(scene)
            }
        };
        let vectors = match m.get("vectors") {
            None => None,
            Some(v) => Some(
                serde_json::from_value(v.clone())
                    .with_context(|| format!("{}: vectors", file.display()))?,
            ),
        };
        let path = dir
            .canonicalize()
            .with_context(|| format!("design directory {shown}"))?;
        Ok(DesignDir {
            path,
            top,
            config,
            files,
            scene,
            vectors,
        })
    }

    /// The directory, absolute.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The directory's own name (`rtl_out`).
    pub fn name(&self) -> String {
        self.path
            .file_name()
            .map_or_else(|| "design".into(), |n| n.to_string_lossy().into_owned())
    }

    /// The design's Verilog files, names in the directory.
    pub fn file_names(&self) -> &[String] {
        &self.files
    }

    /// The design's Verilog files, absolute.
    pub fn files(&self) -> Vec<PathBuf> {
        self.files.iter().map(|f| self.path.join(f)).collect()
    }

    /// The file parameters of testbench `tb` (`<module>_tb`) set to absolute paths in this
    /// directory, and its vector file: what a simulator run from elsewhere needs.
    pub fn testbench_files(&self, tb: &str) -> Result<(Vec<(String, String)>, PathBuf)> {
        let (files, vectors) = crate::emit::tb::testbench_files(&self.config, tb)?;
        let params = files.into_iter().map(|f| (f.param, f.default)).collect();
        Ok((self.absolute(params)?, self.path.join(vectors)))
    }

    /// The top's init-file parameters set to absolute paths in this directory.
    pub fn top_files(&self) -> Result<Vec<(String, String)>> {
        let params = crate::emit::tb::top_files(&self.config)
            .into_iter()
            .map(|f| (f.param, f.default))
            .collect();
        self.absolute(params)
    }

    fn absolute(&self, params: Vec<(String, String)>) -> Result<Vec<(String, String)>> {
        params
            .into_iter()
            .map(|(name, rel)| {
                let path = self.path.join(&rel).to_string_lossy().into_owned();
                if !crate::toolchain::verilog_string_ok(&path) {
                    bail!("{path}: a file path with a quote, backslash or newline cannot be a Verilog parameter; move the design");
                }
                Ok((name, path))
            })
            .collect()
    }

    /// The testbench file of module `module`: `tb/<module>_tb.v`.
    pub fn testbench(&self, module: &str) -> PathBuf {
        self.path.join("tb").join(format!("{module}_tb.v"))
    }

    /// The testbenches' top modules (`<module>_tb`, one per `tb/<module>_tb.v`), sorted.
    pub fn testbenches(&self) -> Result<Vec<String>> {
        let tb = self.path.join("tb");
        let entries = std::fs::read_dir(&tb).with_context(|| {
            format!(
                "{} has no testbenches: generate the design with `rmapgen generate --out {}`",
                tb.display(),
                self.path.display()
            )
        })?;
        let mut v = Vec::new();
        for e in entries {
            let name = e
                .with_context(|| format!("cannot read {}", tb.display()))?
                .file_name();
            if let Some(m) = name.to_string_lossy().strip_suffix(".v") {
                if m.ends_with("_tb") {
                    v.push(m.to_string());
                }
            }
        }
        v.sort();
        Ok(v)
    }
}
