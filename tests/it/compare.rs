//! `rmapgen compare`: error statistics of one PNG against another, checked on images whose
//! differences are planted, so every figure it prints is known in advance.

use crate::helpers::{assert_error, run, tempdir};
use image::{ImageBuffer, Luma, Rgba};
use std::path::Path;

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// `rmapgen compare --json image reference`, parsed.
fn json(image: &Path, reference: &Path) -> serde_json::Value {
    let out = run(&["compare", "--json", s(image), s(reference)]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn the_figures_are_those_of_the_planted_differences() {
    let tmp = tempdir();
    let (w, h) = (20u32, 10u32);
    let base = |x: u32, y: u32| ((x * 7 + y * 13) % 200) as u8;
    let reference = ImageBuffer::from_fn(w, h, |x, y| Luma([base(x, y)]));
    // +3 at (4, 2), -1 at (17, 9): max 3 there, mean abs 4/200, mean 2/200, RMSE sqrt(10/200).
    let image = ImageBuffer::from_fn(w, h, |x, y| {
        let d: i32 = match (x, y) {
            (4, 2) => 3,
            (17, 9) => -1,
            _ => 0,
        };
        Luma([(base(x, y) as i32 + d) as u8])
    });
    let (a, b) = (tmp.path().join("a.png"), tmp.path().join("b.png"));
    image.save(&a).unwrap();
    reference.save(&b).unwrap();

    let out = run(&["compare", s(&a), s(&b)]);
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{text}");
    let psnr = 20.0 * (255.0 / (10.0f64 / 200.0).sqrt()).log10();
    for want in [
        "20x10 gray8 (200 samples)",
        "max abs error 3 LSB at pixel (4, 2) channel 0",
        "mean abs error 0.0200",
        "mean error +0.0100",
        &format!("PSNR {psnr:.2} dB"),
    ] {
        assert!(text.contains(want), "{want:?} in {text}");
    }

    let j = json(&a, &b);
    assert_eq!(j["max_abs_error"], 3);
    assert_eq!(j["worst_pixel"], serde_json::json!([4, 2, 0]));
    assert_eq!(j["abs_error_histogram"], serde_json::json!([198, 1, 0, 1]));
    assert_eq!(j["peak"], 255);

    let out = run(&["compare", s(&b), s(&b)]);
    assert!(String::from_utf8_lossy(&out.stdout).contains(": identical"));
}

#[test]
fn sixteen_bit_and_rgba_images_use_their_own_peak_and_channels() {
    let tmp = tempdir();
    let g16 = |d: u16| ImageBuffer::from_fn(4, 4, move |x, _| Luma([1000 * x as u16 + d]));
    let (a, b) = (tmp.path().join("a16.png"), tmp.path().join("b16.png"));
    g16(0).save(&a).unwrap();
    g16(300).save(&b).unwrap();
    let j = json(&a, &b);
    assert_eq!(j["kind"], "gray16");
    assert_eq!(j["peak"], 65535);
    assert_eq!(j["max_abs_error"], 300);

    // RGBA: only the alpha of pixel (1, 0) differs, so the worst sample is channel 3.
    let rgba = |alpha: u8| {
        ImageBuffer::from_fn(3, 2, move |x, y| {
            Rgba([10, 20, 30, if (x, y) == (1, 0) { alpha } else { 255 }])
        })
    };
    let (c, d) = (tmp.path().join("c.png"), tmp.path().join("d.png"));
    rgba(250).save(&c).unwrap();
    rgba(255).save(&d).unwrap();
    let j = json(&c, &d);
    assert_eq!(j["kind"], "rgba8");
    assert_eq!(j["pixels"], 24);
    assert_eq!(j["worst_pixel"], serde_json::json!([1, 0, 3]));

    // A grey image against an RGBA one of the same size: refused, naming both kinds.
    let grey = tmp.path().join("grey.png");
    ImageBuffer::from_fn(3, 2, |_, _| Luma([1u8]))
        .save(&grey)
        .unwrap();
    assert_error(&run(&["compare", s(&grey), s(&d)]), "is 3x2 gray8 and");
}

#[test]
fn bad_inputs_give_one_line_and_exit_2() {
    let tmp = tempdir();
    let small = tmp.path().join("small.png");
    let big = tmp.path().join("big.png");
    ImageBuffer::from_fn(2, 2, |_, _| Luma([0u8]))
        .save(&small)
        .unwrap();
    ImageBuffer::from_fn(3, 2, |_, _| Luma([0u8]))
        .save(&big)
        .unwrap();
    assert_error(
        &run(&["compare", s(&small), s(&big)]),
        "compare needs images of the same size and kind",
    );
    let missing = tmp.path().join("missing.png");
    assert_error(&run(&["compare", s(&missing), s(&big)]), "reading");
    let text = tmp.path().join("not.png");
    std::fs::write(&text, "not a png").unwrap();
    assert_error(&run(&["compare", s(&text), s(&big)]), "decoding");
    // Nothing is written beside the inputs.
    let mut names: Vec<String> = std::fs::read_dir(tmp.path())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(names, ["big.png", "not.png", "small.png"]);
}
