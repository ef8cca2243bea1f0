//! `rmapgen bench`: the quick run writes its table, CSV and plots, and the Pareto marking
//! follows its definition.

use super::helpers;
use rmapgen::bench::row::Row;
use rmapgen::bench::{pareto, table};
use rmapgen::flow::fpga::Family;

fn row(scene: &str, bits: u64, speed: f64, rmse: f64) -> Row {
    Row {
        scene: scene.into(),
        design: format!("{bits}/{speed}"),
        config: String::new(),
        map_fit: "sample".into(),
        entries: 0,
        max_abs_error: 0,
        rmse,
        psnr_db: 0.0,
        msamples_1_thread: speed,
        msamples_all_cores: speed,
        float_ratio: 1.0,
        map_build_us: 0.0,
        rom_bits: 0,
        map_bits: bits,
        ice40_cells: None,
        ice40_brams: None,
        ice40_too_big: false,
        family: Family::Ice40,
        lanes: 1,
        dsps: None,
        fmax_mhz: None,
        pareto_cost: false,
        pareto_speed: false,
    }
}

#[test]
fn pareto_fronts_per_scene() {
    let mut rows = vec![
        row("a", 100, 10.0, 2.0),
        row("a", 200, 20.0, 1.0),
        row("a", 300, 5.0, 1.5), // dominated in cost by the second, in speed too
        row("a", 100, 10.0, 2.5), // dominated by the first
        row("b", 900, 1.0, 9.0), // alone in its scene: on both fronts
    ];
    pareto::mark_pareto(&mut rows);
    let fronts: Vec<(bool, bool)> = rows
        .iter()
        .map(|r| (r.pareto_cost, r.pareto_speed))
        .collect();
    assert_eq!(
        fronts,
        [
            (true, false),
            (true, true),
            (false, false),
            (false, false),
            (true, true)
        ]
    );
    let md = table::markdown(&rows);
    assert_eq!(md.lines().count(), 2 + rows.len());
    assert!(md.lines().nth(2).unwrap().ends_with("| cost |"), "{md}");
    let csv = table::csv(&rows);
    assert_eq!(csv.lines().count(), 1 + rows.len());
    assert!(csv.lines().all(|l| l.split(',').count() == 20), "{csv}");
}

#[test]
fn a_design_too_big_for_the_device_is_a_figure() {
    let mut placed = row("s", 100, 1.0, 1.0);
    placed.ice40_cells = Some(1714);
    placed.ice40_brams = Some(11);
    placed.fmax_mhz = Some(154.44);
    let mut big = row("s", 200, 1.0, 0.5);
    big.ice40_too_big = true;
    let md = table::markdown(&[placed.clone(), big.clone()]);
    let lines: Vec<&str> = md.lines().collect();
    assert!(lines[2].contains("| 1714 | 11 | 154.4 |"), "{md}");
    assert!(lines[3].contains("| does not fit | - | - |"), "{md}");
    let csv = table::csv(&[placed, big]);
    let last: Vec<&str> = csv.lines().last().unwrap().split(',').collect();
    assert_eq!(
        last[last.len() - 6..last.len() - 2],
        ["", "", "", "true"],
        "{csv}"
    );
}

#[test]
fn another_family_or_lanes_name_the_family_and_add_dsps_and_samples_per_second() {
    let mut r = row("s", 100, 1.0, 1.0);
    r.family = Family::Ecp5;
    r.lanes = 4;
    r.ice40_cells = Some(5000);
    r.ice40_brams = Some(28);
    r.dsps = Some(32);
    r.fmax_mhz = Some(125.0);
    let md = table::markdown(std::slice::from_ref(&r));
    let lines: Vec<&str> = md.lines().collect();
    assert!(
        lines[0].contains(
            "| ECP5 cells | block RAMs | Fmax (MHz) | DSP | samples/s (4 lanes) | Pareto |"
        ),
        "{md}"
    );
    assert_eq!(lines[0].matches('|').count(), lines[1].matches('|').count());
    assert!(
        lines[2].contains("| 5000 | 28 | 125.0 | 32 | 5.000e8 |"),
        "{md}"
    );
    let csv = table::csv(std::slice::from_ref(&r));
    let head = csv.lines().next().unwrap();
    assert!(
        head.contains(",ecp5_cells,ecp5_brams,fmax_mhz,ecp5_too_big,"),
        "{csv}"
    );
    assert!(head.ends_with(",lanes,dsps,samples_per_s"), "{csv}");
    assert!(
        csv.lines().nth(1).unwrap().ends_with(",4,32,500000000"),
        "{csv}"
    );
    // The default (iCE40, one lane) has the columns it had before the flags.
    let d = table::csv(&[row("s", 100, 1.0, 1.0)]);
    assert!(
        d.lines()
            .next()
            .unwrap()
            .ends_with(",ice40_cells,ice40_brams,fmax_mhz,ice40_too_big,pareto_cost,pareto_speed"),
        "{d}"
    );
    let json = serde_json::to_value(row("s", 100, 1.0, 1.0)).unwrap();
    assert!(
        json.get("family").is_none() && json.get("lanes").is_none(),
        "{json}"
    );
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(
        (json["family"].as_str(), json["lanes"].as_u64()),
        (Some("ecp5"), Some(4))
    );
}

