//! A short order to visit several loops: nearest neighbour from the first
//! loop, then 2-opt (reversing a stretch of the order while that shortens it), over a travel
//! cost that need not be symmetric. The same is run from the given order too and the shorter
//! of the two kept, so the result is never longer than the given order. Deterministic: ties go
//! to the lower index, and improvements are taken in a fixed scan order.

/// Smallest gain a 2-opt move must bring (mm): below it, rounding could undo and redo a move
/// forever.
const MIN_GAIN: f64 = 1e-9;

/// Most 2-opt sweeps over the order (each O(n²)); an order of 200 loops settles in far fewer.
const MAX_SWEEPS: usize = 200;

/// The total cost of visiting `order` in turn.
pub(crate) fn length(order: &[usize], cost: &[Vec<f64>]) -> f64 {
    order.windows(2).map(|pair| cost[pair[0]][pair[1]]).sum()
}

/// A short open path through every index of `cost` (an n × n matrix, `cost[a][b]` the travel
/// from a to b) starting at index 0: the shorter of 2-opt after nearest neighbour and 2-opt
/// after the order 0, 1, …, n − 1.
pub(crate) fn short_order(cost: &[Vec<f64>]) -> Vec<usize> {
    let count = cost.len();
    if count <= 2 {
        return (0..count).collect();
    }
    let mut nearest = vec![0];
    let mut left: Vec<usize> = (1..count).collect();
    while !left.is_empty() {
        let here = nearest[nearest.len() - 1];
        let (at, _) = left.iter().enumerate().fold((0, f64::INFINITY), |best, (at, &next)| {
            if cost[here][next] < best.1 { (at, cost[here][next]) } else { best }
        });
        nearest.push(left.remove(at));
    }
    let from_nearest = two_opt(nearest, cost);
    let from_given = two_opt((0..count).collect(), cost);
    if length(&from_given, cost) < length(&from_nearest, cost) { from_given } else { from_nearest }
}

/// 2-opt on an open path whose first stop stays first: reverses `order[i..=j]` (1 ≤ i < j)
/// whenever that shortens the path, until no reversal does. The reversed stretch is travelled
/// backwards, so its inner legs are costed in their new direction.
fn two_opt(mut order: Vec<usize>, cost: &[Vec<f64>]) -> Vec<usize> {
    let count = order.len();
    let mut forward = vec![0.0; count];
    let mut backward = vec![0.0; count];
    for _ in 0..MAX_SWEEPS {
        // forward[k]: the legs before stop k as travelled; backward[k]: the same legs reversed.
        for k in 1..count {
            forward[k] = forward[k - 1] + cost[order[k - 1]][order[k]];
            backward[k] = backward[k - 1] + cost[order[k]][order[k - 1]];
        }
        let mut improved = false;
        'scan: for i in 1..count - 1 {
            for j in i + 1..count {
                let before = order[i - 1];
                let after = order.get(j + 1).copied();
                let old = cost[before][order[i]]
                    + (forward[j] - forward[i])
                    + after.map_or(0.0, |after| cost[order[j]][after]);
                let new = cost[before][order[j]]
                    + (backward[j] - backward[i])
                    + after.map_or(0.0, |after| cost[order[i]][after]);
                if new < old - MIN_GAIN {
                    order[i..=j].reverse();
                    improved = true;
                    break 'scan;
                }
            }
        }
        if !improved {
            break;
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    fn matrix(points: &[[f64; 2]]) -> Vec<Vec<f64>> {
        points.iter().map(|a| points.iter().map(|b| (a[0] - b[0]).hypot(a[1] - b[1])).collect()).collect()
    }

    #[test]
    fn a_scrambled_line_is_put_in_order() {
        let xs = [0.0, 70.0, 20.0, 50.0, 10.0, 60.0, 30.0, 40.0];
        let points: Vec<[f64; 2]> = xs.iter().map(|&x| [x, 0.0]).collect();
        let cost = matrix(&points);
        let order = short_order(&cost);
        assert_eq!(order[0], 0);
        let visited: Vec<f64> = order.iter().map(|&i| xs[i]).collect();
        assert_eq!(visited, [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0]);
        assert!((length(&order, &cost) - 70.0).abs() < 1e-12);
    }

    #[test]
    fn never_longer_than_the_given_order_and_every_stop_once() {
        // Points on a pseudo-random walk (a fixed linear congruential sequence).
        let mut state: u64 = 12_345;
        let mut next = || {
            state = state.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1_442_695_040_888_963_407);
            (state >> 33) as f64 / f64::from(1u32 << 31) * 100.0
        };
        for count in [1, 2, 3, 5, 12, 40] {
            let points: Vec<[f64; 2]> = (0..count).map(|_| [next(), next()]).collect();
            let cost = matrix(&points);
            let order = short_order(&cost);
            let mut sorted = order.clone();
            sorted.sort_unstable();
            assert_eq!(sorted, (0..count).collect::<Vec<_>>());
            assert_eq!(order[0], 0);
            let given: Vec<usize> = (0..count).collect();
            assert!(length(&order, &cost) <= length(&given, &cost) + 1e-12, "{count}");
            assert_eq!(short_order(&cost), order, "deterministic");
        }
    }
}
