//! Global-nearest-neighbour assignment: the one-to-one pairing of tracks and plots with the
//! least total cost, by the Hungarian method (Kuhn 1955; Munkres 1957) in its O(n³)
//! shortest-augmenting-path form with row and column potentials (Jonker & Volgenant,
//! *Computing* 38, 1987). Pairs outside the gate cost more than leaving both unpaired, so they
//! are never chosen.

/// The pairs `(row, column)` of the least-cost assignment of the `rows × cols` matrix `cost`
/// (row-major; `None` where a pair is not allowed), each row and column used at most once,
/// a row left unpaired at cost `miss_cost` each side (that is, a pair is taken only when it
/// costs less than `2·miss_cost`, the price of leaving both unpaired).
pub fn assign(
    cost: &[Option<f64>],
    rows: usize,
    cols: usize,
    miss_cost: f64,
) -> Vec<(usize, usize)> {
    // Square matrix of n = rows + cols: real pairs, each row's "miss" column, each column's
    // "miss" row, and zero-cost dummy pairs between the misses.
    let n = rows + cols;
    if rows == 0 || cols == 0 {
        return Vec::new();
    }
    let big = 1e18;
    let at = |i: usize, j: usize| -> f64 {
        match (i < rows, j < cols) {
            (true, true) => cost[i * cols + j].unwrap_or(big),
            (true, false) => {
                if j - cols == i {
                    miss_cost
                } else {
                    big
                }
            }
            (false, true) => {
                if i - rows == j {
                    miss_cost
                } else {
                    big
                }
            }
            (false, false) => 0.0,
        }
    };
    // Shortest augmenting paths with potentials u (rows) and v (columns), 1-based with 0 a
    // sentinel column.
    let mut u = vec![0.0; n + 1];
    let mut v = vec![0.0; n + 1];
    let mut row_of = vec![0usize; n + 1];
    let mut way = vec![0usize; n + 1];
    let mut min_to = vec![0.0; n + 1];
    let mut used = vec![false; n + 1];
    for i in 1..=n {
        row_of[0] = i;
        let mut j0 = 0;
        min_to.fill(f64::INFINITY);
        used.fill(false);
        loop {
            used[j0] = true;
            let i0 = row_of[j0];
            let mut delta = f64::INFINITY;
            let mut j1 = 0;
            for j in 1..=n {
                if !used[j] {
                    let reduced = at(i0 - 1, j - 1) - u[i0] - v[j];
                    if reduced < min_to[j] {
                        min_to[j] = reduced;
                        way[j] = j0;
                    }
                    if min_to[j] < delta {
                        delta = min_to[j];
                        j1 = j;
                    }
                }
            }
            for j in 0..=n {
                if used[j] {
                    u[row_of[j]] += delta;
                    v[j] -= delta;
                } else {
                    min_to[j] -= delta;
                }
            }
            j0 = j1;
            if row_of[j0] == 0 {
                break;
            }
        }
        loop {
            let j1 = way[j0];
            row_of[j0] = row_of[j1];
            j0 = j1;
            if j0 == 0 {
                break;
            }
        }
    }
    let mut pairs: Vec<(usize, usize)> = (1..=n)
        .filter(|&j| row_of[j] >= 1 && row_of[j] - 1 < rows && j - 1 < cols)
        .map(|j| (row_of[j] - 1, j - 1))
        .filter(|&(i, j)| cost[i * cols + j].is_some())
        .collect();
    pairs.sort_unstable();
    pairs
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every partial one-to-one pairing enumerated: the least total cost, misses included.
    fn brute_force(cost: &[Option<f64>], rows: usize, cols: usize, miss: f64) -> f64 {
        fn go(
            i: usize,
            used: &mut Vec<bool>,
            cost: &[Option<f64>],
            rows: usize,
            cols: usize,
            miss: f64,
        ) -> f64 {
            if i == rows {
                return used.iter().filter(|&&u| !u).count() as f64 * miss;
            }
            let mut best = miss + go(i + 1, used, cost, rows, cols, miss);
            for j in 0..cols {
                if let (false, Some(c)) = (used[j], cost[i * cols + j]) {
                    used[j] = true;
                    best = best.min(c + go(i + 1, used, cost, rows, cols, miss));
                    used[j] = false;
                }
            }
            best
        }
        go(0, &mut vec![false; cols], cost, rows, cols, miss)
    }

    #[test]
    fn assignment_is_the_least_cost_pairing() {
        // A small deterministic generator (xorshift) for the cases.
        let mut state = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state >> 11) as f64 / (1u64 << 53) as f64
        };
        for case in 0..300 {
            let rows = 1 + case % 5;
            let cols = 1 + (case / 5) % 6;
            let cost: Vec<Option<f64>> = (0..rows * cols)
                .map(|_| (next() < 0.7).then(|| 10.0 * next()))
                .collect();
            let miss = 4.0;
            let pairs = assign(&cost, rows, cols, miss);
            let mut seen_r = vec![false; rows];
            let mut seen_c = vec![false; cols];
            let mut total = 0.0;
            for &(i, j) in &pairs {
                assert!(!seen_r[i] && !seen_c[j], "case {case}: {pairs:?}");
                seen_r[i] = true;
                seen_c[j] = true;
                total += cost[i * cols + j].unwrap();
            }
            total += (rows - pairs.len()) as f64 * miss + (cols - pairs.len()) as f64 * miss;
            let best = brute_force(&cost, rows, cols, miss);
            assert!(
                (total - best).abs() < 1e-9,
                "case {case}: {total} vs {best}"
            );
        }
    }
}
