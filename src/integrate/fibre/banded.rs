//! A symmetric banded matrix and its LDLᵀ factorisation without pivoting,
//! for the saddle-point systems of inextensible fibres ([`super::kkt`]).
//!
//! Storage is the lower band by rows, aligned by column: entry (i, j)
//! with i − b ≤ j ≤ i sits in slot b − (i − j) of row i, so a row's
//! diagonal is its last slot and slot q of every row holds column i − b + q.
//! Then every inner loop — the factorisation's update of a row, the
//! solves' products — runs over contiguous slots in increasing order (and
//! vectorises). The factorisation overwrites the band with the unit lower
//! factor L (below the diagonal) and D⁻¹ (on it, so the solve multiplies
//! where it would divide): A = L·D·Lᵀ, right-looking, b(b + 1)/2
//! multiply–adds per column. Without pivoting it needs every leading
//! principal minor to be non-zero, which holds for the fibre systems in
//! their interleaved ordering: each multiplier follows the positions it
//! constrains, so its pivot is −J·A⁻¹·Jᵀ restricted to them, strictly
//! negative, and every position pivot stays positive (Vanderbei 1995,
//! symmetric quasi-definite matrices; Golub & Van Loan, *Matrix
//! Computations*, §4.3 for banded LDLᵀ). The cost is O(N·b²), the solve
//! O(N·b), and neither allocates: the band's size is fixed when the fibre
//! is set up.

/// Half-bandwidth of the matrices this module factorises.
pub const B: usize = 8;
const W: usize = B + 1;

/// A symmetric N × N matrix of half-bandwidth [`B`], lower band stored by
/// rows: `rows[i][B − k]` is entry (i, i − k).
#[derive(Clone, Debug, PartialEq)]
pub struct Banded {
    /// The N rows, then B rows of padding that the factorisation of the
    /// last columns updates and nothing reads, so that every column has a
    /// full band below it.
    rows: Vec<[f64; W]>,
}

impl Banded {
    /// The zero matrix of order `n`.
    pub fn zeros(n: usize) -> Self {
        Self { rows: vec![[0.0; W]; n + B] }
    }

    pub fn order(&self) -> usize {
        self.rows.len() - B
    }

    /// Sets every entry to 0, keeping the storage.
    pub fn clear(&mut self) {
        self.rows.fill([0.0; W]);
    }

    /// Adds `value` to entry (i, j) (and so (j, i)); |i − j| ≤ B.
    #[inline(always)]
    pub fn add(&mut self, i: usize, j: usize, value: f64) {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        debug_assert!(i - j <= B);
        self.rows[i][B - (i - j)] += value;
    }

    /// Entry (i, j) of the matrix (before factorisation).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if i - j > B {
            0.0
        } else {
            self.rows[i][B - (i - j)]
        }
    }

    /// Makes row and column `i` those of the identity.
    pub fn isolate(&mut self, i: usize) {
        let n = self.order();
        self.rows[i] = [0.0; W];
        self.rows[i][B] = 1.0;
        for k in 1..=B.min(n - 1 - i) {
            self.rows[i + k][B - k] = 0.0;
        }
    }

    /// y = A·x (before factorisation).
    pub fn times(&self, x: &[f64], y: &mut [f64]) {
        let n = self.order();
        y[..n].fill(0.0);
        for (i, row) in self.rows[..n].iter().enumerate() {
            let mut yi = row[B] * x[i];
            for k in 1..=B.min(i) {
                yi += row[B - k] * x[i - k];
                y[i - k] += row[B - k] * x[i];
            }
            y[i] += yi;
        }
    }

    /// Factorises in place into L and D⁻¹ (right-looking: column j's
    /// multipliers l = a_·j/d_j update the trailing triangle). Fails,
    /// naming the row, on a zero or non-finite pivot.
    pub fn factorize(&mut self) -> Result<(), usize> {
        for j in 0..self.order() {
            let d = self.rows[j][B];
            if d == 0.0 || !d.is_finite() {
                return Err(j);
            }
            let inverse = 1.0 / d;
            self.rows[j][B] = inverse;
            let below: &mut [[f64; W]; B] = (&mut self.rows[j + 1..j + 1 + B]).try_into().expect("a full band");
            eliminate(inverse, below);
        }
        Ok(())
    }

    /// Solves A·x = r in place with the factors of [`Banded::factorize`].
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = self.order();
        // L·y = r.
        for i in 0..n {
            let row = &self.rows[i];
            let mut s = x[i];
            if i >= B {
                // The farthest column first: only the last product waits
                // for the entry just solved. (A tree sum of the products
                // rounds worse on long chains: the 60-point case of the
                // saddle-point test then misses its 1e-7 residual.)
                let before: &[f64; B] = x[i - B..i].try_into().expect("a full band");
                for q in 0..B {
                    s -= row[q] * before[q];
                }
            } else {
                for q in B - i..B {
                    s -= row[q] * x[i + q - B];
                }
            }
            x[i] = s;
        }
        for (xi, row) in x[..n].iter_mut().zip(&self.rows) {
            *xi *= row[B];
        }
        // Lᵀ·x = D⁻¹·y.
        for i in (0..n).rev() {
            let xi = x[i];
            let row = &self.rows[i];
            if i >= B {
                let before: &mut [f64; B] = (&mut x[i - B..i]).try_into().expect("a full band");
                for q in 0..B {
                    before[q] -= row[q] * xi;
                }
            } else {
                for q in B - i..B {
                    x[i + q - B] -= row[q] * xi;
                }
            }
        }
    }
}

