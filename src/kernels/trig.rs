//! Sine and cosine of one angle together, for the shape evaluation's inner loop (a third of a
//! planning evaluation was the two separate libm calls per quadrature node).
//!
//! The argument is reduced to `r ∈ [−π/4, π/4]` by `x = n·π/2 + r` with π/2 split into three
//! 33-bit parts (Cody–Waite, so `n·pᵢ` is exact for `|n| < 2²⁰`), and `sin r`, `cos r` are the
//! minimax polynomials of fdlibm's `__kernel_sin` / `__kernel_cos`; the quadrant `n mod 4`
//! picks and signs them. The result is within about one unit in the last place of the correctly
//! rounded value (tested against `f64::sin_cos` below). Arguments beyond `|x| ≥ 10⁵`, which no
//! shape produces, fall back to `f64::sin_cos`.

/// `1.5 · 2⁵²`: adding it rounds a double below `2⁵¹` to the nearest integer, which then sits
/// in the low mantissa bits.
const ROUND: f64 = 6_755_399_441_055_744.0;
/// First 33 bits of π/2.
const PIO2_1: f64 = 1.5707963267341256;
/// Next 33 bits of π/2.
const PIO2_2: f64 = 6.077100506303966e-11;
/// π/2 − PIO2_1 − PIO2_2.
const PIO2_3: f64 = 2.0222662487111665e-21;

const S1: f64 = -0.16666666666666632;
const S2: f64 = 0.00833333333332249;
const S3: f64 = -0.0001984126982985795;
const S4: f64 = 2.7557313707070068e-6;
const S5: f64 = -2.5050760253406863e-8;
const S6: f64 = 1.58969099521155e-10;

const C1: f64 = 0.0416666666666666;
const C2: f64 = -0.001388888888887411;
const C3: f64 = 2.480158728947673e-5;
const C4: f64 = -2.7557314351390663e-7;
const C5: f64 = 2.087572321298175e-9;
const C6: f64 = -1.1359647557788195e-11;

/// `(sin x, cos x)`.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() >= 1e5 || !x.is_finite() {
        return x.sin_cos();
    }
    reduced(x)
}

/// `s[i], c[i] = sin x[i], cos x[i]`: without branches when every argument is in range, so
/// that the loop vectorises.
#[inline(always)]
pub fn sin_cos_slice(x: &[f64], s: &mut [f64], c: &mut [f64]) {
    if in_range(x) {
        sin_cos_slice_in_range(x, s, c);
    } else {
        for ((&xi, si), ci) in x.iter().zip(s.iter_mut()).zip(c.iter_mut()) {
            (*si, *ci) = sin_cos(xi);
        }
    }
}

/// Whether every argument is in the branch-free kernel's range `|x| < 10⁵` (false for NaN).
/// Without an early exit, so that the test vectorises.
#[inline(always)]
pub fn in_range(x: &[f64]) -> bool {
    x.iter().fold(true, |ok, v| ok & (v.abs() < 1e5))
}

/// [`sin_cos_slice`] for arguments that are all [`in_range`].
#[inline(always)]
pub fn sin_cos_slice_in_range(x: &[f64], s: &mut [f64], c: &mut [f64]) {
    for ((&xi, si), ci) in x.iter().zip(s.iter_mut()).zip(c.iter_mut()) {
        (*si, *ci) = reduced(xi);
    }
}

/// The kernel for `|x| < 10⁵`; the quadrant swaps and signs by bit operations.
#[inline(always)]
fn reduced(x: f64) -> (f64, f64) {
    let t = x * std::f64::consts::FRAC_2_PI + ROUND;
    let quadrant = t.to_bits();
    let n = t - ROUND;
    let r = ((x - n * PIO2_1) - n * PIO2_2) - n * PIO2_3;
    let z = r * r;
    let s = r + z * r * (S1 + z * (S2 + z * (S3 + z * (S4 + z * (S5 + z * S6)))));
    let hz = 0.5 * z;
    let w = 1.0 - hz;
    let c =
        w + (((1.0 - w) - hz) + z * z * (C1 + z * (C2 + z * (C3 + z * (C4 + z * (C5 + z * C6))))));
    // Quadrant q = n mod 4: odd q swaps sine and cosine; the sine is negated for q = 2, 3 and
    // the cosine for q = 1, 2.
    let swap = (quadrant & 1).wrapping_neg();
    let (sb, cb) = (s.to_bits(), c.to_bits());
    let sin = (sb & !swap) | (cb & swap);
    let cos = (cb & !swap) | (sb & swap);
    let sin_sign = (quadrant & 2) << 62;
    let cos_sign = (quadrant.wrapping_add(1) & 2) << 62;
    (
        f64::from_bits(sin ^ sin_sign),
        f64::from_bits(cos ^ cos_sign),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Units in the last place between `a` and the reference `b`.
    fn ulps(a: f64, b: f64) -> f64 {
        let ulp = f64::EPSILON * b.abs().max(f64::MIN_POSITIVE);
        ((a - b) / ulp).abs()
    }

    #[test]
    fn matches_libm_within_about_one_ulp() {
        // Deterministic sweep of angles a rod produces (|x| up to 60 rad), plus the quadrant
        // boundaries and tiny arguments.
        let mut worst: f64 = 0.0;
        let mut xs: Vec<f64> = (0..200_001)
            .map(|i| -60.0 + 120.0 * i as f64 / 200_000.0)
            .collect();
        for k in -40..=40 {
            let b = k as f64 * std::f64::consts::FRAC_PI_2;
            xs.extend([b, b + 1e-9, b - 1e-9, b + 1e-15, b - 1e-15]);
        }
        xs.extend([0.0, -0.0, 1e-300, -1e-20, 1e-8, std::f64::consts::FRAC_PI_4]);
        for &x in &xs {
            let (s, c) = sin_cos(x);
            let (s0, c0) = x.sin_cos();
            // Relative to the value, and absolutely to ulp(1) near a zero of the function (where
            // the reduction's last bit of π/2 sets the error of the libm value too).
            let es = ulps(s, s0).min((s - s0).abs() / f64::EPSILON);
            let ec = ulps(c, c0).min((c - c0).abs() / f64::EPSILON);
            worst = worst.max(es).max(ec);
        }
        assert!(worst <= 1.5, "worst error {worst} ulp");
    }

    #[test]
    fn slices_match_single_calls() {
        let x: Vec<f64> = (0..1000).map(|i| -31.0 + 0.0621 * i as f64).collect();
        let (mut s, mut c) = (vec![0.0; x.len()], vec![0.0; x.len()]);
        sin_cos_slice(&x, &mut s, &mut c);
        for i in 0..x.len() {
            assert_eq!((s[i], c[i]), sin_cos(x[i]));
        }
        let mut y = x.clone();
        y[500] = 2e5;
        sin_cos_slice(&y, &mut s, &mut c);
        assert_eq!((s[500], c[500]), 2e5_f64.sin_cos());
        assert_eq!((s[499], c[499]), sin_cos(y[499]));
    }

    #[test]
    fn large_and_non_finite_arguments_use_libm() {
        for x in [1e5, -3e7, 1e300] {
            assert_eq!(sin_cos(x), x.sin_cos());
        }
        assert!(sin_cos(f64::NAN).0.is_nan());
        assert!(sin_cos(f64::INFINITY).1.is_nan());
    }
}
