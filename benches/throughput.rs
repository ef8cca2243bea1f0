//! Throughput of the hot paths on the same inputs: the fused bit-exact batch path on one
//! thread and on all cores, the per-stage model it must equal, and the float Phong reference
//! (four lights, specular on) it must beat by 10x. `cargo bench --bench throughput`.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use rmapgen::config::Config;
use rmapgen::model::fast::FastShader;
use rmapgen::model::map_fit::LsqFit;
use rmapgen::model::{reflectance_map, Model};
use rmapgen::reference::Reference;
use rmapgen::rng::SplitMix64;
use rmapgen::scene::Scene;
use std::hint::black_box;

/// Uniform random gradients over the whole `grad_bits` cube (the hardest case for branch
/// prediction: every max axis, sign pattern and shift occurs).
fn uniform(cfg: &Config, n: usize, seed: u64) -> Vec<[i32; 3]> {
    let mut rng = SplitMix64::new(seed);
    let half = 1i64 << (cfg.grad_bits - 1);
    (0..n)
        .map(|_| [(); 3].map(|_| (rng.range(0, 2 * half as u64 - 1) as i64 - half) as i32))
        .collect()
}

fn scene(name: &str) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("scenes")
        .join(name);
    Scene::from_toml_file(&path).expect("scene loads")
}

fn throughput(c: &mut Criterion) {
    let cfg = Config::default();
    let model = Model::new(&cfg);
    let four = scene("four_lights.toml");
    let maps = four.maps(&cfg);
    let fast = FastShader::new(&model, &maps);
    let reference = Reference::new(&cfg, &four);
    // 1M gradients: 12 MB in, 2 MB out, larger than L2, so the input streams as in a render.
    let grads = uniform(&cfg, 1 << 20, 1);
    let mut out = vec![0u16; grads.len()];

    let mut g = c.benchmark_group("shade_1M_uniform");
    g.throughput(Throughput::Elements(grads.len() as u64));
    g.sample_size(20);
    g.bench_function("fast_1_thread", |b| {
        b.iter(|| fast.shade_batch(black_box(&grads), &mut out))
    });
    g.bench_function("fast_all_cores", |b| {
        b.iter(|| fast.shade_batch_par(black_box(&grads), &mut out))
    });
    g.bench_function("model_1_thread", |b| {
        b.iter(|| {
            for (o, &x) in out.iter_mut().zip(black_box(&grads)) {
                *o = model.intensity(&maps, x) as u16;
            }
        })
    });
    g.bench_function("reference_4_lights_1_thread", |b| {
        b.iter(|| {
            for (o, &x) in out.iter_mut().zip(black_box(&grads)) {
                *o = reference.intensity(x) as u16;
            }
        })
    });
    g.bench_function("reference_4_lights_all_cores", |b| {
        b.iter(|| reference.intensities(black_box(&grads)))
    });
    g.finish();

    // Per-frame cost of the fused intensity table (the position table is per configuration).
    let mut g = c.benchmark_group("per_frame");
    g.bench_function("fast_set_maps", |b| {
        b.iter_batched(
            || fast.clone(),
            |mut f| f.set_maps(black_box(&maps)),
            BatchSize::SmallInput,
        )
    });
    g.bench_function("fast_new", |b| {
        b.iter(|| FastShader::new(black_box(&model), black_box(&maps)))
    });
    // Host map build of one frame on the standard scene: sampled, and the least-squares fits
    // (their configuration-only part, LsqFit::new, done once outside the loop).
    let standard = Scene::standard().prepared();
    g.bench_function("map_sample", |b| {
        b.iter(|| reflectance_map::contents(&cfg, |n| standard.shade(black_box(n))))
    });
    let fit = LsqFit::new(&cfg);
    g.bench_function("map_lsq", |b| {
        b.iter(|| fit.fit(|n| standard.shade(black_box(n))))
    });
    let plain = LsqFit::plain(&cfg);
    g.bench_function("map_lsq_plain", |b| {
        b.iter(|| plain.fit(|n| standard.shade(black_box(n))))
    });
    g.bench_function("lsq_precompute_per_config", |b| {
        b.iter(|| LsqFit::new(black_box(&cfg)))
    });
    g.finish();
}

criterion_group!(benches, throughput);
criterion_main!(benches);
