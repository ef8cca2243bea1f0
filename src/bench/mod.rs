//! `rmapgen bench`: error against run time and hardware cost, over a set of configurations,
//! scenes and map fits, plus an octahedral map of about the same entry count (model only).
//!
//! Per row: the sphere test image's error against the float reference (max abs, RMSE, PSNR,
//! via `render`); the fast bit-exact path's throughput on one thread and on all cores over 2^20
//! uniform random gradients, and the float reference's on the same gradients (all cores, the
//! ratio); the host's map build per frame (median); the ROM and map bits and, with Yosys and
//! nextpnr-ice40 installed, the generated design placed and routed on an iCE40 HX8K
//! (`rtl::fpga::ice40_report`: logic cells, block RAMs, post-route Fmax). A row is
//! on a scene's Pareto front when no other row of that scene is at least as good in both error
//! (RMSE) and cost (bits), or in both error and one-thread speed.

pub mod octahedral;
pub mod plot;

use crate::config::Config;
use crate::model::fast::FastShader;
use crate::model::map_fit::{self, LsqFit, MapFit};
use crate::model::Model;
use crate::output::StagedDir;
use crate::reference::Reference;
use crate::render::{self, metrics, sphere_gradients};
use crate::rng::SplitMix64;
use crate::rtl::fpga::{self, FpgaReport};
use crate::scene::Scene;
use anyhow::Result;
use octahedral::Octahedral;
use rayon::prelude::*;
use serde::Serialize;
use std::time::Instant;

/// What to measure.
#[derive(Clone, Debug)]
pub struct Options {
    /// Sphere image side for the error figures.
    pub size: u32,
    /// Seconds spent timing each throughput figure.
    pub seconds: f64,
    /// Place and route each configuration (Yosys, nextpnr-ice40) when they are installed.
    pub yosys: bool,
    /// Only the paper's configuration (and the octahedral map).
    pub quick: bool,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            size: 512,
            seconds: 0.3,
            yosys: true,
            quick: false,
        }
    }
}

/// One measured row.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub scene: String,
    /// A short name of the configuration (or the octahedral map).
    pub design: String,
    pub config: String,
    pub map_fit: String,
    pub entries: u32,
    pub max_abs_error: u32,
    pub rmse: f64,
    pub psnr_db: f64,
    pub msamples_1_thread: f64,
    pub msamples_all_cores: f64,
    /// All-core throughput over the float reference's, same inputs.
    pub float_ratio: f64,
    pub map_build_us: f64,
    pub rom_bits: u64,
    pub map_bits: u64,
    /// iCE40 HX8K after place and route: logic cells, block RAMs, Fmax (with the tools).
    pub ice40_cells: Option<u32>,
    pub ice40_brams: Option<u32>,
    pub fmax_mhz: Option<f64>,
    /// The flow ran and the design does not fit the HX8K (the cells, RAMs and Fmax are then
    /// None).
    pub ice40_too_big: bool,
    pub pareto_cost: bool,
    pub pareto_speed: bool,
}

impl Row {
    pub fn bits(&self) -> u64 {
        self.rom_bits + self.map_bits
    }
}

/// The configurations measured: the paper's, and a spread over the widths and stages.
pub fn configurations(quick: bool) -> Vec<(&'static str, Config)> {
    let d = Config::default();
    let mut v = vec![("paper I3 P3", d.clone())];
    if quick {
        return v;
    }
    v.extend([
        (
            "I2 P3",
            Config {
                index_bits: 2,
                ..d.clone()
            },
        ),
        (
            "I4 P3",
            Config {
                index_bits: 4,
                ..d.clone()
            },
        ),
        (
            "I3 P2",
            Config {
                interp_bits: 2,
                ..d.clone()
            },
        ),
        (
            "I3 P4",
            Config {
                interp_bits: 4,
                ..d.clone()
            },
        ),
        (
            "I3 nearest",
            Config {
                interpolation: false,
                interp_bits: 0,
                ..d.clone()
            },
        ),
        (
            "I3 P3 linear",
            Config {
                compensation: false,
                ..d.clone()
            },
        ),
        (
            "R6 F6 W7",
            Config {
                red_bits: 6,
                frac_bits: 6,
                recip_bits: 7,
                ..d.clone()
            },
        ),
    ]);
    v
}

/// The scenes measured: (name, scene).
pub fn scenes() -> Vec<(String, Scene)> {
    let diffuse = Scene::from_toml_str(include_str!("../../scenes/diffuse.toml"))
        .expect("diffuse scene is valid");
    vec![
        ("standard".into(), Scene::standard()),
        ("two_lights".into(), Scene::alternate()),
        ("diffuse".into(), diffuse),
    ]
}

