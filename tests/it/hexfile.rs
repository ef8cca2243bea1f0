//! The hex files hold exactly what the model uses: one contents function feeds both.

use rmapgen::config::Config;
use rmapgen::hexfile;
use rmapgen::model::{atan_rom, recip_rom, Model};
use rmapgen::scene::Scene;

fn entries(text: &str) -> Vec<u32> {
    text.lines()
        .filter(|l| !l.starts_with("//"))
        .map(|l| u32::from_str_radix(l, 16).unwrap())
        .collect()
}

#[test]
fn hex_files_equal_model_tables() {
    for cfg in [
        Config::default(),
        Config {
            compensation: false,
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        },
    ] {
        let scene = Scene::standard();
        let files = hexfile::all(&Model::new(&cfg), &scene.maps(&cfg));
        let get = |name: &str| {
            files
                .iter()
                .find(|(n, _)| n == name)
                .map(|(_, t)| entries(t))
        };
        let model = Model::new(&cfg);
        assert_eq!(get("recip_rom.hex").unwrap(), model.recip);
        assert_eq!(get("recip_rom.hex").unwrap(), recip_rom::contents(&cfg));
        assert_eq!(get("atan_rom.hex"), model.atan.clone());
        if cfg.compensation {
            assert_eq!(get("atan_rom.hex").unwrap(), atan_rom::contents(&cfg));
        }
        let maps = scene.maps(&cfg);
        for (axis, n) in ["x", "y", "z"].iter().enumerate() {
            assert_eq!(
                get(&format!("map_{n}.hex")).unwrap(),
                maps.axis(axis as u32)
            );
        }
    }
}

#[test]
fn hex_digits_fit_widths() {
    let cfg = Config::default();
    for (name, text) in hexfile::all(&Model::new(&cfg), &Scene::standard().maps(&cfg)) {
        let w = if name.starts_with("recip") { 3 } else { 2 };
        assert!(
            text.lines()
                .filter(|l| !l.starts_with("//"))
                .all(|l| l.len() == w),
            "{name}"
        );
    }
}
