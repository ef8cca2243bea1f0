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

/// A PNG of 8-bit RGBA `pixels` (row by row), written with Adam7 interlacing when
/// `interlaced` (neither the `image` nor the `png` encoder writes it): every pass's rows, each
/// with filter type 0, in one zlib stream.
fn rgba_png(path: &Path, w: u32, h: u32, pixels: &[u8], interlaced: bool) {
    use std::io::Write;
    const PASSES: [(u32, u32, u32, u32); 7] = [
        (0, 0, 8, 8),
        (4, 0, 8, 8),
        (0, 4, 4, 8),
        (2, 0, 4, 4),
        (0, 2, 2, 4),
        (1, 0, 2, 2),
        (0, 1, 1, 2),
    ];
    let full = [(0, 0, 1, 1)];
    let passes: &[(u32, u32, u32, u32)] = if interlaced { &PASSES } else { &full };
    let mut raw = Vec::new();
    for &(x0, y0, dx, dy) in passes {
        if x0 >= w || y0 >= h {
            continue; // an empty pass has no rows
        }
        for y in (y0..h).step_by(dy as usize) {
            raw.push(0);
            for x in (x0..w).step_by(dx as usize) {
                let i = ((y * w + x) * 4) as usize;
                raw.extend_from_slice(&pixels[i..i + 4]);
            }
        }
    }
    let mut z = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::fast());
    z.write_all(&raw).unwrap();
    let idat = z.finish().unwrap();
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    let mut chunk = |kind: &[u8], data: &[u8]| {
        png.extend_from_slice(&(data.len() as u32).to_be_bytes());
        let mut crc = flate2::Crc::new();
        crc.update(kind);
        crc.update(data);
        png.extend_from_slice(kind);
        png.extend_from_slice(data);
        png.extend_from_slice(&crc.sum().to_be_bytes());
    };
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&w.to_be_bytes());
    ihdr.extend_from_slice(&h.to_be_bytes());
    ihdr.extend_from_slice(&[8, 6, 0, 0, interlaced as u8]);
    chunk(b"IHDR", &ihdr);
    chunk(b"IDAT", &idat);
    chunk(b"IEND", &[]);
    std::fs::write(path, png).unwrap();
}

/// Two RGBA images of `w` x `h` whose samples differ by a known pattern.
fn rgba_pair(w: u32, h: u32) -> (Vec<u8>, Vec<u8>) {
    let n = (w * h * 4) as usize;
    let a: Vec<u8> = (0..n).map(|i| (i * 7 % 251) as u8).collect();
    let b: Vec<u8> = a
        .iter()
        .enumerate()
        .map(|(i, &v)| if i % 97 == 0 { v.wrapping_add(3) } else { v })
        .collect();
    (a, b)
}

/// The memory of a comparison (issue 32 §5: two 16000² RGBA PNGs, 1.02 GB decoded each,
/// allocated 4.1 GB and aborted under `ulimit -v 4000000`: both were decoded, then both
/// widened to u32, 10 times one image's decoded size in all). Non-interlaced images are
/// streamed row by row: the peak is the two decoders' state and a row each, about 0.7 MiB,
/// the same for an 8 MiB image as for a 1 MiB one (asserted: under 1 MiB, growing by less
/// than 64 KiB). An interlaced image is held whole, once: the peak is its decoded size plus
/// that (k = 1 per interlaced input, plus 1 MiB), never a converted copy.
#[test]
fn compare_memory_is_rows_or_one_decoded_image() {
    const MIB: usize = 1 << 20;
    let tmp = tempdir();
    let path = |n: &str| tmp.path().join(n);
    let compare = rmapgen::cmd::compare::compare;
    let mut streamed = Vec::new();
    for (w, h) in [(1024u32, 256u32), (1024, 2048)] {
        let decoded = (w * h * 4) as usize; // 1 MiB, 8 MiB
        let (a, b) = rgba_pair(w, h);
        rgba_png(&path("a.png"), w, h, &a, false);
        rgba_png(&path("b.png"), w, h, &b, false);
        rgba_png(&path("ai.png"), w, h, &a, true);
        rgba_png(&path("bi.png"), w, h, &b, true);

        let (plain, peak) = crate::alloc::peak_during(|| compare(&path("a.png"), &path("b.png")));
        let plain = plain.unwrap();
        eprintln!("{w}x{h} RGBA8 ({decoded} bytes decoded each): peak {peak} bytes streamed");
        assert!(
            peak < MIB,
            "streamed: peak {peak} bytes for {decoded}-byte images"
        );
        streamed.push(peak);
        assert_eq!(plain.metrics.max_abs_error, 3);
        assert_eq!(plain.metrics.abs_error_histogram[3], decoded.div_ceil(97));

        // Interlaced: the same figures, one image held whole for each interlaced input.
        for (x, y, held) in [("ai.png", "b.png", 1), ("ai.png", "bi.png", 2)] {
            let (r, peak) = crate::alloc::peak_during(|| compare(&path(x), &path(y)));
            eprintln!("{x} against {y}: peak {peak} bytes");
            assert!(peak >= held * decoded, "interlaced held whole: peak {peak}");
            assert!(
                peak <= held * decoded + MIB,
                "{x} against {y}: peak {peak} bytes"
            );
            assert_eq!(r.unwrap().metrics, plain.metrics);
        }
    }
    assert!(
        streamed[1] < streamed[0] + MIB / 16,
        "the streamed peak grows with the image: {streamed:?}"
    );
}

/// An interlaced PNG compares equal to the same image not interlaced, and its rows come in
/// image order (a planted difference is found at its own pixel).
#[test]
fn interlaced_images_compare_by_pixel() {
    let tmp = tempdir();
    let (w, h) = (13u32, 11u32); // not multiples of 8: partial passes
    let (a, _) = rgba_pair(w, h);
    let mut b = a.clone();
    b[((6 * w + 5) * 4 + 2) as usize] ^= 0x10; // pixel (5, 6), channel 2
    let (p, q, r) = (
        tmp.path().join("p.png"),
        tmp.path().join("q.png"),
        tmp.path().join("r.png"),
    );
    rgba_png(&p, w, h, &a, true);
    rgba_png(&q, w, h, &a, false);
    rgba_png(&r, w, h, &b, true);
    let out = run(&["compare", s(&p), s(&q)]);
    assert!(String::from_utf8_lossy(&out.stdout).contains(": identical"));
    let j = json(&p, &r);
    assert_eq!(j["worst_pixel"], serde_json::json!([5, 6, 2]));
    assert_eq!(j["max_abs_error"], 16);
}
