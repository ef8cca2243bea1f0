//! `rmapgen bench`: error against run time and hardware cost, over a set of configurations,
//! scenes and map fits, plus an octahedral map of about the same entry count (model only).
//!
//! Per row: the sphere test image's error against the float reference (max abs, RMSE, PSNR,
//! via `render`); the fast bit-exact path's throughput on one thread and on all cores over 2^20
//! uniform random gradients, and the float reference's on the same gradients (all cores, the
//! ratio); the host's map build per frame (median); the ROM and map bits and, with Yosys and
//! nextpnr installed, the generated design placed and routed on an iCE40 HX8K, or with
//! `--family ecp5` an ECP5-85F, built with `--lanes` lanes ([`fpga::figures`]: logic cells,
//! block RAMs, DSP blocks on the ECP5, post-route Fmax, samples/s = lanes x Fmax). A row is
//! on a scene's Pareto front when no other row of that scene is at least as good in both error
//! (RMSE) and cost (bits), or in both error and one-thread speed.

pub mod datasheet;
pub mod fpga;
pub mod octahedral;
pub mod pareto;
pub mod plot;
pub mod row;
pub mod table;
pub mod throughput;
mod timing;

use crate::config::Config;
use crate::flow::fpga::Family;
use crate::model::fast::FastShader;
use crate::model::map_fit::{self, LsqFit, MapFit};
use crate::model::Model;
use crate::output::StagedDir;
use crate::reference::Reference;
use crate::render::{self, metrics, sphere_gradients};
use crate::scene::Scene;
use anyhow::Result;
use fpga::{figures, Flow};
use octahedral::Octahedral;
use pareto::mark_pareto;
use rayon::prelude::*;
use row::Row;
use table::{csv, markdown};
use timing::{median, time, uniform};

/// What to measure.
#[derive(Clone, Debug)]
pub struct Options {
    /// Sphere image side for the error figures.
    pub size: u32,
    /// Seconds spent timing each throughput figure.
    pub seconds: f64,
    /// Place and route each configuration (Yosys, nextpnr) when they are installed.
    pub yosys: bool,
    /// The family placed, on its default part.
    pub family: Family,
    /// Lanes of each placed design (the model's figures are per lane).
    pub lanes: u32,
    /// Only the paper's configuration (and the octahedral map).
    pub quick: bool,
    /// The scenes measured, (name, scene): [`scenes`] unless the command names one.
    pub scenes: Vec<(String, Scene)>,
    /// The map fits measured for each scene: [`FITS`] unless the command names one.
    pub fits: Vec<MapFit>,
}

/// The map fits measured by default (each on the configurations it applies to, [`measured`]).
pub const FITS: [MapFit; 3] = [MapFit::Sample, MapFit::Lsq, MapFit::Table];

/// Whether a row measures `fit` on `cfg`: a fit the design can hold ([`MapFit::check`]: the
/// `table` fit needs a loaded compensation table), and on a design whose table is loaded with
/// the maps only the fit that fits it (another fit loads the atan table, and its rows would be
/// the ROM design's again).
pub fn measured(fit: MapFit, cfg: &Config) -> bool {
    fit.check(cfg).is_ok() && (cfg.comp_table.is_rom() || fit == MapFit::Table)
}

impl Default for Options {
    fn default() -> Self {
        Options {
            size: 512,
            seconds: 0.3,
            yosys: true,
            family: Family::default(),
            lanes: 1,
            quick: false,
            scenes: scenes(),
            fits: FITS.to_vec(),
        }
    }
}

