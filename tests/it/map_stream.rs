//! `rmapgen maps`: the host write stream of a scene's maps. The stream, written through the
//! host port of the generated top in Icarus exactly as its lines say, makes the RTL shade
//! with exactly those entries (and a stream with a wrong address does not); every format
//! decodes to the maps `generate` writes; bad input is one line and exit 2, nothing written.

use super::helpers;
use rmapgen::config::Config;
use rmapgen::map_stream::{self, Format};
use rmapgen::model::map_set::{read_maps, MapSet};
use rmapgen::scene::Scene;
use std::path::Path;
use std::process::Command;

/// A host driver as a testbench: reads the stream with `$readmemh` (three words per write),
/// drives each write through the port one per clock after reset, then swaps with the first
/// sample and checks every result against `vectors.hex` (`gx gy gz zero i`, shaded by the
/// model with the streamed map).
const HOST_TB: &str = r#"`timescale 1ns/1ps
`default_nettype none
module host_tb;
  parameter G = 12, A = 9, M = 8, NW = 1536, NV = 1;
  reg clk_i = 1'b0, rst_ni = 1'b0, valid_i = 1'b0, swap_i = 1'b0, wr_en_i = 1'b0;
  reg [G-1:0] gx_i = 0, gy_i = 0, gz_i = 0;
  reg [1:0] wr_axis_i = 0;
  reg [A-1:0] wr_addr_i = 0;
  reg [M-1:0] wr_data_i = 0;
  wire valid_o, zero_o;
  wire [M-1:0] i_o;
  rmap_top dut (.clk_i(clk_i), .rst_ni(rst_ni), .valid_i(valid_i), .gx_i(gx_i), .gy_i(gy_i),
    .gz_i(gz_i), .swap_i(swap_i), .wr_en_i(wr_en_i), .wr_axis_i(wr_axis_i),
    .wr_addr_i(wr_addr_i), .wr_data_i(wr_data_i), .valid_o(valid_o), .zero_o(zero_o),
    .i_o(i_o));
  always #5 clk_i = ~clk_i;
  reg [15:0] s [0:3*NW-1];
  reg [15:0] v [0:5*NV-1];
  integer k, nout, passed, failed, fd;
  initial begin
    fd = $fopen("stream.hex", "r");
    if (fd == 0) $fatal(1, "no stream.hex");
    $fclose(fd);
    for (k = 0; k < 3*NW; k = k + 1) s[k] = 16'hxxxx;
    $readmemh("stream.hex", s);
    $readmemh("vectors.hex", v);
    if (^s[3*NW-1] === 1'bx || ^v[5*NV-1] === 1'bx) $fatal(1, "short stream or vectors");
    nout = 0; passed = 0; failed = 0;
    repeat (2) @(negedge clk_i);
    rst_ni = 1'b1;
    for (k = 0; k < NW; k = k + 1) begin
      @(negedge clk_i);
      wr_en_i = 1'b1;
      wr_axis_i = s[3*k][1:0];
      wr_addr_i = s[3*k+1][A-1:0];
      wr_data_i = s[3*k+2][M-1:0];
    end
    for (k = 0; k < NV; k = k + 1) begin
      @(negedge clk_i);
      wr_en_i = 1'b0;
      swap_i = (k == 0);
      valid_i = 1'b1;
      gx_i = v[5*k][G-1:0];
      gy_i = v[5*k+1][G-1:0];
      gz_i = v[5*k+2][G-1:0];
    end
    @(negedge clk_i);
    valid_i = 1'b0;
    swap_i = 1'b0;
    repeat (200) @(negedge clk_i);
    if (nout != NV) $display("%0d results for %0d samples", nout, NV);
    $display("%0d passed, %0d failed", passed, failed + (NV - nout));
    $finish;
  end
  always @(negedge clk_i) begin
    if (valid_o) begin
      if ({zero_o, i_o} === {v[5*nout+3][0], v[5*nout+4][M-1:0]}) passed = passed + 1;
      else begin
        failed = failed + 1;
        if (failed < 5) $display("sample %0d: got %0d %0d, expected %0d %0d", nout, zero_o,
          i_o, v[5*nout+3][0], v[5*nout+4][M-1:0]);
      end
      nout = nout + 1;
    end
  end
endmodule
`default_nettype wire
"#;

fn scene_path(name: &str) -> String {
    helpers::root()
        .join("scenes")
        .join(name)
        .to_string_lossy()
        .into_owned()
}

