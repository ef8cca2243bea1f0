use glam::DVec3;
use rmapgen::{config::Config, model::{reflectance_map, Model}, scene::Scene};
fn main() {
    let scene = Scene::from_toml_file(std::path::Path::new(&std::env::args().nth(1).unwrap_or("scenes/standard.toml".into()))).unwrap();
    let p = scene.prepared();
    for (comp, interp) in [(true, true), (false, true), (true, false), (false,false)] {
        let cfg = Config { compensation: comp, interpolation: interp, interp_bits: if interp {3} else {0}, ..Config::default() };
        let m = Model::new(&cfg);
        let maps = reflectance_map::contents(&cfg, |n| p.shade(n));
        let n = 512; let (mut se, mut mx, mut cnt) = (0f64, 0i64, 0);
        for j in 0..n { for i in 0..n {
            let x = 2.0*(i as f64+0.5)/n as f64-1.0; let y = -(2.0*(j as f64+0.5)/n as f64-1.0);
            let r2 = x*x+y*y; if r2 > 1.0 { continue; }
            let nn = DVec3::new(x, y, (1.0-r2).sqrt());
            let g = (nn * 2047.0).round();
            let gi = [g.x as i32, g.y as i32, g.z as i32];
            let gn = DVec3::new(g.x, g.y, g.z).normalize();
            let rf = reflectance_map::quantise(&cfg, p.shade(gn)) as i64;
            let md = m.intensity(&maps, gi) as i64;
            let e = md - rf; se += (e*e) as f64; mx = mx.max(e.abs()); cnt += 1;
        }}
        let rmse = (se/cnt as f64).sqrt();
        println!("comp={comp} interp={interp}: max {mx} rmse {rmse:.3} psnr {:.2}", 20.0*(255.0/rmse).log10());
    }
}
