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

/// The points (cost, error) of one scene that no other is at least as good as in both, in
/// cost order: the front a chart draws for a measure the rows do not mark (the largest error).
pub fn front(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut f: Vec<(f64, f64)> = points
        .iter()
        .copied()
        .filter(|&(x, y)| {
            !points
                .iter()
                .any(|&(a, b)| a <= x && b <= y && (a < x || b < y))
        })
        .collect();
    f.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
    f.dedup();
    f
}

#[cfg(test)]
mod tests {
    use super::front;

    #[test]
    fn the_front_keeps_what_nothing_beats_in_both() {
        let p = [
            (3.0, 5.0),
            (1.0, 9.0),
            (2.0, 5.0),
            (2.0, 5.0),
            (4.0, 1.0),
            (5.0, 1.0),
            (1.5, 9.5),
        ];
        assert_eq!(front(&p), vec![(1.0, 9.0), (2.0, 5.0), (4.0, 1.0)]);
        assert!(front(&[]).is_empty());
    }
}