/// Runs the host testbench in `dir` (a generated default design holding `stream.hex` and
/// `vectors.hex`); returns (passed, failed).
fn simulate(dir: &Path, cfg: &Config, vectors: usize) -> (u64, u64) {
    std::fs::write(dir.join("host_tb.v"), HOST_TB).unwrap();
    let mut sources: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".v"))
        .collect();
    sources.sort();
    let params = [
        format!("-Phost_tb.G={}", cfg.grad_bits),
        format!("-Phost_tb.A={}", cfg.map_addr_bits()),
        format!("-Phost_tb.M={}", cfg.map_bits),
        format!("-Phost_tb.NW={}", 3 * cfg.map_entries()),
        format!("-Phost_tb.NV={vectors}"),
    ];
    let c = Command::new("iverilog")
        .current_dir(dir)
        .args(["-g2005", "-s", "host_tb", "-o", "host.vvp"])
        .args(&params)
        .args(&sources)
        .output()
        .expect("iverilog runs");
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let r = Command::new("vvp")
        .current_dir(dir)
        .args(["-N", "host.vvp"])
        .output()
        .expect("vvp runs");
    let out = String::from_utf8_lossy(&r.stdout).into_owned();
    assert!(r.status.success(), "{out}");
    let last = out.lines().last().unwrap_or_default();
    let n: Vec<u64> = last
        .split(|c: char| !c.is_ascii_digit())
        .filter(|s| !s.is_empty())
        .map(|s| s.parse().unwrap())
        .collect();
    assert!(last.ends_with("failed") && n.len() == 2, "{out}");
    (n[0], n[1])
}

