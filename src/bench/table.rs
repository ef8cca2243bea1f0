//! The rows as text: a Markdown table (printed and written as bench.md) and CSV (bench.csv).
//! Separate from measuring and plotting: the column layout of each format lives here.
//!
//! The FPGA columns name the family placed; with the default (iCE40, one lane) they are the
//! columns the bench had before `--family` and `--lanes`. Otherwise two more follow the
//! Fmax: DSP blocks and samples/s = lanes x Fmax.

use super::row::Row;
use crate::flow::fpga::Family;

/// The family and lane count of the rows' FPGA columns (every row of a run has the same),
/// and whether they are the default's.
fn fpga(rows: &[Row]) -> (Family, u32, bool) {
    rows.first().map_or((Family::default(), 1, true), |r| {
        (r.family, r.lanes, r.default_fpga())
    })
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let (family, lanes, default) = fpga(rows);
    let (more_head, more_rule) = if default {
        (String::new(), "")
    } else {
        (format!(" DSP | samples/s ({lanes} lanes) |"), "---:|---:|")
    };
    let mut s = format!(
        "| scene | design | map | entries | max abs (LSB) | RMSE (LSB) | PSNR (dB) | 1 thread (M/s) | all cores (M/s) | x float | map build (us) | ROM + map bits | {} cells | block RAMs | Fmax (MHz) |{more_head} Pareto |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|{more_rule}---|\n",
        family.title()
    );
    for r in rows {
        let pareto = match (r.pareto_cost, r.pareto_speed) {
            (true, true) => "cost, speed",
            (true, false) => "cost",
            (false, true) => "speed",
            _ => "",
        };
        let more = if default {
            String::new()
        } else {
            format!(
                " {} | {} |",
                r.dsps.map_or("-".into(), |d| d.to_string()),
                r.samples_per_s().map_or("-".into(), |v| format!("{v:.3e}"))
            )
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {:.3} | {:.2} | {:.0} | {:.0} | {:.1} | {:.0} | {} | {} | {} | {} |{more} {} |\n",
            r.scene,
            r.design,
            r.map_fit,
            r.entries,
            r.max_abs_error,
            r.rmse,
            r.psnr_db,
            r.msamples_1_thread,
            r.msamples_all_cores,
            r.float_ratio,
            r.map_build_us,
            r.bits(),
            if r.ice40_too_big {
                "does not fit".into()
            } else {
                r.ice40_cells.map_or("-".into(), |c| c.to_string())
            },
            r.ice40_brams.map_or("-".into(), |c| c.to_string()),
            r.fmax_mhz.map_or("-".into(), |f| format!("{f:.1}")),
            pareto
        );
    }
    s
}

/// The rows as CSV with a header line.
pub fn csv(rows: &[Row]) -> String {
    let (family, _, default) = fpga(rows);
    let f = family.name();
    let mut s = format!("scene,design,config,map_fit,entries,max_abs_error,rmse,psnr_db,msamples_1_thread,msamples_all_cores,float_ratio,map_build_us,rom_bits,map_bits,{f}_cells,{f}_brams,fmax_mhz,{f}_too_big,pareto_cost,pareto_speed");
    if !default {
        s += ",lanes,dsps,samples_per_s";
    }
    s += "\n";
    for r in rows {
        s += &format!(
            "{},{},\"{}\",{},{},{},{:.4},{:.3},{:.2},{:.2},{:.2},{:.1},{},{},{},{},{},{},{},{}",
            r.scene,
            r.design,
            r.config,
            r.map_fit,
            r.entries,
            r.max_abs_error,
            r.rmse,
            r.psnr_db,
            r.msamples_1_thread,
            r.msamples_all_cores,
            r.float_ratio,
            r.map_build_us,
            r.rom_bits,
            r.map_bits,
            r.ice40_cells.map_or(String::new(), |c| c.to_string()),
            r.ice40_brams.map_or(String::new(), |c| c.to_string()),
            r.fmax_mhz.map_or(String::new(), |f| format!("{f:.2}")),
            r.ice40_too_big,
            r.pareto_cost,
            r.pareto_speed
        );
        if !default {
            s += &format!(
                ",{},{},{}",
                r.lanes,
                r.dsps.map_or(String::new(), |d| d.to_string()),
                r.samples_per_s()
                    .map_or(String::new(), |v| format!("{v:.0}"))
            );
        }
        s += "\n";
    }
    s
}
