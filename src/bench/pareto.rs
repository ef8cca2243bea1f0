//! Which rows are on a scene's Pareto fronts: error (RMSE) against cost (bits), and error
//! against one-thread speed. Separate from measuring: it reads finished rows only, and its
//! definition is tested on hand-made rows.

use super::row::Row;

/// Marks each scene's Pareto fronts: (bits, RMSE) and (one-thread speed, RMSE).
pub fn mark_pareto(rows: &mut [Row]) {
    let snapshot = rows.to_vec();
    for r in rows.iter_mut() {
        let same = snapshot.iter().filter(|o| o.scene == r.scene);
        let (mut cost, mut speed) = (true, true);
        for o in same {
            if o.bits() <= r.bits() && o.rmse <= r.rmse && (o.bits() < r.bits() || o.rmse < r.rmse)
            {
                cost = false;
            }
            if o.msamples_1_thread >= r.msamples_1_thread
                && o.rmse <= r.rmse
                && (o.msamples_1_thread > r.msamples_1_thread || o.rmse < r.rmse)
            {
                speed = false;
            }
        }
        r.pareto_cost = cost;
        r.pareto_speed = speed;
    }
}