impl Options {
    /// Progress steps of [`run`]: each scene's reference, each configuration's speed and
    /// synthesis and its (scene, fit) rows, each scene's octahedral map.
    pub fn steps(&self) -> usize {
        configurations(self.quick)
            .iter()
            .map(|(_, c)| {
                1 + self.fits.iter().filter(|&&f| measured(f, c)).count() * self.scenes.len()
            })
            .sum::<usize>()
            + 2 * self.scenes.len()
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
        // The compensation table loaded with the maps and fitted to the scene (issue 33):
        // the paper's maps plus 256 x 7 bits of table, with 4 interpolation bits.
        (
            "I3 P4 table",
            Config {
                interp_bits: 4,
                comp_table: crate::config::CompTable::Ram,
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

/// Measures every row; `progress` is called once per finished step with a description.
pub fn run(opts: &Options, progress: &dyn Fn(&str)) -> Result<Vec<Row>> {
    let grads = uniform(1 << 20);
    let mut out16 = vec![0u16; grads.len()];
    let scenes = &opts.scenes;
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
    for (name, s) in scenes {
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
        figures(&cs, opts.family, opts.lanes)?
    } else {
        vec![Flow::NotRun; configs.len()]
    };
    for ((design, cfg), fig) in configs.into_iter().zip(figures) {
        let placed = match &fig {
            Flow::Placed(r) => Some(r.as_ref()),
            _ => None,
        };
        let model = Model::new(&cfg);
        let fast = FastShader::new(&model, &Scene::standard().maps(&cfg));
        let loaded_table = if cfg.comp_table.is_rom() {
            0
        } else {
            cfg.comp_table_bits()
        };
        let one = grads.len() as f64 / time(opts.seconds, || fast.shade_batch(&grads, &mut out16));
        let all =
            grads.len() as f64 / time(opts.seconds, || fast.shade_batch_par(&grads, &mut out16));
        progress(&format!("{design}: speed and synthesis"));
        // What a host prepares once per configuration; the time of a frame is the fit alone.
        let lsq = LsqFit::new(&cfg);
        let plain = LsqFit::plain(&cfg);
        let minimax = opts
            .fits
            .contains(&MapFit::Minimax)
            .then(|| map_fit::minimax::MinimaxFit::new(&cfg));
        for (k, (name, scene)) in scenes.iter().enumerate() {
            for &fit in opts.fits.iter().filter(|&&f| measured(f, &cfg)) {
                let p = scene.prepared();
                let shade = |n| p.shade(n);
                let build = match fit {
                    MapFit::Sample => median(7, || {
                        drop(std::hint::black_box(map_fit::contents(&cfg, fit, shade)))
                    }),
                    MapFit::Lsq => median(7, || drop(std::hint::black_box(lsq.fit(shade)))),
                    MapFit::LsqPlain => median(7, || drop(std::hint::black_box(plain.fit(shade)))),
                    MapFit::Minimax => {
                        let m = minimax.as_ref().expect("made when minimax is measured");
                        median(3, || drop(std::hint::black_box(m.fit(shade))))
                    }
                    // Seconds a frame: one run.
                    MapFit::Table => median(1, || {
                        drop(std::hint::black_box(map_fit::contents(&cfg, fit, shade)))
                    }),
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
                    // A loaded table is per-frame memory like the maps, not a ROM.
                    rom_bits: cfg.rom_total_bits() - loaded_table,
                    map_bits: cfg.map_total_bits() + loaded_table,
                    ice40_cells: placed.map(|f| f.logic_cells),
                    ice40_brams: placed.map(|f| f.block_rams),
                    fmax_mhz: placed.map(|f| f.fmax_mhz),
                    ice40_too_big: matches!(fig, Flow::DoesNotFit(_)),
                    family: opts.family,
                    lanes: opts.lanes,
                    dsps: placed.filter(|_| opts.family.get().dsps).map(|f| f.dsps),
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
            family: opts.family,
            lanes: opts.lanes,
            dsps: None,
            pareto_cost: false,
            pareto_speed: false,
        });
        progress(&format!("octahedral: {name}"));
    }
    mark_pareto(&mut rows);
    Ok(rows)
}

/// Writes bench.md, bench.csv, bench.json and the plots (PNG and SVG).
pub fn write(rows: &[Row], out: &StagedDir) -> Result<()> {
    out.write_text("bench.md", &markdown(rows))?;
    out.write_text("bench.csv", &csv(rows))?;
    out.write_text("bench.json", &serde_json::to_string_pretty(rows)?)?;
    // The scenes in the order of their first row.
    let mut scene_names: Vec<String> = Vec::new();
    for r in rows {
        if !scene_names.contains(&r.scene) {
            scene_names.push(r.scene.clone());
        }
    }
    let marker = |r: &Row| {
        if r.design.starts_with("octahedral") {
            2
        } else if r.map_fit == "sample" {
            0
        } else if r.map_fit == MapFit::Table.name() {
            3
        } else {
            1
        }
    };
    let index = |r: &Row| scene_names.iter().position(|s| *s == r.scene).unwrap_or(0);
    /// A chart: file, x label, y label, log x, x and y of a row, and the row's mark of the
    /// Pareto front (None: the front of x and y, [`pareto::front`]); its title is apart.
    type Axis<'a> = (
        &'static str,
        &'a str,
        &'static str,
        bool,
        fn(&Row) -> f64,
        fn(&Row) -> f64,
        Option<fn(&Row) -> bool>,
    );
    const KEY: &str =
        "dot sampled, triangle fitted, outlined bar fitted table, cross octahedral; lines: Pareto";
    let cost = format!("ROM + per-frame map (and table) bits; {KEY}");
    let speed = format!("million samples/s, one thread; {KEY}");
    let cost = cost.as_str();
    let rmse = "RMSE (LSB), sphere image";
    let titles = [
        "RMSE against memory",
        "RMSE against speed",
        "Largest error against memory",
    ];
    let charts: [Axis; 3] = [
        (
            "error_vs_cost",
            cost,
            rmse,
            true,
            |r| r.bits() as f64,
            |r| r.rmse,
            Some(|r| r.pareto_cost),
        ),
        (
            "error_vs_speed",
            speed.as_str(),
            rmse,
            false,
            |r| r.msamples_1_thread,
            |r| r.rmse,
            Some(|r| r.pareto_speed),
        ),
        (
            "max_error_vs_cost",
            cost,
            "largest abs error (LSB), sphere image",
            true,
            |r| r.bits() as f64,
            |r| r.max_abs_error as f64,
            None,
        ),
    ];
    for ((file, x_label, y_label, log_x, x, y, on_front), title) in charts.into_iter().zip(&titles)
    {
        let points: Vec<plot::Point> = rows
            .iter()
            .map(|r| plot::Point {
                x: x(r),
                y: y(r),
                scene: index(r),
                marker: marker(r),
            })
            .collect();
        let fronts: Vec<Vec<(f64, f64)>> = scene_names
            .iter()
            .map(|s| {
                let of_scene = rows.iter().filter(|r| r.scene == *s);
                match on_front {
                    Some(on) => {
                        let mut f: Vec<(f64, f64)> =
                            of_scene.filter(|r| on(r)).map(|r| (x(r), y(r))).collect();
                        f.sort_by(|a, b| a.0.total_cmp(&b.0));
                        f
                    }
                    None => pareto::front(&of_scene.map(|r| (x(r), y(r))).collect::<Vec<_>>()),
                }
            })
            .collect();
        let chart = plot::Chart {
            title,
            x_label,
            y_label,
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
