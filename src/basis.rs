//! The Ritz basis of the paper's §4.1, written in the dimensionless arc length `t = s/L ∈ [0, 1]`:
//!
//! `e₀ = 1, e₁ = t, e₂ᵢ = sin(2πi t), e₂ᵢ₊₁ = cos(2πi t)`, `i = 1..pairs`.
//!
//! The paper writes `e₂ = s`; using `t = s/L` instead makes every coefficient dimensionless
//! (a coefficient `b` of `t` equals `b/L` of the paper's `s`).

use std::f64::consts::TAU;

/// A Ritz basis with `pairs` sine/cosine pairs (`2 + 2·pairs` functions), optionally split at
/// `t_a` (paper §6.2): then it also holds `H(t − t_a)·eᵢ(t)`, so that a field is
/// `a_l·e(t)` left of `t_a` and `(a_l + b)·e(t) = a_r·e(t)` right of it; continuity at `t_a`,
/// `b·e(t_a) = 0`, is a linear constraint of the problem (see [`Basis::continuity_row`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Basis {
    pairs: usize,
    split: Option<f64>,
}

impl Basis {
    /// A basis with `pairs` sine/cosine pairs. The paper uses 4 (10 functions).
    pub fn new(pairs: usize) -> Self {
        Basis { pairs, split: None }
    }

    /// The same basis split at `t_a ∈ (0, 1)`: twice as many functions.
    pub fn split_at(pairs: usize, t_a: f64) -> Self {
        Basis {
            pairs,
            split: Some(t_a),
        }
    }

    /// The split point, if any.
    pub fn split(&self) -> Option<f64> {
        self.split
    }

    /// Continuity at the split: the row `r` with `r · a_field = 0` (zeros on the unsplit half).
    pub fn continuity_row(&self) -> Option<Vec<f64>> {
        let ta = self.split?;
        let half = 2 + 2 * self.pairs;
        let mut row = vec![0.0; 2 * half];
        Basis::new(self.pairs).values(ta, &mut row[half..]);
        Some(row)
    }

    /// Number of sine/cosine pairs.
    pub fn pairs(&self) -> usize {
        self.pairs
    }

    /// Number of basis functions, `2 + 2·pairs` (twice that when split).
    pub fn len(&self) -> usize {
        (2 + 2 * self.pairs) * if self.split.is_some() { 2 } else { 1 }
    }

    /// Always false: the basis holds at least `1` and `t`.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Values `e(t)` written into `out` (length [`Basis::len`]).
    pub fn values(&self, t: f64, out: &mut [f64]) {
        out[0] = 1.0;
        out[1] = t;
        for i in 1..=self.pairs {
            let (s, c) = (TAU * i as f64 * t).sin_cos();
            out[2 * i] = s;
            out[2 * i + 1] = c;
        }
        self.mirror(t, out);
    }

    /// The split half: `H(t − t_a)` times the first half (`H(0) = 0`).
    fn mirror(&self, t: f64, out: &mut [f64]) {
        if let Some(ta) = self.split {
            let half = 2 + 2 * self.pairs;
            let on = if t > ta { 1.0 } else { 0.0 };
            for i in 0..half {
                out[half + i] = on * out[i];
            }
        }
    }

    /// Derivatives `de/dt` written into `out`.
    pub fn derivatives(&self, t: f64, out: &mut [f64]) {
        out[0] = 0.0;
        out[1] = 1.0;
        for i in 1..=self.pairs {
            let w = TAU * i as f64;
            let (s, c) = (w * t).sin_cos();
            out[2 * i] = w * c;
            out[2 * i + 1] = -w * s;
        }
        self.mirror(t, out);
    }

    /// `Σ aᵢ eᵢ(t)` for one field's coefficients.
    pub fn eval(&self, coeffs: &[f64], t: f64) -> f64 {
        let mut e = vec![0.0; self.len()];
        self.values(t, &mut e);
        dot(coeffs, &e)
    }
}

/// Plain dot product of two equally long slices.
#[inline]
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}