/// Eliminates column j (reciprocal pivot `inverse`) from the B rows below
/// it, `below[t − 1]` being row j + t (see [`update_row`]). Each row is its
/// own instance of the update, so every loop has a fixed trip count and unrolls.
#[inline(always)]
fn eliminate(inverse: f64, below: &mut [[f64; W]; B]) {
    // c[s] = a_{j+s, j}.
    let c: [f64; W] = std::array::from_fn(|s| if s == 0 { 0.0 } else { below[s - 1][B - s] });
    const { assert!(B == 8, "one update per row below") };
    update_row::<1>(&mut below[0], &c, inverse);
    update_row::<2>(&mut below[1], &c, inverse);
    update_row::<3>(&mut below[2], &c, inverse);
    update_row::<4>(&mut below[3], &c, inverse);
    update_row::<5>(&mut below[4], &c, inverse);
    update_row::<6>(&mut below[5], &c, inverse);
    update_row::<7>(&mut below[6], &c, inverse);
    update_row::<8>(&mut below[7], &c, inverse);
}

/// Row j + T of the elimination of column j: a_{j+T, j+s} −= l·c_s for
/// 1 ≤ s ≤ T (slot B − T + s), then l = c_T/d takes the column's slot.
#[inline(always)]
fn update_row<const T: usize>(row: &mut [f64; W], c: &[f64; W], inverse: f64) {
    let l = c[T] * inverse;
    for (slot, cs) in row[B - T + 1..].iter_mut().zip(&c[1..=T]) {
        *slot -= l * cs;
    }
    row[B - T] = l;
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quasi-definite banded matrix: SPD blocks with negative multipliers
    /// between them, like a fibre's saddle-point system.
    fn sample(n: usize) -> Banded {
        let mut a = Banded::zeros(n);
        for i in 0..n {
            let multiplier = i % 3 == 2;
            a.add(i, i, if multiplier { 0.0 } else { 4.0 + (i as f64 * 0.37).sin() });
            for k in 1..=B.min(i) {
                let value = ((i * 7 + k * 3) as f64).cos() * if multiplier || (i - k) % 3 == 2 { 1.0 } else { 0.3 };
                a.add(i, i - k, value);
            }
        }
        a
    }

    #[test]
    fn the_factorisation_solves_against_the_dense_product() {
        let n = 23;
        let a = sample(n);
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.9).sin() + 0.1).collect();
        let mut r = vec![0.0; n];
        a.times(&x, &mut r);
        // The dense product agrees with `times`.
        for (i, ri) in r.iter().enumerate() {
            let dense: f64 = (0..n).map(|j| a.get(i, j) * x[j]).sum();
            assert!((dense - ri).abs() < 1e-12);
        }
        let mut f = a.clone();
        f.factorize().unwrap();
        f.solve_in_place(&mut r);
        for (xi, yi) in x.iter().zip(&r) {
            assert!((xi - yi).abs() < 1e-11, "{xi} vs {yi}");
        }
    }

    #[test]
    fn an_isolated_row_is_the_identity_and_a_zero_pivot_is_reported() {
        let mut a = sample(10);
        a.isolate(4);
        for j in 0..10 {
            assert_eq!(a.get(4, j), if j == 4 { 1.0 } else { 0.0 });
        }
        let mut singular = Banded::zeros(3);
        singular.add(0, 0, 1.0);
        assert_eq!(singular.factorize(), Err(1));
    }
}
