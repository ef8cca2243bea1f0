//! The parameter grid: the configurations the generated hardware is checked in, each row with
//! what it covers. One list, read by the parameter-grid tests (`tests/it/grid.rs`: lint,
//! synthesis, exact agreement with the model), by the generator's checks
//! (`tests/it/rtl_generate.rs`: manifest, lint, Icarus) and by `rmapgen sim --matrix` (`make
//! sim-matrix`: every testbench in both simulators and the C++ harness).
//!
//! The rows are chosen for coverage, and `tests/it/grid.rs` holds them to it: each width at
//! both ends of its range (recip_bits at its smallest legal value, frac_bits + 1), each of the
//! eight combinations of compensation, interpolation and colour, every pipeline depth, and the
//! handshake on and off, both memory targets, mixed so that the ends meet each other and the
//! optional stages, the AXI4-Stream top (with and without tuser), 2 and 4 lanes with and without the handshake, both
//! multiplier styles (`--mult infer` at every depth, with and without the handshake), and the
//! compensation table as a loaded RAM (`--comp-table ram`: with and without the handshake and
//! lanes, for each memory target).

use crate::config::{Bus, CompTable, Config, Mult, Target, RANGES};
use crate::family::Family;

/// One configuration of the grid.
#[derive(Clone, Debug, PartialEq)]
pub struct GridRow {
    /// A short name: a test, a directory (`build/matrix/<name>`).
    pub name: &'static str,
    pub config: Config,
    /// Also run every stage testbench and the top's under Icarus in the grid test (Verilator
    /// runs the top's in every row): a subset that still has every optional stage and both
    /// interfaces.
    pub icarus: bool,
    /// Why the row is there: what it covers.
    pub covers: &'static str,
}

macro_rules! grid {
    ($( $name:ident: $g:literal $r:literal $w:literal $f:literal $i:literal $p:literal $m:literal
        $comp:literal $interp:literal $color:literal $depth:literal $hs:literal $icarus:literal
        $ice40:literal
        $(axis $user:literal)? $(lanes $lanes:literal)? $(mult $mult:ident)? $(table $table:ident)?
        $(bus $bus:ident)? $covers:literal; )*) => {
        /// Every row, in the order below.
        pub fn rows() -> Vec<GridRow> {
            vec![$(GridRow {
                name: stringify!($name),
                config: Config {
                    grad_bits: $g, red_bits: $r, recip_bits: $w, frac_bits: $f,
                    index_bits: $i, interp_bits: $p, map_bits: $m,
                    compensation: $comp == 1, interpolation: $interp == 1, color: $color == 1,
                    pipeline_depth: $depth, handshake: $hs == 1,
                    prefix: String::new(),
                    target: match $ice40 { 1 => Target::Family(Family::Ice40), 2 => Target::Family(Family::Ecp5), 3 => Target::Family(Family::Gowin), _ => Target::Generic },
                    axis: false $(|| { let _: u32 = $user; true })?,
                    axis_user: 0 $(+ $user)?,
                    lanes: 1 $(- 1 + $lanes)?,
                    mult: *[Mult::Tree $(, Mult::$mult)?].last().expect("a style"),
                    comp_table: *[CompTable::Rom $(, CompTable::$table)?].last().expect("a table"),
                    bus: *[Bus::None $(, Bus::$bus)?].last().expect("a bus"),
                },
                icarus: $icarus == 1,
                covers: $covers,
            }),*]
        }
    };
}

