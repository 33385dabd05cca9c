//! A symmetric banded matrix and its LDLᵀ factorisation without pivoting,
//! for the saddle-point systems of inextensible fibres ([`super::kkt`]).
//!
//! Storage is the lower band by rows: entry (i, j) with i − b ≤ j ≤ i sits
//! in slot i − j of row i, so a row's diagonal is its first slot. The
//! factorisation overwrites the band with the unit lower factor L (below the
//! diagonal) and D (on it): A = L·D·Lᵀ, right-looking, b(b + 1)/2
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
/// rows: `rows[i][k]` is entry (i, i − k).
#[derive(Clone, Debug, PartialEq)]
pub struct Banded {
    rows: Vec<[f64; W]>,
}

impl Banded {
    /// The zero matrix of order `n`.
    pub fn zeros(n: usize) -> Self {
        Self { rows: vec![[0.0; W]; n] }
    }

    pub fn order(&self) -> usize {
        self.rows.len()
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
        self.rows[i][i - j] += value;
    }

    /// Entry (i, j) of the matrix (before factorisation).
    pub fn get(&self, i: usize, j: usize) -> f64 {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        if i - j > B {
            0.0
        } else {
            self.rows[i][i - j]
        }
    }

    /// Makes row and column `i` those of the identity.
    pub fn isolate(&mut self, i: usize) {
        let n = self.rows.len();
        self.rows[i] = [0.0; W];
        self.rows[i][0] = 1.0;
        for k in 1..=B.min(n - 1 - i) {
            self.rows[i + k][k] = 0.0;
        }
    }

    /// y = A·x (before factorisation).
    pub fn times(&self, x: &[f64], y: &mut [f64]) {
        let n = self.rows.len();
        y[..n].fill(0.0);
        for (i, row) in self.rows.iter().enumerate() {
            let mut yi = row[0] * x[i];
            for k in 1..=B.min(i) {
                yi += row[k] * x[i - k];
                y[i - k] += row[k] * x[i];
            }
            y[i] += yi;
        }
    }

    /// Factorises in place into L·D·Lᵀ (right-looking: column j's
    /// multipliers l = a_·j/d_j update the trailing triangle). Fails,
    /// naming the row, on a zero or non-finite pivot.
    #[allow(clippy::needless_range_loop)] // slot arithmetic reads clearer with indices
    pub fn factorize(&mut self) -> Result<(), usize> {
        let n = self.rows.len();
        // Columns with a full band below them: fixed bounds, so the loops unroll.
        for j in 0..n.saturating_sub(B) {
            let d = self.rows[j][0];
            if d == 0.0 || !d.is_finite() {
                return Err(j);
            }
            let below: &mut [[f64; W]; B] = (&mut self.rows[j + 1..j + 1 + B]).try_into().expect("a full band");
            let mut c = [0.0; W];
            for t in 1..=B {
                c[t] = below[t - 1][t];
            }
            let inverse = 1.0 / d;
            for t in 1..=B {
                let l = c[t] * inverse;
                let row = &mut below[t - 1];
                for s in 1..=t {
                    row[t - s] -= l * c[s];
                }
                row[t] = l;
            }
        }
        for j in n.saturating_sub(B)..n {
            let d = self.rows[j][0];
            if d == 0.0 || !d.is_finite() {
                return Err(j);
            }
            let reach = B.min(n - 1 - j);
            // c[t] = a_{j+t, j}.
            let mut c = [0.0; W];
            for t in 1..=reach {
                c[t] = self.rows[j + t][t];
            }
            let inverse = 1.0 / d;
            for t in 1..=reach {
                let l = c[t] * inverse;
                let row = &mut self.rows[j + t];
                // a_{j+t, j+s} −= l·c[s] for 1 ≤ s ≤ t: slot t − s.
                for s in 1..=t {
                    row[t - s] -= l * c[s];
                }
                row[t] = l;
            }
        }
        Ok(())
    }

    /// Solves A·x = r in place with the factors of [`Banded::factorize`].
    pub fn solve_in_place(&self, x: &mut [f64]) {
        let n = self.rows.len();
        for i in 0..n {
            let row = &self.rows[i];
            let mut s = x[i];
            if i >= B {
                let before: &[f64; B] = x[i - B..i].try_into().expect("a full band");
                for k in 1..=B {
                    s -= row[k] * before[B - k];
                }
            } else {
                for k in 1..=i {
                    s -= row[k] * x[i - k];
                }
            }
            x[i] = s;
        }
        for (xi, row) in x.iter_mut().zip(&self.rows) {
            *xi /= row[0];
        }
        for i in (0..n).rev() {
            let xi = x[i];
            let row = &self.rows[i];
            if i >= B {
                let before: &mut [f64; B] = (&mut x[i - B..i]).try_into().expect("a full band");
                for k in 1..=B {
                    before[B - k] -= row[k] * xi;
                }
            } else {
                for k in 1..=i {
                    x[i - k] -= row[k] * xi;
                }
            }
        }
    }
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
