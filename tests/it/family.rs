//! The FPGA family descriptors (src/family/) against the tools they describe: every part a
//! descriptor lists has, by nextpnr's own report, the logic cells, block RAMs and DSP blocks
//! it says; and the block RAMs the generated README's "Fits on" table gives for a design
//! (`emit::manifest::block_rams_of`, from the descriptor's block shapes and read ports) are
//! the ones Yosys maps, memory by memory; and the Gowin parts' pin lists (src/family/
//! gowin_pins.rs) are Apycula's. Skipped where a family's tools are missing (and failing under
//! CI=true, as the ECP5 flow's tests do).

use crate::helpers;
use rmapgen::config::{Config, Target};
use rmapgen::family::Family;
use rmapgen::toolchain;
use rmapgen::{emit, flow::fpga};

/// Whether `family`'s Yosys and nextpnr are installed (fails under CI=true, where `make
/// test` installs both families' tools first).
fn tools(family: Family) -> bool {
    let d = family.get();
    let found = toolchain::installed(&toolchain::tool(&d.yosys))
        && toolchain::installed(&toolchain::tool(&d.nextpnr));
    if !found {
        assert!(
            std::env::var("CI").map_or(true, |v| v != "true"),
            "the {} tools are not installed and CI=true",
            d.title
        );
        eprintln!("skipping: the {} tools are not installed", d.title);
    }
    found
}

/// The default design written for `family` (its memories are the ones "Fits on" counts)
/// synthesised once, then packed into every part the descriptor lists.
fn check(family: Family) {
    if !tools(family) {
        return;
    }
    let d = family.get();
    let cfg = Config::default().for_target(Target::Family(family));
    let tmp = helpers::tempdir();
    let dir = tmp.path().join("design");
    let out = rmapgen::output::StagedDir::new(&dir, &Default::default()).unwrap();
    emit::write_design(
        &rmapgen::design::Design::standard(&cfg).unwrap(),
        &out,
        None,
    )
    .unwrap();
    let dir = out.commit().unwrap();
    let mut opts = fpga::Options {
        logs: Some(tmp.path().join("logs")),
        ..fpga::Options::for_family(family)
    };
    let syn = fpga::synthesise(&dir, &opts).expect("the default design synthesises");
    let memories = emit::manifest::memories(&cfg);
    assert_eq!(syn.memories().len(), memories.len());
    for m in &memories {
        let placed = syn
            .memories()
            .iter()
            .find(|p| p.instance == m.instance)
            .unwrap_or_else(|| panic!("{} not in the synthesis", m.instance));
        assert_eq!(
            placed.block_rams,
            emit::manifest::block_rams_of(m, family),
            "{}: {} ({} x {}, {} reads) in {}",
            d.title,
            m.instance,
            m.entries,
            m.width,
            m.reads,
            d.block_ram.cell
        );
    }
    assert_eq!(
        syn.stat().block_rams,
        emit::manifest::block_rams(&Config::default(), family)
    );
    // Every part's figures against nextpnr's: equal, or at least the datasheet's where the
    // part shares a larger part's die and nextpnr offers all of it (`Part::die`).
    let mut wrong = Vec::new();
    for p in d.parts {
        opts.device = p.device.to_string();
        opts.package = p.package.to_string();
        let u = fpga::pack(&syn, &opts).unwrap_or_else(|e| panic!("{}: {e:#}", p.title));
        for (key, says) in [
            (d.names.logic, p.logic_cells),
            (d.names.block_ram, p.block_rams),
            (d.names.dsp, p.dsps),
        ] {
            let has = u.of(key).1;
            let ok = match p.die {
                None => has == u64::from(says),
                Some(_) => has >= u64::from(says),
            };
            if !ok {
                wrong.push(format!(
                    "{} {key}: the descriptor says {says}, nextpnr {has}",
                    p.title
                ));
            }
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
}

#[test]
fn the_ice40_descriptor_is_what_yosys_and_nextpnr_say() {
    check(Family::Ice40);
}

#[test]
fn the_ecp5_descriptor_is_what_yosys_and_nextpnr_say() {
    check(Family::Ecp5);
}

#[test]
fn the_gowin_descriptor_is_what_yosys_and_nextpnr_say() {
    check(Family::Gowin);
}

/// The pin lists rmapgen writes Gowin pin files from are the ones of the Apycula that the venv's
/// nextpnr-himbaechel-gowin installs (scripts/gowin-pins.py --check, with the venv's Python:
/// the one beside that nextpnr).
#[test]
fn the_gowin_pins_are_apyculas() {
    if !tools(Family::Gowin) {
        return;
    }
    let nextpnr = toolchain::tool(&Family::Gowin.get().nextpnr);
    let python = toolchain::locate(&nextpnr)
        .and_then(|p| p.canonicalize().ok())
        .map(|p| p.with_file_name("python"))
        .expect("the Gowin nextpnr is installed");
    let out = std::process::Command::new(&python)
        .arg(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/scripts/gowin-pins.py"
        ))
        .arg("--check")
        .output()
        .unwrap_or_else(|e| panic!("{}: {e}", python.display()));
    assert!(
        out.status.success(),
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}
