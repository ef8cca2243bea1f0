//! The rows as text: a Markdown table (printed and written as bench.md) and CSV (bench.csv).
//! Separate from measuring and plotting: the column layout of each format lives here.

use super::row::Row;

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| scene | design | map | entries | max abs (LSB) | RMSE (LSB) | PSNR (dB) | 1 thread (M/s) | all cores (M/s) | x float | map build (us) | ROM + map bits | iCE40 cells | block RAMs | Fmax (MHz) | Pareto |\n\
         |---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|\n",
    );
    for r in rows {
        let pareto = match (r.pareto_cost, r.pareto_speed) {
            (true, true) => "cost, speed",
            (true, false) => "cost",
            (false, true) => "speed",
            _ => "",
        };
        s += &format!(
            "| {} | {} | {} | {} | {} | {:.3} | {:.2} | {:.0} | {:.0} | {:.1} | {:.0} | {} | {} | {} | {} | {} |\n",
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
    let mut s = String::from("scene,design,config,map_fit,entries,max_abs_error,rmse,psnr_db,msamples_1_thread,msamples_all_cores,float_ratio,map_build_us,rom_bits,map_bits,ice40_cells,ice40_brams,fmax_mhz,ice40_too_big,pareto_cost,pareto_speed\n");
    for r in rows {
        s += &format!(
            "{},{},\"{}\",{},{},{},{:.4},{:.3},{:.2},{:.2},{:.2},{:.1},{},{},{},{},{},{},{},{}\n",
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
    }
    s
}