// G grad, R reduced, W reciprocal entry, F fraction, I index, P interpolation fraction, M map
// entry bits; comp(ensation), interp(olation), color, pipeline depth, handshake, run in Icarus,
// --target ice40 (1), ecp5 (2), gowin (3) or generic (0); `axis U`: the AXI4-Stream top rmap_axis with a U-bit tuser;
// `lanes L`: the lanes top rmap_lanes with L lanes (its testbench runs in place of rmap_top's);
// `mult Infer`: inferred multipliers (`--mult infer`), else adder trees; `table Ram`: the
// compensation table as a RAM the host loads (`--comp-table ram`), else the atan ROM; `bus
// Wishbone` or `bus Axi4Lite`: the bus top rmap_bus (`--bus`), its sample top's testbenches run.
grid! {
//                  G  R  W  F  I  P  M  comp interp color depth hs icarus target
    paper:          12 8  10 8  3  3  8  1    1      0     2     0  1  0
        "the paper's widths at the default depth: the committed rtl_out/ design";
    paper_depth0:   12 8  10 8  3  3  8  1    1      0     0     0  1  0
        "the paper's design with the fewest registers (latency 12)";
    paper_depth1:   12 8  10 8  3  3  8  1    1      0     1     0  0  1
        "the paper's design at the middle depth";
    paper_hs:       12 8  10 8  3  3  8  1    1      0     2     1  1  0
        "the paper's design with the valid/ready handshake (golden/handshake)";
    color:          12 8  10 8  3  3  8  1    1      1     2     0  0  0
        "the colour multiplier on the paper's design (golden/color)";
    no_comp:        12 8  10 8  3  3  8  0    1      0     2     0  0  0
        "the linear index in place of the atan ROM";
    no_interp:      12 8  10 8  3  0  8  1    0      0     1     0  0  1
        "nearest entry: one map bank, no interpolator";
    bare:           12 8  10 8  3  0  8  0    0      0     0     0  1  0
        "neither optional stage, compact registers";
    no_comp_color:  12 8  10 8  3  3  8  0    1      1     1     1  0  1
        "linear index with colour, under backpressure";
    no_interp_color:12 8  10 8  3  0  8  1    0      1     0     1  1  0
        "nearest entry with colour, under backpressure, compact registers";
    bare_color:     12 8  10 8  3  0  8  0    0      1     2     0  0  0
        "colour alone: neither optional stage";
    narrowest:       8 6   5 4  2  1  6  1    1      0     0     0  1  0
        "every width at the low end of its range (interpolation on: 1 bit)";
    narrowest_bare:  8 6   5 4  2  0  6  0    0      1     2     1  0  0
        "the narrowest widths with neither optional stage, colour and the handshake";
    widest:         16 12 20 12 6  5  12 1    1      1     2     1  0  1
        "every width at the high end of its range, every stage, the handshake";
    widest_depth0:  16 12 13 12 6  5  12 0    1      0     0     0  0  0
        "the widest widths with the smallest legal reciprocal (F + 1), compact registers";
    grad16_red6:    16 6   9 8  3  3  8  1    1      0     1     0  1  0
        "the widest gradient truncated to the narrowest magnitude after the shift";
    grad8_red8:      8 8  10 8  3  3  8  1    1      0     2     0  0  0
        "reduced width equal to the gradient width: nothing truncated after the shift";
    no_truncation:   8 8  20 7  3  3  8  1    1      0     2     0  0  0
        "nothing truncated, with the widest reciprocal over a 7-bit fraction (normalise's longest shift)";
    frac4_recip20:  12 8  20 4  3  2  8  1    1      0     0     1  0  0
        "the narrowest fraction with the widest reciprocal, under backpressure";
    frac12_recip13: 12 12 13 12 4  4  10 1    1      0     1     0  0  0
        "the widest fraction with its smallest legal reciprocal (F + 1)";
    index6_interp1: 12 8  10 8  6  1  8  1    1      0     2     0  0  0
        "the largest map with the coarsest interpolation";
    index2_interp5: 12 8  10 8  2  5  8  1    1      1     1     0  1  1
        "the smallest map with the finest interpolation, with colour";
    map12:          12 8  10 8  3  3  12 1    1      0     2     0  0  0
        "the widest map entries and output";
    map6_nearest:   12 8  10 8  4  0  6  1    0      0     2     0  0  0
        "the narrowest map entries, nearest entry";
    index6_nearest: 14 10 12 10 6  0  10 0    0      0     1     1  0  0
        "the largest map without interpolation (the widest bank address), under backpressure";
    axis_color:     12 8  10 8  3  3  8  1    1      1     2     1  1  0  axis 3
        "the AXI4-Stream top (rmap_axis: byte-padded tdata, 3-bit tuser, tlast) around the handshake top with colour";
    axis_table_narrow: 8 6 5 4  2  1  6  1    1      0     0     1  0  0  axis 0 table Ram
        "the AXI4-Stream top without tuser (--axis-user 0) at the narrowest widths, with the compensation table loaded through the host port, compact registers";
    lanes2:         12 8  10 8  3  3  8  1    1      0     2     0  0  0  lanes 2
        "two lanes of the paper's design, per-lane valid bits";
    lanes2_hs:      12 8  10 8  3  3  8  1    1      1     2     1  0  1  lanes 2
        "two lanes with colour under whole-beat backpressure, memories for the iCE40";
    lanes4:         12 8  10 8  3  0  8  0    0      0     0     0  0  0  lanes 4
        "four lanes of the smallest design (neither optional stage, compact registers)";
    lanes4_hs:      12 8  10 8  3  0  8  1    0      0     1     1  0  0  lanes 4
        "four lanes under whole-beat backpressure, nearest entry";
    lanes2_hs_ecp5: 12 8  10 8  3  3  8  1    1      0     2     1  1  2  lanes 2
        "two lanes sharing a true dual-port reciprocal ROM (--target ecp5) under whole-beat backpressure, every testbench in Icarus";
    lanes4_gowin:   12 8  10 8  3  3  8  1    1      1     0     0  0  3  lanes 4
        "four lanes, two ROMs each shared by a pair (--target gowin: dual-port BSRAM), with colour, compact registers";
    paper_infer:    12 8  10 8  3  3  8  1    1      0     2     0  1  0  mult Infer
        "the paper's design with inferred multipliers (--mult infer): plain products for DSP blocks";
    color_infer:    12 8  10 8  3  3  8  0    1      1     0     0  1  0  mult Infer
        "inferred multipliers in every multiplying stage (linear index, interpolation, colour), compact registers";
    hs_infer:       12 8  10 8  3  3  8  1    1      1     1     1  0  0  mult Infer
        "inferred multipliers with colour under backpressure, at the middle depth";
    widest_infer:   16 12 20 12 6  5  12 1    1      1     2     1  0  1  mult Infer
        "inferred multipliers at the widest widths (products wider than one 18 x 18 DSP), every stage, the handshake";
    table_ram:      12 8  10 8  3  3  8  1    1      0     2     0  1  0  table Ram
        "the compensation table as a RAM the host loads with the maps (--comp-table ram), double-buffered, every testbench in Icarus";
    table_ram_narrow: 8 6  5 4  2  1  6  1    1      0     0     0  1  2  table Ram
        "the loaded table at the narrowest widths (a 16-entry table through a 7-bit write address), compact registers, memories for the ECP5";
    table_ram_lanes2_hs: 12 8 10 8 3  3  8  1    1      1     1     1  0  1  lanes 2 table Ram
        "two lanes, each with its own loaded table, with colour under whole-beat backpressure, memories for the iCE40";
}

