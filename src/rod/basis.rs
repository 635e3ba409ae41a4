//! The Ritz basis, written in the dimensionless arc length `t = s/L ∈ [0, 1]`. The paper's
//! §4.1 ([`BasisKind::Paper`]):
//!
//! `e₀ = 1, e₁ = t, e₂ᵢ = sin(2πi t), e₂ᵢ₊₁ = cos(2πi t)`, `i = 1..pairs`.
//!
//! The paper writes `e₂ = s`; using `t = s/L` instead makes every coefficient dimensionless
//! (a coefficient `b` of `t` equals `b/L` of the paper's `s`). Its sines and cosines are
//! periodic, and a shape whose curvature differs at its two ends is not: there the paper's
//! basis converges only algebraically. [`BasisKind::Legendre`] spans the polynomials of the same
//! number of degrees of freedom, `e₀ = 1, e₁ = t, e_k = P_k(2t − 1)` (`k = 2..1 + 2·pairs`, the
//! Legendre polynomials), and converges spectrally for any smooth shape.

use std::f64::consts::TAU;

/// Which functions a [`Basis`] holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BasisKind {
    /// The paper's `1, t, sin(2πit), cos(2πit)`.
    #[default]
    Paper,
    /// `1, t, P₂(2t − 1), …, P_{1+2·pairs}(2t − 1)`: polynomials of degree `1 + 2·pairs`.
    Legendre,
}

/// A Ritz basis with `pairs` sine/cosine pairs (`2 + 2·pairs` functions), optionally split at
/// `t_a` (paper §6.2): then it also holds `H(t − t_a)·eᵢ(t)`, so that a field is
/// `a_l·e(t)` left of `t_a` and `(a_l + b)·e(t) = a_r·e(t)` right of it; continuity at `t_a`,
/// `b·e(t_a) = 0`, is a linear constraint of the problem (see [`Basis::continuity_row`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Basis {
    pairs: usize,
    split: Option<f64>,
    kind: BasisKind,
}

impl Basis {
    /// The paper's basis with `pairs` sine/cosine pairs. The paper uses 4 (10 functions).
    pub fn new(pairs: usize) -> Self {
        Basis {
            pairs,
            split: None,
            kind: BasisKind::Paper,
        }
    }

    /// The same basis split at `t_a ∈ (0, 1)`: twice as many functions.
    pub fn split_at(pairs: usize, t_a: f64) -> Self {
        Basis {
            pairs,
            split: Some(t_a),
            kind: BasisKind::Paper,
        }
    }

    /// The same number of functions, of `kind`.
    pub fn of_kind(self, kind: BasisKind) -> Self {
        Basis { kind, ..self }
    }

    /// Which functions the basis holds.
    pub fn kind(&self) -> BasisKind {
        self.kind
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
        Basis::new(self.pairs)
            .of_kind(self.kind)
            .values(ta, &mut row[half..]);
        Some(row)
    }

    /// Number of sine/cosine pairs (for Legendre polynomials: the degree is `1 + 2·pairs`).
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
        match self.kind {
            BasisKind::Paper => {
                for i in 1..=self.pairs {
                    let (s, c) = (TAU * i as f64 * t).sin_cos();
                    out[2 * i] = s;
                    out[2 * i + 1] = c;
                }
            }
            BasisKind::Legendre => {
                // (n + 1) P_{n+1} = (2n + 1) x P_n − n P_{n−1}, x = 2t − 1.
                let x = 2.0 * t - 1.0;
                let (mut p0, mut p1) = (1.0, x);
                for (k, o) in out[2..2 + 2 * self.pairs].iter_mut().enumerate() {
                    let n = (k + 1) as f64;
                    let p2 = ((2.0 * n + 1.0) * x * p1 - n * p0) / (n + 1.0);
                    *o = p2;
                    (p0, p1) = (p1, p2);
                }
            }
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
        match self.kind {
            BasisKind::Paper => {
                for i in 1..=self.pairs {
                    let w = TAU * i as f64;
                    let (s, c) = (w * t).sin_cos();
                    out[2 * i] = w * c;
                    out[2 * i + 1] = -w * s;
                }
            }
            BasisKind::Legendre => {
                // P'_{n+1} = P'_{n−1} + (2n + 1) P_n, and d/dt = 2 d/dx.
                let x = 2.0 * t - 1.0;
                let (mut p0, mut p1) = (1.0, x);
                let (mut d0, mut d1) = (0.0, 1.0);
                for (k, o) in out[2..2 + 2 * self.pairs].iter_mut().enumerate() {
                    let n = (k + 1) as f64;
                    let p2 = ((2.0 * n + 1.0) * x * p1 - n * p0) / (n + 1.0);
                    let d2 = d0 + (2.0 * n + 1.0) * p1;
                    *o = 2.0 * d2;
                    (p0, p1, d0, d1) = (p1, p2, d1, d2);
                }
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// Legendre values against the closed forms of P₂…P₅ and derivatives against central
    /// differences of the values.
    #[test]
    fn legendre_values_and_derivatives() {
        let b = Basis::new(2).of_kind(BasisKind::Legendre);
        let (mut e, mut d, mut ep, mut em) =
            (vec![0.0; 6], vec![0.0; 6], vec![0.0; 6], vec![0.0; 6]);
        for &t in &[0.0, 0.13, 0.5, 0.77, 1.0] {
            b.values(t, &mut e);
            let x: f64 = 2.0 * t - 1.0;
            let closed = [
                1.0,
                t,
                0.5 * (3.0 * x * x - 1.0),
                0.5 * (5.0 * x.powi(3) - 3.0 * x),
                (35.0 * x.powi(4) - 30.0 * x * x + 3.0) / 8.0,
                (63.0 * x.powi(5) - 70.0 * x.powi(3) + 15.0 * x) / 8.0,
            ];
            for k in 0..6 {
                assert!((e[k] - closed[k]).abs() < 1e-14, "P{k}({t})");
            }
            b.derivatives(t, &mut d);
            let h = 1e-6;
            b.values(t + h, &mut ep);
            b.values(t - h, &mut em);
            for k in 0..6 {
                assert!(
                    (d[k] - (ep[k] - em[k]) / (2.0 * h)).abs() < 1e-7,
                    "P{k}'({t})"
                );
            }
        }
    }
}
