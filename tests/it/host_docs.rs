//! The generated README's host-facing facts, checked against the model and the RTL rather
//! than for presence: the address fields' bits against the address encoder; the u/v axes,
//! index tangents, scene and light-model formula, read from the README alone, reproduce every
//! entry of `map_<axis>.hex` (line k = address k); the latency edges, reset and write-port
//! behaviour it states against the generated top in Icarus.

use super::helpers;
use rmapgen::config::Config;
use rmapgen::design::Design;
use rmapgen::emit::package::readme;
use rmapgen::model::map_addr;
use rmapgen::model::map_set::read_maps;
use rmapgen::scene::Scene;
use std::path::Path;
use std::process::Command;

/// The rows of the first Markdown table after `heading`, cells trimmed.
fn table(readme: &str, heading: &str, after: &str) -> Vec<Vec<String>> {
    let start = readme
        .find(heading)
        .unwrap_or_else(|| panic!("no {heading}"));
    let rest = &readme[start..];
    let rest = &rest[rest.find(after).unwrap_or_else(|| panic!("no {after}"))..];
    rest.lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().trim_matches('`').to_string())
                .collect()
        })
        .collect()
}

fn configs() -> Vec<Config> {
    vec![
        Config::default(),
        Config {
            index_bits: 2,
            compensation: false,
            ..Config::default()
        },
        Config {
            index_bits: 6,
            interpolation: false,
            interp_bits: 0,
            ..Config::default()
        },
    ]
}

#[test]
fn address_fields_are_where_the_encoder_puts_them() {
    for cfg in configs() {
        let text = readme(&Design::for_scene(&cfg, &Scene::standard()).unwrap()).unwrap();
        let a = cfg.map_addr_bits();
        assert!(
            text.contains(&format!("`wr_addr_i` ({a} bits)")),
            "{}",
            cfg.summary()
        );
        let rows = table(&text, "## Map addresses", "| field |");
        let names: Vec<&str> = rows.iter().map(|r| r[0].as_str()).collect();
        assert_eq!(names, ["s_max", "s_u", "i_u", "s_v", "i_v"]);
        for (k, row) in rows.iter().enumerate() {
            // The field at its largest value, alone, through the encoder.
            let mut f = [0u32; 5];
            f[k] = if k == 2 || k == 4 {
                cfg.entries() - 1
            } else {
                1
            };
            let bits = map_addr::addr(&cfg, f[0], f[1], f[2], f[3], f[4]);
            let (lo, hi) = (bits.trailing_zeros(), 31 - bits.leading_zeros());
            let want = if lo == hi {
                format!("[{lo}]")
            } else {
                format!("[{hi}:{lo}]")
            };
            assert_eq!(row[1], want, "{} {}", row[0], cfg.summary());
            assert_eq!(row[2], bits.count_ones().to_string(), "{}", row[0]);
        }
    }
}

/// The scene in the README's TOML block.
fn scene_of(text: &str) -> toml::Value {
    let block = text.split("```toml\n").nth(1).expect("a toml block");
    toml::from_str(block.split("```").next().unwrap()).expect("TOML")
}