/// Seconds per call of `f`: after one warm-up call, the best of three windows of at least
/// `seconds` / 3 each (and at least one call), so a busy moment on the machine counts less.
fn time(seconds: f64, mut f: impl FnMut()) -> f64 {
    f();
    (0..3)
        .map(|_| {
            let start = Instant::now();
            let mut n = 0u32;
            while n == 0 || start.elapsed().as_secs_f64() < seconds / 3.0 {
                f();
                n += 1;
            }
            start.elapsed().as_secs_f64() / n as f64
        })
        .fold(f64::INFINITY, f64::min)
}

/// Median seconds of `runs` calls.
fn median(runs: usize, mut f: impl FnMut()) -> f64 {
    let mut t: Vec<f64> = (0..runs)
        .map(|_| {
            let s = Instant::now();
            f();
            s.elapsed().as_secs_f64()
        })
        .collect();
    t.sort_by(f64::total_cmp);
    t[runs / 2]
}

fn uniform(n: usize) -> Vec<[i32; 3]> {
    let mut rng = SplitMix64::new(1);
    (0..n)
        .map(|_| [(); 3].map(|_| rng.range(0, 4095) as i32 - 2048))
        .collect()
}

/// What the iCE40 flow gave for one configuration.
#[derive(Clone, Debug)]
pub enum Ice40 {
    /// Yosys or nextpnr-ice40 is not installed (or the flow was not asked for).
    NotRun,
    /// The design needs more of the device than it has (nextpnr's complaint).
    DoesNotFit(String),
    Placed(Box<FpgaReport>),
}

/// The iCE40 figures of each configuration (in parallel, one flow per core); `NotRun` for
/// all when Yosys or nextpnr-ice40 is missing. A design too big for the HX8K is a figure, any
/// other failure an error.
pub fn ice40_figures(configs: &[Config]) -> Result<Vec<Ice40>> {
    let opts = fpga::Options::default();
    if !fpga::tools_available(&opts) {
        return Ok(vec![Ice40::NotRun; configs.len()]);
    }
    configs
        .par_iter()
        .map(|c| match fpga::ice40_report(c, &opts) {
            Ok(r) => Ok(Ice40::Placed(Box::new(r))),
            Err(e) => match e.downcast_ref::<fpga::DoesNotFit>() {
                Some(d) => Ok(Ice40::DoesNotFit(d.message.clone())),
                None => Err(e.context(format!("iCE40 flow of {}", c.summary()))),
            },
        })
        .collect()
}

