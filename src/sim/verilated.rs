//! The generated design in the loop: Verilator builds the top of a configuration once, and
//! [`VerilatedTop`] shades batches of gradients with it through `tb/top_apply.cpp`. The sphere
//! and volume renders use it (`--rtl`) to show the hardware's own image next to the model's.

use crate::config::Config;
use crate::model::IntensitySource;
use crate::output::StagedDir;
use crate::scene::Scene;
use crate::stages::TOP;
use crate::toolchain::{run_tool, verilator};
use crate::vectors::inputs::enc_grad;
use anyhow::{bail, Result};
use std::path::{Path, PathBuf};
use std::process::Command;

const HARNESS: &str = include_str!("../../tb/top_apply.cpp");

/// A Verilated `rmap_top` with the scene's map in its RAM (both buffers).
pub struct VerilatedTop {
    cfg: Config,
    _dir: crate::output::Scratch,
    design: PathBuf,
    exe: PathBuf,
}

impl VerilatedTop {
    /// Generates the design for `cfg` with `scene`'s map and builds it with Verilator.
    pub fn build(cfg: &Config, scene: &Scene) -> Result<VerilatedTop> {
        let dir = crate::output::Scratch::new()?;
        let design = dir.path().join("design");
        let staged = StagedDir::new(&design, &Default::default())?;
        let d = crate::design::Design::for_scene(cfg, scene)?;
        crate::emit::write_design(&d, &staged, None)?;
        crate::emit::tb::write_all(&d, &staged)?;
        staged.commit()?;
        let harness = dir.path().join("top_apply.cpp");
        crate::disk::write(&harness, HARNESS)?;
        let mut sources: Vec<PathBuf> = std::fs::read_dir(&design)?
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "v"))
            .collect();
        sources.sort();
        let mdir = dir.path().join("obj");
        run_tool(
            &mut verilator::harness(
                &TOP.module(cfg),
                &mdir,
                "top_apply",
                &sources,
                &harness,
                &design.join("tb"),
                // Run from the design directory, where the default init files are.
                &[],
            ),
            "verilator",
        )?;
        Ok(VerilatedTop {
            cfg: cfg.clone(),
            design,
            exe: mdir.join("top_apply"),
            _dir: dir,
        })
    }

    /// The directory the design was generated into.
    pub fn design_dir(&self) -> &Path {
        &self.design
    }

    /// Intensity, zero flag and colour of every sample, as the hardware computes them.
    pub fn shade(
        &self,
        gradients: &[[i32; 3]],
        rgb: Option<&[[u32; 3]]>,
    ) -> Result<Vec<(bool, u32, [u32; 3])>> {
        use std::fmt::Write as _;
        let mut text = String::with_capacity(gradients.len() * 16);
        for (k, g) in gradients.iter().enumerate() {
            let [x, y, z] = g.map(|v| enc_grad(&self.cfg, v));
            let _ = write!(text, "{x:x} {y:x} {z:x}");
            if self.cfg.color {
                let c = rgb.map(|c| c[k]).unwrap_or([0; 3]);
                let _ = write!(text, " {:x} {:x} {:x}", c[0], c[1], c[2]);
            }
            text.push('\n');
        }
        let input = self._dir.path().join("input.hex");
        let output = self._dir.path().join("output.hex");
        crate::disk::write(&input, text)?;
        run_tool(
            Command::new(&self.exe)
                .arg(&input)
                .arg(&output)
                .current_dir(&self.design),
            "the Verilated top",
        )?;
        let out = std::fs::read_to_string(&output)?;
        let rows: Vec<(bool, u32, [u32; 3])> = out
            .lines()
            .map(|l| {
                let f: Vec<u32> = l
                    .split(' ')
                    .map(|x| u32::from_str_radix(x, 16).unwrap_or(u32::MAX))
                    .collect();
                let c = if f.len() == 5 {
                    [f[2], f[3], f[4]]
                } else {
                    [0; 3]
                };
                (f[0] == 1, f[1], c)
            })
            .collect();
        if rows.len() != gradients.len() {
            bail!(
                "the Verilated top returned {} samples for {}",
                rows.len(),
                gradients.len()
            );
        }
        Ok(rows)
    }
}

impl IntensitySource for VerilatedTop {
    fn intensities(&self, gradients: &[[i32; 3]]) -> Result<Vec<u32>> {
        Ok(self
            .shade(gradients, None)?
            .into_iter()
            .map(|(_, i, _)| i)
            .collect())
    }
}