fn vec3(v: &toml::Value) -> [f64; 3] {
    let a = v.as_array().expect("array");
    [0, 1, 2].map(|k| a[k].as_float().expect("float"))
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn unit(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    a.map(|x| x / l)
}

/// Every entry of the design in `dir`, computed from its README alone: the address table,
/// the u/v table, the tangent column the README says the design uses, the scene and the
/// light-model formula. Returns (entries that differ, entries that differ by more than 1 LSB).
fn from_readme(dir: &Path, cfg: &Config) -> (usize, usize) {
    let text = std::fs::read_to_string(dir.join("README.md")).unwrap();
    let fields = table(&text, "## Map addresses", "| field |");
    let field = |name: &str, addr: u32| {
        let r = fields.iter().find(|r| r[0] == name).unwrap();
        let b = r[1].trim_matches(['[', ']']);
        let (hi, lo) = match b.split_once(':') {
            Some((h, l)) => (h.parse::<u32>().unwrap(), l.parse::<u32>().unwrap()),
            None => (b.parse().unwrap(), b.parse().unwrap()),
        };
        (addr >> lo) & ((1 << (hi - lo + 1)) - 1)
    };
    let uv = table(&text, "## Map addresses", "| `wr_axis_i` | max axis |");
    let comp = text.contains("This design has compensation **on**");
    assert!(comp || text.contains("This design has compensation **off**"));
    let tangents: Vec<f64> = table(&text, "## Map addresses", "| i | t(i)")
        .iter()
        .map(|r| r[if comp { 1 } else { 2 }].parse().unwrap())
        .collect();
    assert_eq!(tangents.len() as u32, cfg.entries());
    let s = scene_of(&text);
    let m = &s["material"];
    let num = |k: &str| m[k].as_float().unwrap();
    let view = unit(vec3(&s["view"]["direction"]));
    let two_sided = s["view"]["two_sided"].as_bool().unwrap();
    let lights: Vec<([f64; 3], f64)> = s["light"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| {
            (
                unit(vec3(&l["direction"])),
                l["intensity"].as_float().unwrap(),
            )
        })
        .collect();
    let max: f64 = text
        .split("scaled to\n  2^M - 1 = ")
        .nth(1)
        .unwrap()
        .split(' ')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    let axis_index = |name: &str| ["x", "y", "z"].iter().position(|a| *a == name).unwrap();
    let committed = read_maps(cfg, dir, 0).unwrap();
    let (mut differ, mut far) = (0, 0);
    for axis in 0..3u32 {
        let row = &uv[axis as usize];
        for addr in 0..cfg.map_entries() {
            let sgn = |b: u32| if b == 1 { -1.0 } else { 1.0 };
            let mut n = [0.0; 3];
            n[axis_index(&row[1])] = sgn(field("s_max", addr));
            n[axis_index(&row[2])] =
                sgn(field("s_u", addr)) * tangents[field("i_u", addr) as usize];
            n[axis_index(&row[3])] =
                sgn(field("s_v", addr)) * tangents[field("i_v", addr) as usize];
            let mut n = unit(n);
            if two_sided && dot(n, view) < 0.0 {
                n = n.map(|x| -x);
            }
            let mut l_sum = num("ambient");
            for &(l, i) in &lights {
                let nl = dot(n, l);
                if nl > 0.0 {
                    let r = [0, 1, 2].map(|k| 2.0 * nl * n[k] - l[k]);
                    l_sum += i
                        * (num("diffuse") * nl
                            + num("specular") * dot(r, view).max(0.0).powf(num("shininess")));
                }
            }
            let entry = (l_sum.clamp(0.0, 1.0) * max + 0.5).floor() as i64;
            let got = committed.get(axis, addr) as i64;
            if entry != got {
                differ += 1;
                if (entry - got).abs() > 1 {
                    far += 1;
                }
            }
        }
    }
    (differ, far)
}

#[test]
fn the_readme_alone_gives_every_map_entry() {
    let t = helpers::tempdir();
    for (k, (flags, scene)) in [
        (vec![], "standard.toml"),
        (
            vec!["--no-compensation", "--index-bits", "4"],
            "four_lights.toml",
        ),
        (vec!["--map-bits", "10"], "engine.toml"),
    ]
    .into_iter()
    .enumerate()
    {
        let d = t.path().join(format!("d{k}"));
        let s = helpers::root().join("scenes").join(scene);
        let mut a = vec!["generate", "--vectors", "0", "--scene", s.to_str().unwrap()];
        a.extend(&flags);
        a.extend(["--out", d.to_str().unwrap()]);
        let o = helpers::run(&a);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        let cfg = rmapgen::design_dir::DesignDir::open(&d).unwrap().config;
        let text = std::fs::read_to_string(d.join("README.md")).unwrap();
        assert!(text.contains(&format!("scene `{scene}`")), "{scene}");
        // Exact: the README's formula with plain dot products gives the model's entries.
        let (differ, far) = from_readme(&d, &cfg);
        assert_eq!((differ, far), (0, 0), "{scene} {flags:?}: entries differ");
    }
}

/// A probe of the generated top (default configuration, in `dir`): the edges around one
/// sample, and where writes during reset, with a swap and to axis 3 land in bank 00.
const PROBE_TB: &str = r#"`timescale 1ns/1ps
module probe_tb;
  reg clk = 0, rst_n = 0, valid = 0, swap = 0, wr_en = 0;
  reg [11:0] gx = 0, gy = 0, gz = 0;
  reg [1:0] wr_axis = 0; reg [8:0] wr_addr = 0; reg [7:0] wr_data = 0;
  wire valid_o, zero_o; wire [7:0] i_o;
  rmap_top dut(.clk_i(clk), .rst_ni(rst_n), .valid_i(valid), .gx_i(gx), .gy_i(gy), .gz_i(gz),
    .swap_i(swap), .wr_en_i(wr_en), .wr_axis_i(wr_axis), .wr_addr_i(wr_addr),
    .wr_data_i(wr_data), {HANDSHAKE}.valid_o(valid_o), .zero_o(zero_o), .i_o(i_o));
  always #5 clk = ~clk;
  integer n = 0; integer acc = -1; reg cap_q = 0;
  always @(posedge clk) begin
    n <= n + 1;
    cap_q <= valid_o;
    if (valid) acc = n;
  end
  always @(posedge clk) begin #1;
    if (valid_o) $display("high %0d", n - 1 - acc);
    if (cap_q) $display("captured %0d", n - 1 - acc);
  end
  initial begin
    @(negedge clk); wr_en = 1; wr_axis = 0; wr_addr = 0; wr_data = 8'hA1; swap = 0;
    @(negedge clk); wr_addr = 9'd2; wr_data = 8'hA2; swap = 1;
    @(negedge clk); wr_en = 0; swap = 0;
    @(negedge clk); rst_n = 1;
    $display("front %0d", dut.front_q);
    $display("reset write %h %h", dut.u_map_lookup.u_bank_00.mem[512], dut.u_map_lookup.u_bank_00.mem[1]);
    @(negedge clk); swap = 1; wr_en = 1; wr_axis = 1; wr_addr = 0; wr_data = 8'hC1;
    @(negedge clk); swap = 0; wr_en = 0;
    $display("swap write %0d %h", dut.front_q, dut.u_map_lookup.u_bank_00.mem[128]);
    @(negedge clk); wr_en = 1; wr_axis = 3; wr_addr = 0; wr_data = 8'hD1;
    @(negedge clk); wr_en = 0;
    $display("axis3 write %h", dut.u_map_lookup.u_bank_00.mem[384]);
    @(negedge clk); rst_n = 0;
    @(negedge clk); rst_n = 1;
    $display("front after reset %0d", dut.front_q);
    repeat (3) @(negedge clk);
    valid = 1; gx = 100; gy = 20; gz = 30;
    @(negedge clk); valid = 0;
    repeat (40) @(negedge clk);
    $finish;
  end
endmodule
"#;

#[test]
fn the_readme_states_what_the_rtl_does_at_its_edges_reset_and_write_port() {
    probe(false);
    probe(true);
}

/// The probe on the default design, or with `--handshake` (`ready_i` tied high).
fn probe(handshake: bool) {
    let t = helpers::tempdir();
    let d = t.path().join("d");
    let mut a = vec!["generate", "--vectors", "0", "--out", d.to_str().unwrap()];
    if handshake {
        a.push("--handshake");
    }
    let o = helpers::run(&a);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let ports = if handshake {
        ".ready_i(1'b1), .ready_o(), "
    } else {
        ""
    };
    std::fs::write(d.join("probe_tb.v"), PROBE_TB.replace("{HANDSHAKE}", ports)).unwrap();
    let mut src: Vec<String> = std::fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".v"))
        .collect();
    src.sort();
    let c = Command::new("iverilog")
        .current_dir(&d)
        .args(["-g2005", "-s", "probe_tb", "-o", "probe.vvp"])
        .args(&src)
        .output()
        .expect("iverilog runs");
    assert!(c.status.success(), "{}", String::from_utf8_lossy(&c.stderr));
    let r = Command::new("vvp")
        .current_dir(&d)
        .args(["-N", "probe.vvp"])
        .output()
        .expect("vvp runs");
    let out = String::from_utf8_lossy(&r.stdout).into_owned();
    let line = |p: &str| {
        out.lines()
            .find_map(|l| l.strip_prefix(p))
            .unwrap_or_else(|| panic!("no {p:?} in {out}"))
            .trim()
            .to_string()
    };
    let text = std::fs::read_to_string(d.join("README.md")).unwrap();
    // valid_o goes high (exactly once) just after edge t + high and a register captures it
    // at t + captured; the README gives both.
    let (high, captured) = (line("high "), line("captured "));
    assert_eq!(out.matches("high ").count(), 1, "{out}");
    assert!(
        text.contains(&format!("just after edge *t* + {high}:"))
            && text.contains(&format!("captures them at edge *t* + {captured}.")),
        "edges {high}, {captured} (handshake {handshake})"
    );
    let lat = rmapgen::stages::rmap_top::top_latency(&Config::default());
    assert_eq!(captured, lat.to_string());
    // Writes in reset land in buffer 1, or buffer 0 with swap_i high (bank 00 address
    // {buf, axis, s_max, s_u, i_u >> 1, s_v, i_v >> 1}: 512 is buffer 1, entry 0; 1 is
    // buffer 0, address 2); reset leaves buffer 0 the front.
    assert_eq!(line("front "), "0");
    assert_eq!(line("reset write "), "a1 a2");
    assert!(text.contains("into buffer 1, or into buffer 0 if `swap_i` is high in that\nclock"));
    // A write with swap_i goes to the new back buffer: buffer 0 when buffer 1 becomes the front.
    assert_eq!(line("swap write "), "1 c1");
    assert!(text.contains("A write in the same clock as `swap_i` goes to the new back buffer"));
    // Axis 3 lands in the fourth axis slot (128 * 3), which no sample address reaches.
    assert_eq!(line("axis3 write "), "d1");
    assert!(text.contains("`wr_axis_i` = 3 writes an unused fourth axis slot"));
    assert_eq!(line("front after reset "), "0");
    assert!(text.contains("Reset makes buffer 0 the\nfront buffer again"));
}

