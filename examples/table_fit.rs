//! The fitted compensation table (issue 33), measured: for each scene given, the default
//! configuration (or `--interp-bits P`) with the atan table and minimax maps against a table
//! fitted to the scene with its minimax maps, on the 512² and 1024² spheres against the float
//! reference, and the fit's time. docs/PERFORMANCE.md has the figures.
//!
//!     cargo run --release --example table_fit -- [--interp-bits P] scenes/standard.toml ...

use anyhow::{bail, Context, Result};
use rmapgen::config::Config;
use rmapgen::model::map_fit::table_fit::TableFit;
use rmapgen::model::{Maps, Model};
use rmapgen::reference::Reference;
use rmapgen::render::{metrics, model_intensities, sphere_gradients};
use rmapgen::scene::Scene;
use std::time::Instant;

fn sphere(model: &Model, maps: &Maps, scene: &Scene, size: u32) -> (u32, f64) {
    let cfg = &model.cfg;
    let g: Vec<[i32; 3]> = sphere_gradients(cfg, size, 0).iter().map(|p| p.2).collect();
    let m = metrics(
        &model_intensities(model, maps, &g),
        &Reference::new(cfg, scene).intensities(&g),
        cfg.map_max(),
    );
    (m.max_abs_error, m.psnr_db.unwrap_or(f64::INFINITY))
}

fn main() -> Result<()> {
    let mut cfg = Config::default();
    let mut scenes = Vec::new();
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--interp-bits" => {
                cfg.interp_bits = args.next().context("--interp-bits N")?.parse()?;
            }
            s if s.starts_with('-') => bail!("unknown flag {s}"),
            path => scenes.push(path.to_string()),
        }
    }
    cfg.validate()?;
    let t = Instant::now();
    let fit = TableFit::new(&cfg);
    println!(
        "{}: code ranges in {:.2} s",
        cfg.summary(),
        t.elapsed().as_secs_f64()
    );
    println!("| scene | atan table, minimax maps (512², 1024²) | fitted table (512², 1024²) | bound | fit |");
    println!("|---|---|---|---|---|");
    for path in scenes {
        let scene = Scene::from_toml_file(path.as_ref())?;
        let p = scene.prepared();
        let t = Instant::now();
        let (table, maps, r) = fit.fit(|n| p.shade(n));
        let secs = t.elapsed().as_secs_f64();
        let atan_model = Model::new(&cfg);
        let (atan_maps, _) = fit.maps(atan_model.atan.as_ref().expect("compensation"), &|n| {
            p.shade(n)
        });
        let (a512, adb) = sphere(&atan_model, &atan_maps, &scene, 512);
        let (a1024, _) = sphere(&atan_model, &atan_maps, &scene, 1024);
        let mut model = Model::new(&cfg);
        model.atan = Some(table);
        let (f512, fdb) = sphere(&model, &maps, &scene, 512);
        let (f1024, _) = sphere(&model, &maps, &scene, 1024);
        println!(
            "| {path} | {a512} ({adb:.2} dB), {a1024} | **{f512}** ({fdb:.2} dB), {f1024} | {:.1} → {:.1} | {secs:.1} s, {} entries moved |",
            r.atan_bound, r.bound, r.changed
        );
    }
    Ok(())
}