/// The row called `name`.
pub fn row(name: &str) -> Option<GridRow> {
    rows().into_iter().find(|r| r.name == name)
}

/// The narrowest design with every stage: each width at the low end of its range, the
/// reciprocal at its smallest legal value (frac_bits + 1) and interpolation on with one bit;
/// the paper's switches and depth otherwise.
pub fn narrowest() -> Config {
    let min = |f: &str| RANGES.iter().find(|r| r.0 == f).expect("a width field").1;
    Config {
        grad_bits: min("grad_bits"),
        red_bits: min("red_bits"),
        recip_bits: min("recip_bits").max(min("frac_bits") + 1),
        frac_bits: min("frac_bits"),
        index_bits: min("index_bits"),
        interp_bits: min("interp_bits").max(1),
        map_bits: min("map_bits"),
        ..Config::default()
    }
}

/// The rows named (all when none is), in the grid's order; an unknown name is an error
/// listing the rows.
pub fn selected(names: &[String]) -> anyhow::Result<Vec<GridRow>> {
    let rows = rows();
    if let Some(n) = names
        .iter()
        .find(|n| !rows.iter().any(|r| r.name == n.as_str()))
    {
        let all: Vec<&str> = rows.iter().map(|r| r.name).collect();
        anyhow::bail!(
            "--row {n}: no such row in the grid; rows: {}",
            all.join(", ")
        );
    }
    Ok(rows
        .into_iter()
        .filter(|r| names.is_empty() || names.iter().any(|n| n == r.name))
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_narrowest_design_is_valid_and_its_row_only_changes_the_depth() {
        narrowest().validate().unwrap();
        let r = row("narrowest").unwrap();
        assert_eq!(
            r.config,
            Config {
                pipeline_depth: 0,
                ..narrowest()
            }
        );
        assert!(row("no such row").is_none());
    }
}