/// The README's gradient and colour rules, checked against the model: the colour formula it
/// prints gives the colour multiply's every output (every channel value, every intensity, two
/// map widths), the most negative gradient shades as its half, as it says, and no port's
/// description says the same thing twice.
#[test]
fn the_readme_states_the_gradient_and_colour_rules_the_model_follows() {
    use rmapgen::model::Model;
    use rmapgen::stages::color_mul::model as color_mul;
    for map_bits in [8, 6] {
        let cfg = Config {
            color: true,
            map_bits,
            ..Config::default()
        };
        let text = readme(&Design::for_scene(&cfg, &Scene::standard()).unwrap()).unwrap();
        let d = cfg.map_max();
        assert!(
            text.contains(&format!("with D = {d} and i the"))
                && text.contains("`r_o = floor((2 * r_i * i + D) / (2 * D))`"),
            "the colour formula"
        );
        for c in 0..256u32 {
            for i in 0..=d {
                let said = (2 * c * i + d) / (2 * d);
                assert_eq!(
                    color_mul::eval(&cfg, [c, 0, c], i),
                    [said, 0, said],
                    "c {c} i {i}"
                );
            }
        }
        for l in text.lines().filter(|l| l.starts_with("| `")) {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            if let Some(desc) = cells.get(4) {
                if let Some((a, b)) = desc.split_once(": ") {
                    assert!(!a.contains(b), "said twice: {l}");
                }
            }
        }
    }
    let cfg = Config::default();
    let text = readme(&Design::for_scene(&cfg, &Scene::standard()).unwrap()).unwrap();
    let min = -(1i32 << (cfg.grad_bits - 1));
    assert!(text.contains(&format!(
        "Every 12-bit\nvalue is a legal input, {min} included"
    )));
    assert!(text.contains("density volume's gradient points into the material, so negate it"));
    let model = Model::new(&cfg);
    let maps = Scene::standard().maps(&cfg);
    for g in [
        [min, 5, 7],
        [min, min, 1],
        [3, min, -9],
        [min, min, min],
        [-77, 1000, min],
    ] {
        let half = g.map(|c| c.signum() * (c.abs() >> 1));
        assert_eq!(
            model.intensity(&maps, g),
            model.intensity(&maps, half),
            "{g:?} shades as {half:?}"
        );
    }
}