/// The FPGA flags of bench and of its throughput sweep: bad input is one line, exit 2, and
/// nothing written (no synthesis runs: every case fails before it).
#[test]
fn bad_fpga_flags_are_one_line_and_write_nothing() {
    let tmp = helpers::tempdir();
    let out = tmp.path().join("b");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &str)] = &[
        // Lists are the sweep's; the bench places one family with one lane count.
        (
            &["--lanes", "1,2"],
            "--lanes takes one lane count without --throughput",
        ),
        (
            &["--family", "ice40,ecp5"],
            "--family takes one family without --throughput",
        ),
        (&["--lanes", "9"], "--lanes must be in 1..=8, not 9"),
        (
            &["--family", "virtex"],
            "invalid value 'virtex' for '--family",
        ),
        // --mult is the sweep's only.
        (&["--mult", "infer"], "--throughput"),
        (
            &["--throughput", "--mult", "tree,fast"],
            "invalid value 'fast' for '--mult",
        ),
        // A value named twice would be a row measured twice into one log directory.
        (
            &["--throughput", "--mult", "tree,tree"],
            "--mult names tree twice",
        ),
        (
            &["--throughput", "--lanes", "2,1,2"],
            "--lanes names 2 twice",
        ),
        (
            &["--throughput", "--family", "ecp5,ecp5"],
            "--family names ecp5 twice",
        ),
        // --quick's one design holds the atan table in a ROM.
        (
            &["--map-fit", "table"],
            "--quick measures the paper's design, whose compensation table is a ROM",
        ),
    ];
    for (args, needle) in cases {
        let mut a = vec!["bench", "--quick", "--out", o];
        a.extend_from_slice(args);
        helpers::assert_error(&helpers::run(&a), needle);
        assert!(!out.exists(), "{args:?} wrote {o}");
    }
}

#[test]
fn quick_run_writes_table_csv_and_plots() {
    let dir = helpers::tempdir();
    let out = dir.path().join("bench");
    let run = helpers::run(&[
        "bench",
        "--quick",
        "--no-yosys",
        "--size",
        "48",
        "--seconds",
        "0.01",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    for f in [
        "bench.md",
        "bench.csv",
        "bench.json",
        "error_vs_cost.png",
        "error_vs_cost.svg",
        "error_vs_speed.png",
        "error_vs_speed.svg",
    ] {
        assert!(
            out.join(f)
                .metadata()
                .map(|m| m.len() > 100)
                .unwrap_or(false),
            "{f}"
        );
    }
    let md = std::fs::read_to_string(out.join("bench.md")).unwrap();
    // The paper's configuration with both fits and the octahedral map, on three scenes.
    assert_eq!(md.lines().count(), 2 + 3 * 3, "{md}");
    assert!(
        md.contains("| standard | paper I3 P3 | lsq |") && md.contains("octahedral 39x39"),
        "{md}"
    );
    let png = image::open(out.join("error_vs_cost.png")).unwrap();
    assert_eq!((png.width(), png.height()), (900, 600));
    let bad = helpers::run(&["bench", "--size", "3", "--out", out.to_str().unwrap()]);
    helpers::assert_error(&bad, "size 3 is out of range");
}

/// The loaded compensation table's configuration is measured with the fit that loads it and
/// nothing else, and no other configuration with that fit; its table counts as per-frame
/// memory (the maps' column), not ROM.
#[test]
fn the_loaded_table_has_rows_of_its_own_fit_only() {
    use rmapgen::bench::{configurations, measured, Options};
    use rmapgen::model::map_fit::MapFit;
    let all = configurations(false);
    let tables: Vec<_> = all.iter().filter(|(_, c)| !c.comp_table.is_rom()).collect();
    assert_eq!(tables.len(), 1);
    for (name, c) in &all {
        for f in [MapFit::Sample, MapFit::Lsq, MapFit::Minimax, MapFit::Table] {
            assert_eq!(
                measured(f, c),
                (f == MapFit::Table) != c.comp_table.is_rom(),
                "{name} {}",
                f.name()
            );
        }
    }
    // Steps: one per configuration, one per (scene, fit) row, two per scene.
    let o = Options::default();
    let rows: usize = all
        .iter()
        .map(|(_, c)| o.fits.iter().filter(|&&f| measured(f, c)).count())
        .sum();
    assert_eq!(rows, 2 * (all.len() - 1) + 1);
    assert_eq!(
        o.steps(),
        all.len() + rows * o.scenes.len() + 2 * o.scenes.len()
    );
}