/// Measures every row; `progress` is called once per finished step with a description.
pub fn run(opts: &Options, progress: &dyn Fn(&str)) -> Result<Vec<Row>> {
    let grads = uniform(1 << 20);
    let mut out16 = vec![0u16; grads.len()];
    let scenes = scenes();
    let mut rows = Vec::new();
    // The float reference's throughput per scene, and the sphere's gradients and reference
    // values per (scene, configuration output width): every configuration here has 12-bit
    // gradients and 8-bit output, so one set per scene serves them all.
    let d = Config::default();
    let sphere: Vec<[i32; 3]> = sphere_gradients(&d, opts.size, 0)
        .iter()
        .map(|p| p.2)
        .collect();
    let mut reference_speed = Vec::new();
    let mut reference_values = Vec::new();
    for (name, s) in &scenes {
        let r = Reference::new(&d, s);
        reference_speed.push(
            grads.len() as f64
                / time(opts.seconds, || {
                    drop(std::hint::black_box(r.intensities(&grads)))
                }),
        );
        reference_values.push(r.intensities(&sphere));
        progress(&format!("reference {name}"));
    }
    let configs = configurations(opts.quick);
    let figures = if opts.yosys {
        let cs: Vec<Config> = configs.iter().map(|c| c.1.clone()).collect();
        ice40_figures(&cs)?
    } else {
        vec![Ice40::NotRun; configs.len()]
    };
    for ((design, cfg), fig) in configs.into_iter().zip(figures) {
        let placed = match &fig {
            Ice40::Placed(r) => Some(r.as_ref()),
            _ => None,
        };
        let model = Model::new(&cfg);
        let fast = FastShader::new(&model, &Scene::standard().maps(&cfg));
        let one = grads.len() as f64 / time(opts.seconds, || fast.shade_batch(&grads, &mut out16));
        let all =
            grads.len() as f64 / time(opts.seconds, || fast.shade_batch_par(&grads, &mut out16));
        progress(&format!("{design}: speed and synthesis"));
        let lsq = LsqFit::new(&cfg);
        for (k, (name, scene)) in scenes.iter().enumerate() {
            for fit in [MapFit::Sample, MapFit::Lsq] {
                let p = scene.prepared();
                let build = match fit {
                    MapFit::Sample => median(7, || {
                        drop(std::hint::black_box(map_fit::contents(&cfg, fit, |n| {
                            p.shade(n)
                        })))
                    }),
                    _ => median(7, || drop(std::hint::black_box(lsq.fit(|n| p.shade(n))))),
                };
                let mut s = scene.clone();
                s.map_fit = fit;
                let r = render::render(
                    &cfg,
                    &s,
                    render::Options {
                        size: opts.size,
                        shrink: 0,
                    },
                    None,
                )?;
                rows.push(Row {
                    scene: name.clone(),
                    design: design.to_string(),
                    config: cfg.summary(),
                    map_fit: fit.name().to_string(),
                    entries: 3 * cfg.map_entries(),
                    max_abs_error: r.metrics.max_abs_error,
                    rmse: r.metrics.rmse,
                    psnr_db: r.metrics.psnr_db.unwrap_or(f64::INFINITY),
                    msamples_1_thread: one / 1e6,
                    msamples_all_cores: all / 1e6,
                    float_ratio: all / reference_speed[k],
                    map_build_us: build * 1e6,
                    rom_bits: cfg.rom_total_bits(),
                    map_bits: cfg.map_total_bits(),
                    ice40_cells: placed.map(|f| f.logic_cells),
                    ice40_brams: placed.map(|f| f.block_rams),
                    fmax_mhz: placed.map(|f| f.fmax_mhz),
                    ice40_too_big: matches!(fig, Ice40::DoesNotFit(_)),
                    pareto_cost: false,
                    pareto_speed: false,
                });
                progress(&format!("{design}: {name} {}", fit.name()));
            }
        }
    }
    // The octahedral map with about the paper's entry count.
    let side = Octahedral::side_for(3 * d.map_entries());
    for (k, (name, scene)) in scenes.iter().enumerate() {
        let p = scene.prepared();
        let build = median(7, || {
            drop(std::hint::black_box(Octahedral::new(&d, side, |n| {
                p.shade(n)
            })))
        });
        let o = Octahedral::new(&d, side, |n| p.shade(n));
        let one = grads.len() as f64
            / time(opts.seconds, || {
                out16
                    .iter_mut()
                    .zip(&grads)
                    .for_each(|(o16, &g)| *o16 = o.intensity(g) as u16)
            });
        let all = grads.len() as f64
            / time(opts.seconds, || {
                out16
                    .par_iter_mut()
                    .zip(&grads)
                    .for_each(|(o16, &g)| *o16 = o.intensity(g) as u16)
            });
        let values: Vec<u32> = sphere.par_iter().map(|&g| o.intensity(g)).collect();
        let m = metrics(&values, &reference_values[k], d.map_max());
        rows.push(Row {
            scene: name.clone(),
            design: format!("octahedral {side}x{side}"),
            config: format!("octahedral {side}x{side}, float normalise, M{}", d.map_bits),
            map_fit: "sample".into(),
            entries: (side * side) as u32,
            max_abs_error: m.max_abs_error,
            rmse: m.rmse,
            psnr_db: m.psnr_db.unwrap_or(f64::INFINITY),
            msamples_1_thread: one / 1e6,
            msamples_all_cores: all / 1e6,
            float_ratio: all / reference_speed[k],
            map_build_us: build * 1e6,
            rom_bits: 0,
            map_bits: (side * side) as u64 * d.map_bits as u64,
            ice40_cells: None,
            ice40_brams: None,
            fmax_mhz: None,
            ice40_too_big: false,
            pareto_cost: false,
            pareto_speed: false,
        });
        progress(&format!("octahedral: {name}"));
    }
    mark_pareto(&mut rows);
    Ok(rows)
}

/// Marks each scene's Pareto fronts: (bits, RMSE) and (one-thread speed, RMSE).
pub fn mark_pareto(rows: &mut [Row]) {
    let snapshot = rows.to_vec();
    for r in rows.iter_mut() {
        let same = snapshot.iter().filter(|o| o.scene == r.scene);
        let (mut cost, mut speed) = (true, true);
        for o in same {
            if o.bits() <= r.bits() && o.rmse <= r.rmse && (o.bits() < r.bits() || o.rmse < r.rmse)
            {
                cost = false;
            }
            if o.msamples_1_thread >= r.msamples_1_thread
                && o.rmse <= r.rmse
                && (o.msamples_1_thread > r.msamples_1_thread || o.rmse < r.rmse)
            {
                speed = false;
            }
        }
        r.pareto_cost = cost;
        r.pareto_speed = speed;
    }
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| scene | design | map | entries | max abs (LSB) | RMSE (LSB) | PSNR (dB) | 1 thread (M/s) | all cores (M/s) | x float | map build (us) | ROM + map bits | iCE40 cells | block RAMs | Fmax (MHz) | Pareto |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let pareto = match (r.pareto_cost, r.pareto_speed) {
            (true, true) => "cost, speed",
            (true, false) => "cost",
            (false, true) => "speed",
            _ => "",
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {:.3} | {:.2} | {:.0} | {:.0} | {:.1} | {:.0} | {} | {} | {} | {} | {} |\n",
            r.scene,
            r.design,
            r.map_fit,
            r.entries,
            r.max_abs_error,
            r.rmse,
            r.psnr_db,
            r.msamples_1_thread,
            r.msamples_all_cores,
            r.float_ratio,
            r.map_build_us,
            r.bits(),
            if r.ice40_too_big {
                "does not fit".into()
            } else {
                r.ice40_cells.map_or("-".into(), |c| c.to_string())
            },
            r.ice40_brams.map_or("-".into(), |c| c.to_string()),
            r.fmax_mhz.map_or("-".into(), |f| format!("{f:.1}")),
            pareto
        );
    }
    s
}