#[test]
fn the_exported_stream_written_through_the_host_port_is_what_the_rtl_reads() {
    let t = helpers::tempdir();
    let d = t.path().join("d");
    let cfg = Config::default();
    let o = helpers::run(&["generate", "--vectors", "0", "--out", d.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    // A scene the design does not hold: its map reaches the RTL only through the port.
    let diffuse = scene_path("diffuse.toml");
    let stream = t.path().join("stream.hex");
    let o = helpers::run(&[
        "maps",
        d.to_str().unwrap(),
        "--scene",
        &diffuse,
        "--format",
        "hex",
        "--out",
        stream.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&stream).unwrap();
    std::fs::write(d.join("stream.hex"), &text).unwrap();
    // The model's results with the diffuse scene's map as the second buffer (the vectors'
    // map-1 part), with the corner cases and 3000 random gradients.
    let maps = MapSet::from_scenes(
        &cfg,
        &Scene::standard(),
        &Scene::from_toml_file(Path::new(&diffuse)).unwrap(),
    );
    let all = t.path().join("all.hex");
    rmapgen::vectors::write_top_stream(&cfg, &maps, &all, 6000, 7).unwrap();
    let lines: Vec<String> = std::fs::read_to_string(&all)
        .unwrap()
        .lines()
        .filter_map(|l| l.strip_prefix("1 ").map(String::from))
        .collect();
    assert!(lines.len() > 3000, "{}", lines.len());
    std::fs::write(d.join("vectors.hex"), lines.join("\n") + "\n").unwrap();
    let (passed, failed) = simulate(&d, &cfg, lines.len());
    assert_eq!((passed, failed), (lines.len() as u64, 0));

    // Planted fault: the same stream with i_u and i_v exchanged in every address.
    let i = cfg.index_bits;
    let da = cfg.map_addr_bits().div_ceil(4) as usize;
    let bad: String = text
        .lines()
        .map(|l| {
            if l.starts_with("//") {
                return format!("{l}\n");
            }
            let f: Vec<&str> = l.split(' ').collect();
            let a = u32::from_str_radix(f[1], 16).unwrap();
            let (iu, iv) = ((a >> (i + 1)) & ((1 << i) - 1), a & ((1 << i) - 1));
            let swapped =
                (a & !(((1 << i) - 1) << (i + 1)) & !((1 << i) - 1)) | (iv << (i + 1)) | iu;
            format!("{} {:0da$x} {}\n", f[0], swapped, f[2])
        })
        .collect();
    assert_ne!(bad, text);
    std::fs::write(d.join("stream.hex"), bad).unwrap();
    let (_, failed) = simulate(&d, &cfg, lines.len());
    assert!(failed > 100, "a wrong address must show: {failed} failed");
}

#[test]
fn every_format_holds_the_maps_generate_writes() {
    let t = helpers::tempdir();
    let scene = scene_path("two_lights.toml");
    for flags in [
        vec![],
        vec![
            "--index-bits",
            "4",
            "--no-interpolation",
            "--map-bits",
            "10",
        ],
        vec!["--no-compensation", "--prefix", "p_", "--map-fit", "lsq"],
    ] {
        let d = t.path().join("d");
        let mut a = vec!["generate", "--vectors", "0", "--scene", &scene, "--force"];
        a.extend(&flags);
        a.extend(["--out", d.to_str().unwrap()]);
        let o = helpers::run(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let cfg = rmapgen::design_dir::DesignDir::open(&d).unwrap().config;
        let committed = read_maps(&cfg, &d, 0).unwrap();
        let config = d.join("tb").join("config.toml");
        for (format, name) in [(Format::Hex, "hex"), (Format::Bin, "bin"), (Format::C, "c")] {
            let f = t.path().join(format!("maps.{name}"));
            // The design read (its scene and fit are its manifest's), or its configuration
            // described with the scene and flags it was generated with.
            let mut by_config = vec!["maps", "--config", config.to_str().unwrap()];
            by_config.extend(["--scene", &scene]);
            by_config.extend(&flags);
            for mut a in [vec!["maps", d.to_str().unwrap()], by_config] {
                a.extend(["--format", name, "--out", f.to_str().unwrap()]);
                let o = helpers::run(&a);
                assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
                let bytes = std::fs::read(&f).unwrap();
                let writes = map_stream::decode(format, &bytes).unwrap();
                assert_eq!(writes, map_stream::writes(&cfg, &committed), "{a:?}");
                // A second run replaces the file it wrote without --force.
                let o = helpers::run(&a);
                assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
            }
        }
    }
}

#[test]
fn bad_input_is_one_line_and_writes_nothing() {
    let t = helpers::tempdir();
    let notes = t.path().join("notes.hex");
    std::fs::write(&notes, "my notes\n").unwrap();
    let out = t.path().join("m.hex");
    let o = helpers::run(&["maps", "--format", "xml", "--out", out.to_str().unwrap()]);
    helpers::assert_error(&o, "--format");
    let o = helpers::run(&["maps", "--map-fit", "cubic", "--out", out.to_str().unwrap()]);
    helpers::assert_error(&o, "--map-fit");
    let o = helpers::run(&["maps", "--index-bits", "9", "--out", out.to_str().unwrap()]);
    helpers::assert_error(&o, "--index-bits");
    let rtl = helpers::default_design();
    let o = helpers::run(&[
        "maps",
        &rtl,
        "--scene",
        "/nonexistent.toml",
        "--out",
        out.to_str().unwrap(),
    ]);
    helpers::assert_error(&o, "nonexistent.toml");
    assert!(!out.exists());
    // A file rmapgen did not write is not replaced, in any format.
    for f in ["hex", "bin", "c"] {
        let o = helpers::run(&[
            "maps",
            &rtl,
            "--format",
            f,
            "--out",
            notes.to_str().unwrap(),
        ]);
        helpers::assert_error(&o, "was not written by rmapgen");
        assert_eq!(std::fs::read_to_string(&notes).unwrap(), "my notes\n");
    }
    // rmapgen's own stream, unchanged, is replaced in another format too (the rule of
    // directories: what rmapgen wrote and nobody changed since).
    let o = helpers::run(&[
        "maps",
        &rtl,
        "--format",
        "c",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let o = helpers::run(&[
        "maps",
        &rtl,
        "--format",
        "hex",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    assert_eq!(
        helpers::entries(t.path()),
        [".m.hex.rmapgen-sha256", "m.hex", "notes.hex"]
    );
}

#[test]
fn the_c_array_compiles_and_holds_the_writes() {
    // A C compiler is part of the toolchain (Verilator needs one).
    let t = helpers::tempdir();
    let h = t.path().join("maps.h");
    let o = helpers::run(&[
        "maps",
        "--prefix",
        "q_",
        "--no-interpolation",
        "--format",
        "c",
        "--out",
        h.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let c = t.path().join("main.c");
    std::fs::write(
        &c,
        "#include <stdio.h>\n#include \"maps.h\"\nint main(void) {\n  for (unsigned k = 0; k < \
         Q_RMAP_TOP_MAP_WRITES_COUNT; k++)\n    printf(\"%x %x %x\\n\", q_rmap_top_map_writes[k][0], \
         q_rmap_top_map_writes[k][1], q_rmap_top_map_writes[k][2]);\n  return 0;\n}\n",
    )
    .unwrap();
    let exe = t.path().join("main");
    let cc = Command::new("cc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-o"])
        .arg(&exe)
        .arg(&c)
        .output()
        .expect("cc runs");
    assert!(
        cc.status.success(),
        "{}",
        String::from_utf8_lossy(&cc.stderr)
    );
    let out = Command::new(&exe).output().unwrap();
    let got = map_stream::decode_hex(&String::from_utf8_lossy(&out.stdout)).unwrap();
    let cfg = Config {
        prefix: "q_".into(),
        interpolation: false,
        interp_bits: 0,
        ..Config::default()
    };
    assert_eq!(got, map_stream::writes(&cfg, &Scene::standard().maps(&cfg)));
}

/// Issue 60: `maps DIR` reads the design as every command given a design does (its
/// configuration, prefix and scene from manifest.json), refuses a flag that contradicts it,
/// and with neither a design nor a configuration refuses to assume the default design,
/// whose 12-bit header and `rmap_top_*` names would be wrong for any other.
#[test]
fn maps_reads_the_design_and_refuses_to_guess() {
    let t = helpers::tempdir();
    let d = t.path().join("d");
    let scene = scene_path("grazing.toml");
    let o = helpers::run(&[
        "generate",
        "--grad-bits",
        "8",
        "--red-bits",
        "6",
        "--prefix",
        "cam0_",
        "--scene",
        &scene,
        "--vectors",
        "0",
        "--out",
        d.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let design = rmapgen::design_dir::DesignDir::open(&d).unwrap();
    let committed = read_maps(&design.config, &d, 0).unwrap();
    let h = t.path().join("maps.h");
    let ds = d.to_str().unwrap();
    let o = helpers::run(&["maps", ds, "--format", "c", "--out", h.to_str().unwrap()]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&h).unwrap();
    assert!(
        text.starts_with("/* rmapgen map stream: scene grazing.toml, map_fit sample, G8 R6 "),
        "{text}"
    );
    assert!(
        text.contains(
            "static const uint16_t cam0_rmap_top_map_writes[CAM0_RMAP_TOP_MAP_WRITES_COUNT][3]"
        ),
        "{text}"
    );
    let writes = map_stream::decode(Format::C, text.as_bytes()).unwrap();
    assert_eq!(writes, map_stream::writes(&design.config, &committed));
    // Flags that agree are taken; one that contradicts the design is refused, naming both.
    let hex = t.path().join("m.hex");
    let o = helpers::run(&[
        "maps",
        ds,
        "--grad-bits",
        "8",
        "--prefix",
        "cam0_",
        "--out",
        hex.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    std::fs::remove_file(&hex).unwrap();
    let record = t.path().join(".m.hex.rmapgen-sha256");
    std::fs::remove_file(&record).unwrap();
    for (flags, want) in [
        (
            vec!["--grad-bits", "12"],
            "d: --grad-bits 12 sets grad_bits 12, the design has 8",
        ),
        (
            vec!["--prefix", "cam1_"],
            "--prefix cam1_ sets prefix \"cam1_\", the design has \"cam0_\"",
        ),
        (vec!["--map-fit", "table"], "map_fit table"),
    ] {
        let mut a = vec!["maps", ds];
        a.extend(flags);
        a.extend(["--out", hex.to_str().unwrap()]);
        helpers::assert_error(&helpers::run(&a), want);
        assert!(!hex.exists() && !record.exists());
    }
    // Neither a design nor a configuration: refused, nothing written.
    let before = helpers::entries(t.path());
    for a in [
        vec!["maps", "--out", hex.to_str().unwrap()],
        vec![
            "maps",
            "--scene",
            &scene,
            "--format",
            "bin",
            "--out",
            hex.to_str().unwrap(),
        ],
    ] {
        helpers::assert_error(
            &helpers::run(&a),
            "maps: give the design (rmapgen maps DIR) or its configuration (--config FILE or the flags it was generated with)",
        );
    }
    // Not a design.
    let not = t.path().join("scenes");
    std::fs::create_dir(&not).unwrap();
    helpers::assert_error(
        &helpers::run(&[
            "maps",
            not.to_str().unwrap(),
            "--out",
            hex.to_str().unwrap(),
        ]),
        "is not a design rmapgen generated (no manifest.json)",
    );
    std::fs::remove_dir(&not).unwrap();
    assert_eq!(helpers::entries(t.path()), before);
}
