//! The Ritz basis of the paper's §4.1, written in the dimensionless arc length `t = s/L ∈ [0, 1]`:
//!
//! `e₀ = 1, e₁ = t, e₂ᵢ = sin(2πi t), e₂ᵢ₊₁ = cos(2πi t)`, `i = 1..pairs`.
//!
//! The paper writes `e₂ = s`; using `t = s/L` instead makes every coefficient dimensionless
//! (a coefficient `b` of `t` equals `b/L` of the paper's `s`).

use std::f64::consts::TAU;

/// A Ritz basis with `pairs` sine/cosine pairs (`2 + 2·pairs` functions).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Basis {
    pairs: usize,
}

impl Basis {
    /// A basis with `pairs` sine/cosine pairs. The paper uses 4 (10 functions).
    pub fn new(pairs: usize) -> Self {
        Basis { pairs }
    }

    /// Number of sine/cosine pairs.
    pub fn pairs(&self) -> usize {
        self.pairs
    }

    /// Number of basis functions, `2 + 2·pairs`.
    pub fn len(&self) -> usize {
        2 + 2 * self.pairs
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
