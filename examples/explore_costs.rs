//! The measurements behind the explorer's cost model (src/explore/cost.rs): the CPU time
//! (user + system, all threads: core-seconds) of the map fits that can take more than a
//! moment, over every index_bits and interp_bits, at the default configuration otherwise and
//! the standard scene; then what the other fields and the image cost on top. A measurement
//! past `--seconds` of wall time is stopped (through the same cancel points as the explorer)
//! and printed as `over`. Each line also gives the cost model's prediction.
//!
//!     cargo run --release --example explore_costs -- [--seconds S] [--only minimax|table|factors|renders]

use anyhow::{bail, Context, Result};
use rmapgen::cancel::Pool;
use rmapgen::config::Config;
use rmapgen::explore::cost;
use rmapgen::model::map_fit::MapFit;
use rmapgen::scene::Scene;
use std::time::{Duration, Instant};

/// Core-seconds used by this process so far.
fn cpu() -> f64 {
    // SAFETY: getrusage writes the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let t = |v: libc::timeval| v.tv_sec as f64 + v.tv_usec as f64 * 1e-6;
    t(u.ru_utime) + t(u.ru_stime)
}

/// Runs `f` on `pool`, stopped after `limit` of wall time: its core-seconds and wall
/// seconds, or None when stopped.
fn measure(pool: &Pool, limit: Duration, f: impl FnOnce() + Send) -> (Option<f64>, f64) {
    pool.reset();
    let (tx, rx) = std::sync::mpsc::channel::<()>();
    let flag = pool.flag();
    let watch = std::thread::spawn(move || {
        if rx.recv_timeout(limit).is_err() {
            flag.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    });
    let (c, t) = (cpu(), Instant::now());
    let r = pool.run(f);
    let used = cpu() - c;
    drop(tx);
    watch.join().ok();
    (r.ok().map(|_| used), t.elapsed().as_secs_f64())
}

fn line(what: &str, cfg: &Config, scene: &Scene, size: u32, volume: bool, got: (Option<f64>, f64)) {
    let e = cost::estimate(cfg, scene, size, volume);
    let measured = got.0.map_or("over".to_string(), |c| format!("{c:.2}"));
    println!(
        "{what:<40} measured {measured:>7} core-s ({:.1} s wall)  model {:>8.2} core-s {:>6} MiB",
        got.1,
        e.core_seconds,
        e.bytes >> 20
    );
}

fn main() -> Result<()> {
    let mut limit = Duration::from_secs(90);
    let mut only = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seconds" => {
                limit = Duration::from_secs(args.next().context("--seconds S")?.parse()?)
            }
            "--only" => only = Some(args.next().context("--only WHAT")?),
            s => bail!("unknown argument {s}"),
        }
    }
    let pool = Pool::new(0)?;
    let want = |w: &str| only.as_deref().is_none_or(|o| o == w);
    let with = |cfg: &Config, fit: MapFit, lights: usize| {
        let mut s = Scene::standard();
        s.map_fit = fit;
        let l = s.lights[0].clone();
        s.lights = vec![l; lights];
        s.validate()
            .map(|_| s)
            .ok()
            .filter(|_| fit.check(cfg).is_ok() && cfg.validate().is_ok())
    };
    let fit_only = |cfg: &Config, s: &Scene| measure(&pool, limit, || drop(s.maps(cfg)));
    for fit in [MapFit::Minimax, MapFit::Table] {
        if !want(fit.name()) {
            continue;
        }
        for index_bits in 2..=6 {
            let mut over = false;
            for interp_bits in 0..=5 {
                let cfg = Config {
                    index_bits,
                    interp_bits,
                    interpolation: interp_bits > 0,
                    comp_table: if fit == MapFit::Table {
                        rmapgen::config::CompTable::Ram
                    } else {
                        Config::default().comp_table
                    },
                    ..Config::default()
                };
                let Some(s) = with(&cfg, fit, 1) else {
                    println!("{} index_bits {index_bits} interp_bits {interp_bits}: refused by the configuration", fit.name());
                    continue;
                };
                let what = format!(
                    "{} index_bits {index_bits} interp_bits {interp_bits}",
                    fit.name()
                );
                // Past the limit at fewer interpolation bits: past it at more too.
                let got = if over {
                    (None, 0.0)
                } else {
                    fit_only(&cfg, &s)
                };
                over |= got.0.is_none();
                line(&what, &cfg, &s, 16, false, got);
            }
        }
    }
    if want("factors") {
        let base = Config::default();
        let ram = Config {
            comp_table: rmapgen::config::CompTable::Ram,
            ..base.clone()
        };
        let cases: Vec<(&str, Config, MapFit, usize)> = vec![
            ("minimax 8 lights", base.clone(), MapFit::Minimax, 8),
            (
                "minimax map_bits 6",
                Config {
                    map_bits: 6,
                    ..base.clone()
                },
                MapFit::Minimax,
                1,
            ),
            (
                "minimax map_bits 10",
                Config {
                    map_bits: 10,
                    ..base.clone()
                },
                MapFit::Minimax,
                1,
            ),
            (
                "minimax map_bits 12",
                Config {
                    map_bits: 12,
                    ..base.clone()
                },
                MapFit::Minimax,
                1,
            ),
            (
                "minimax grad_bits 8",
                Config {
                    grad_bits: 8,
                    red_bits: 6,
                    ..base.clone()
                },
                MapFit::Minimax,
                1,
            ),
            (
                "minimax grad_bits 16",
                Config {
                    grad_bits: 16,
                    ..base.clone()
                },
                MapFit::Minimax,
                1,
            ),
            (
                "minimax frac_bits 12",
                Config {
                    frac_bits: 12,
                    recip_bits: 13,
                    ..base.clone()
                },
                MapFit::Minimax,
                1,
            ),
            (
                "minimax index 4 interp 5 frac 12",
                Config {
                    index_bits: 4,
                    interp_bits: 5,
                    frac_bits: 12,
                    recip_bits: 13,
                    ..base.clone()
                },
                MapFit::Minimax,
                1,
            ),
            ("table 8 lights", ram.clone(), MapFit::Table, 8),
            (
                "table map_bits 12",
                Config {
                    map_bits: 12,
                    ..ram.clone()
                },
                MapFit::Table,
                1,
            ),
            (
                "table grad_bits 16",
                Config {
                    grad_bits: 16,
                    ..ram.clone()
                },
                MapFit::Table,
                1,
            ),
            (
                "table frac_bits 6",
                Config {
                    frac_bits: 6,
                    ..ram.clone()
                },
                MapFit::Table,
                1,
            ),
            (
                "table frac_bits 9",
                Config {
                    frac_bits: 9,
                    ..ram.clone()
                },
                MapFit::Table,
                1,
            ),
            (
                "table index 5 frac 11",
                Config {
                    index_bits: 5,
                    frac_bits: 11,
                    recip_bits: 12,
                    interp_bits: 1,
                    ..ram.clone()
                },
                MapFit::Table,
                1,
            ),
            (
                "lsq 8 lights index 6 interp 5",
                Config {
                    index_bits: 6,
                    interp_bits: 5,
                    ..base.clone()
                },
                MapFit::Lsq,
                8,
            ),
        ];
        for (what, cfg, fit, lights) in cases {
            match with(&cfg, fit, lights) {
                Some(s) => line(what, &cfg, &s, 16, false, fit_only(&cfg, &s)),
                None => println!("{what}: refused by the configuration"),
            }
        }
    }
    if want("renders") {
        let cfg = Config::default();
        for (lights, size, volume) in [
            (1, 256, false),
            (8, 512, false),
            (1, 256, true),
            (8, 512, true),
        ] {
            let mut s = if volume {
                Scene::from_toml_str(rmapgen::volume::ENGINE_SCENE_TOML)?
            } else {
                Scene::standard()
            };
            let l = s.lights[0].clone();
            s.lights = vec![l; lights];
            let ex = rmapgen::explore::Explorer::new(0, rmapgen::explore::LIMITS)?;
            let body = serde_json::json!({
                "config": {}, "scene": serde_json::to_value(&s)?, "size": size,
                "object": if volume { "volume" } else { "sphere" },
            })
            .to_string();
            let what = format!(
                "render {} {size}² {lights} lights",
                if volume { "volume" } else { "sphere" }
            );
            let (c, t) = (cpu(), Instant::now());
            let r = ex.answer("POST", "/api/render", body.as_bytes());
            let first = (r.status == 200).then_some(cpu() - c);
            line(
                &format!("{what} (first)"),
                &cfg,
                &s,
                size,
                volume,
                (first, t.elapsed().as_secs_f64()),
            );
            let (c, t) = (cpu(), Instant::now());
            let r = ex.answer("POST", "/api/render", body.as_bytes());
            let again = (r.status == 200).then_some(cpu() - c);
            line(
                &format!("{what} (again)"),
                &cfg,
                &s,
                size,
                volume,
                (again, t.elapsed().as_secs_f64()),
            );
        }
    }
    Ok(())
}
