//! The README's hardware table, rendered from the throughput sweeps that measured it: no
//! figure of it is typed. `make readme-hardware` runs the sweeps ([`super::throughput`]) into
//! [`DIR`]`/<name>/` (each its `throughput.json`, `.md` and `.csv`) and writes the table
//! between [`BEGIN`] and [`END`] in README.md; the tests fail when the README's table is not
//! the rendering of the committed sweeps.

use super::throughput::{Layout, Row};
use anyhow::{Context, Result};
use std::path::Path;

/// Where the sweeps behind the table are committed, one directory each.
pub const DIR: &str = "docs/bench/hardware";
/// The README's lines around the table.
pub const BEGIN: &str =
    "<!-- hardware: rendered by make readme-hardware from docs/bench/hardware -->";
pub const END: &str = "<!-- end hardware -->";

/// Every row of every sweep under `dir` (each `<name>/throughput.json`).
pub fn load(dir: &Path) -> Result<Vec<Row>> {
    let mut rows = Vec::new();
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read {}", dir.display()))?
        .map(|e| e.map(|e| e.path()))
        .collect::<std::io::Result<_>>()?;
    names.sort();
    for d in names.iter().filter(|d| d.is_dir()) {
        let f = d.join("throughput.json");
        let text =
            std::fs::read_to_string(&f).with_context(|| format!("cannot read {}", f.display()))?;
        let mut v: Vec<Row> =
            serde_json::from_str(&text).with_context(|| format!("{}", f.display()))?;
        rows.append(&mut v);
    }
    Ok(rows)
}

/// `n` with a thin space between groups of three digits, as the README writes numbers.
fn grouped(n: u32) -> String {
    let s = n.to_string();
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if i > 0 && (s.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    out
}

/// `v` as `m.mmm × 10^e`.
fn scientific(v: f64) -> String {
    let s = format!("{v:.3e}");
    let (m, e) = s.split_once('e').expect("an exponent");
    format!("{m} × 10^{e}")
}

/// The part, the design and how they were measured, as the first column says them.
fn label(r: &Row) -> String {
    let mut s = format!(
        "{} {} {}, {} lane{}",
        r.family.title(),
        r.device,
        r.package,
        r.lanes,
        if r.lanes == 1 { "" } else { "s" }
    );
    if r.layout == Layout::Replicated {
        s += ", every ROM read replicated";
    }
    if r.out_of_context {
        s += ", out of context";
    }
    s
}

/// The table: one row per placed configuration, the lanes then the families in their order;
/// the highest samples/s in bold.
pub fn table(rows: &[Row]) -> String {
    let best = super::throughput::best(rows).map(|b| (b.family, b.lanes, b.mult, b.layout));
    let mut rows: Vec<&Row> = rows.iter().collect();
    let order = |r: &Row| {
        let f = crate::family::Family::ALL
            .iter()
            .position(|&f| f == r.family)
            .unwrap_or(usize::MAX);
        (r.lanes, f, r.mult.name())
    };
    rows.sort_by_key(|r| order(r));
    let mut s = String::from(
        "| part, design (the default configuration) | Fmax: median (seeds) | samples/s | logic cells | block RAMs |\n\
         |---|---|---:|---:|---:|\n",
    );
    for r in rows {
        let f = r.family.get();
        match (&r.report, r.fmax_mhz, r.samples_per_s) {
            (Some(p), Some(m), Some(sps)) => {
                let seeds: Vec<String> = r
                    .seeds
                    .iter()
                    .map(|x| format!("{:.1}", x.fmax_mhz))
                    .collect();
                let mut rate = scientific(sps);
                if best == Some((r.family, r.lanes, r.mult, r.layout)) {
                    rate = format!("**{rate}**");
                }
                s += &format!(
                    "| {} | {m:.1} MHz ({}) | {rate} | {} of {} {} | {} of {} {} |\n",
                    label(r),
                    seeds.join(", "),
                    grouped(p.logic_cells),
                    grouped(p.logic_cells_available),
                    f.names.logic,
                    p.block_rams,
                    p.block_rams_available,
                    f.block_ram.cell,
                );
            }
            _ => s += &format!("| {} | does not fit | | | |\n", label(r)),
        }
    }
    s
}

/// `readme` with its table (between [`BEGIN`] and [`END`]) replaced by `table`; an error if
/// the README has no such place.
pub fn with_table(readme: &str, table: &str) -> Result<String> {
    let b = readme
        .find(BEGIN)
        .with_context(|| format!("README.md has no line {BEGIN}"))?;
    let e = readme[b..]
        .find(END)
        .map(|e| b + e)
        .with_context(|| format!("README.md has no line {END} after {BEGIN}"))?;
    Ok(format!("{}{BEGIN}\n{table}{}", &readme[..b], &readme[e..]))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_written_as_the_readme_writes_them() {
        assert_eq!(grouped(7), "7");
        assert_eq!(grouped(1710), "1 710");
        assert_eq!(grouped(83_640), "83 640");
        assert_eq!(grouped(1_234_567), "1 234 567");
        assert_eq!(scientific(1.0134e9), "1.013 × 10^9");
    }

    #[test]
    fn the_table_replaces_only_what_lies_between_its_lines() {
        let r = format!("a\n{BEGIN}\nold\n{END}\nb\n");
        assert_eq!(
            with_table(&r, "new\n").unwrap(),
            format!("a\n{BEGIN}\nnew\n{END}\nb\n")
        );
        assert!(with_table("a\n", "new\n").is_err());
        assert!(with_table(&format!("{BEGIN}\n"), "new\n").is_err());
    }
}