/// The rows as CSV with a header line.
pub fn csv(rows: &[Row]) -> String {
    let mut s = String::from("scene,design,config,map_fit,entries,max_abs_error,rmse,psnr_db,msamples_1_thread,msamples_all_cores,float_ratio,map_build_us,rom_bits,map_bits,ice40_cells,ice40_brams,fmax_mhz,ice40_too_big,pareto_cost,pareto_speed\n");
    for r in rows {
        s += &format!(
            "{},{},\"{}\",{},{},{},{:.4},{:.3},{:.2},{:.2},{:.2},{:.1},{},{},{},{},{},{},{},{}\n",
            r.scene,
            r.design,
            r.config,
            r.map_fit,
            r.entries,
            r.max_abs_error,
            r.rmse,
            r.psnr_db,
            r.msamples_1_thread,
            r.msamples_all_cores,
            r.float_ratio,
            r.map_build_us,
            r.rom_bits,
            r.map_bits,
            r.ice40_cells.map_or(String::new(), |c| c.to_string()),
            r.ice40_brams.map_or(String::new(), |c| c.to_string()),
            r.fmax_mhz.map_or(String::new(), |f| format!("{f:.2}")),
            r.ice40_too_big,
            r.pareto_cost,
            r.pareto_speed
        );
    }
    s
}

/// Writes bench.md, bench.csv, bench.json and the plots (PNG and SVG).
pub fn write(rows: &[Row], out: &StagedDir) -> Result<()> {
    out.write_text("bench.md", &markdown(rows))?;
    out.write_text("bench.csv", &csv(rows))?;
    out.write_text("bench.json", &serde_json::to_string_pretty(rows)?)?;
    let scene_names: Vec<String> = scenes().into_iter().map(|s| s.0).collect();
    let marker = |r: &Row| {
        if r.design.starts_with("octahedral") {
            2
        } else if r.map_fit == "sample" {
            0
        } else {
            1
        }
    };
    let index = |r: &Row| scene_names.iter().position(|s| *s == r.scene).unwrap_or(0);
    type Axis = (
        &'static str,
        &'static str,
        &'static str,
        bool,
        fn(&Row) -> f64,
        fn(&Row) -> bool,
    );
    let charts: [Axis; 2] = [
        ("error_vs_cost", "RMSE vs ROM + map bits (dot sampled, triangle fitted, cross octahedral; lines: Pareto)", "ROM + map bits", true, |r| r.bits() as f64, |r| r.pareto_cost),
        ("error_vs_speed", "RMSE vs speed (dot sampled, triangle fitted, cross octahedral; lines: Pareto)", "million samples/s, one thread", false, |r| r.msamples_1_thread, |r| r.pareto_speed),
    ];
    for (file, title, x_label, log_x, x, on_front) in charts {
        let points: Vec<plot::Point> = rows
            .iter()
            .map(|r| plot::Point {
                x: x(r),
                y: r.rmse,
                scene: index(r),
                marker: marker(r),
            })
            .collect();
        let fronts: Vec<Vec<(f64, f64)>> = scene_names
            .iter()
            .map(|s| {
                let mut f: Vec<(f64, f64)> = rows
                    .iter()
                    .filter(|r| r.scene == *s && on_front(r))
                    .map(|r| (x(r), r.rmse))
                    .collect();
                f.sort_by(|a, b| a.0.total_cmp(&b.0));
                f
            })
            .collect();
        let chart = plot::Chart {
            title,
            x_label,
            y_label: "RMSE (LSB), sphere image",
            log_x,
            scenes: &scene_names,
            points: &points,
            fronts: &fronts,
        };
        out.write_text(&format!("{file}.svg"), &plot::svg(&chart)?)?;
        out.write_bytes(&format!("{file}.png"), &plot::png(&chart)?)?;
    }
    Ok(())
}
