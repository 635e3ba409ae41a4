//! Signed distances of four points at once, for the obstacle rows' and the verification's
//! inner loops. Where the processor has AVX2 ([`crate::kernels::wide::avx2`]), balls,
//! capsules and boxes take the same IEEE operations in the same order as
//! [`Obstacle::signed_distance_value`] (parry's projections, as inlined there) on four points
//! side by side, so the results are the same to the bit while the square roots and divisions
//! of the four run together. A point where the projection branches off (a box's inside, a
//! capsule's axis), every other shape and every other processor take the one-point path.

use super::{Obstacle, ObstacleShape, v3};
use crate::kernels::written;
use std::mem::MaybeUninit;

/// Points per vector.
pub const LANES: usize = 4;

/// Points per batch: their local coordinates are gathered on the stack, then the kernels run
/// over them four at a time (consecutive fours overlap in the processor). Callers that gather
/// the points themselves do it a batch at a time too.
pub(crate) const BATCH: usize = 64;

impl Obstacle {
    /// `out[i]` = [`Obstacle::signed_distance_value`] of `points[i]` (case units).
    pub fn signed_distance_values(&self, points: &[[f64; 3]], out: &mut [f64]) {
        for (p, o) in points.chunks(BATCH).zip(out.chunks_mut(BATCH)) {
            self.batch(p, o);
        }
    }

    /// [`Obstacle::signed_distance_values`] for at most [`BATCH`] points.
    fn batch(&self, points: &[[f64; 3]], out: &mut [f64]) {
        let n = points.len().min(out.len());
        #[cfg(target_arch = "x86_64")]
        if n >= LANES
            && matches!(
                self.shape,
                ObstacleShape::Ball(_) | ObstacleShape::Capsule(_) | ObstacleShape::Cuboid(_)
            )
            && crate::kernels::wide::avx2()
        {
            let whole = n - n % LANES;
            // Left uninitialised beyond `whole` (zeroing the whole batch cost more than the
            // gathering on short batches).
            let mut xyz = [[MaybeUninit::<f64>::uninit(); BATCH]; 3];
            for (i, p) in points[..whole].iter().enumerate() {
                let v = self.to_local(v3(*p));
                xyz[0][i].write(v.x);
                xyz[1][i].write(v.y);
                xyz[2][i].write(v.z);
            }
            // SAFETY: the first `whole` of each are written just above.
            let c = xyz.each_ref().map(|x| unsafe { written(&x[..whole]) });
            let mut redo = [false; BATCH];
            match &self.shape {
                // SAFETY (all three): the processor has AVX2 (checked above).
                ObstacleShape::Ball(b) => unsafe { x86::ball(b.radius, c, out) },
                ObstacleShape::Capsule(cap) => {
                    let (a, b) = (cap.segment.a, cap.segment.b);
                    let ends = [[a.x, a.y, a.z], [b.x, b.y, b.z]];
                    unsafe { x86::capsule(ends, cap.radius, c, out, &mut redo) }
                }
                ObstacleShape::Cuboid(cb) => {
                    let h = cb.half_extents;
                    unsafe { x86::cuboid([h.x, h.y, h.z], c, out, &mut redo) }
                }
                // (Kept out by the check above.) Every point by the one-point path.
                _ => redo.fill(true),
            }
            for (i, (o, p)) in out[..n].iter_mut().zip(points).enumerate() {
                if i >= whole || redo[i] {
                    *o = self.signed_distance_value(*p);
                }
            }
            return;
        }
        for (o, p) in out[..n].iter_mut().zip(points) {
            *o = self.signed_distance_value(*p);
        }
    }
}

#[cfg(target_arch = "x86_64")]
mod x86 {
    //! The AVX2 kernels: multiplications and additions as separate instructions (no fused
    //! multiply–add, which rounds once instead of twice), in glam's order (`dot` is
    //! `(x₁x₂ + y₁y₂) + z₁z₂`).

    use std::arch::x86_64::*;

    type V = __m256d;

    #[target_feature(enable = "avx2")]
    fn load(a: [f64; 4]) -> V {
        // SAFETY: an unaligned load of four doubles from an array of four.
        unsafe { _mm256_loadu_pd(a.as_ptr()) }
    }

    #[target_feature(enable = "avx2")]
    fn store(v: V) -> [f64; 4] {
        let mut a = [0.0; 4];
        // SAFETY: an unaligned store of four doubles into an array of four.
        unsafe { _mm256_storeu_pd(a.as_mut_ptr(), v) };
        a
    }

    /// Lanes where `m` is set.
    #[target_feature(enable = "avx2")]
    fn lanes(m: V) -> [bool; 4] {
        let bits = _mm256_movemask_pd(m);
        std::array::from_fn(|l| bits & (1 << l) != 0)
    }

    #[target_feature(enable = "avx2")]
    fn dot(a: [V; 3], b: [V; 3]) -> V {
        _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(a[0], b[0]), _mm256_mul_pd(a[1], b[1])),
            _mm256_mul_pd(a[2], b[2]),
        )
    }

    /// The signed distance from `|p − q|`: zero below 1e-14, negative where `inside`.
    #[target_feature(enable = "avx2")]
    fn signed(p: [V; 3], q: [V; 3], inside: V) -> [f64; 4] {
        let v = [0, 1, 2].map(|k| _mm256_sub_pd(p[k], q[k]));
        let d = _mm256_sqrt_pd(dot(v, v));
        let signed = _mm256_blendv_pd(d, _mm256_xor_pd(d, _mm256_set1_pd(-0.0)), inside);
        let small = _mm256_cmp_pd::<_CMP_LT_OQ>(d, _mm256_set1_pd(1e-14));
        store(_mm256_blendv_pd(signed, _mm256_setzero_pd(), small))
    }

    /// The coordinates' four points from `i`.
    #[target_feature(enable = "avx2")]
    fn point(c: [&[f64]; 3], i: usize) -> [V; 3] {
        c.map(|c| load(c[i..i + 4].try_into().expect("four")))
    }

    /// Balls of radius `r` about the local origin (`Ball::project_local_point`, not solid),
    /// for the points of local coordinates `c`, four at a time, into `out`.
    #[target_feature(enable = "avx2")]
    pub(super) fn ball(r: f64, c: [&[f64]; 3], out: &mut [f64]) {
        let (vr, rr) = (_mm256_set1_pd(r), _mm256_set1_pd(r * r));
        for (i, o) in out[..c[0].len()].chunks_exact_mut(4).enumerate() {
            let p = point(c, 4 * i);
            let d2 = dot(p, p);
            let inside = _mm256_cmp_pd::<_CMP_LE_OQ>(d2, rr);
            let s = _mm256_div_pd(vr, _mm256_sqrt_pd(d2));
            o.copy_from_slice(&signed(p, p.map(|c| _mm256_mul_pd(c, s)), inside));
        }
    }

    /// A capsule of radius `r` about the segment `ends` (`project_capsule`), as [`ball`];
    /// `redo` marks the points on the axis (closer than machine epsilon), which need the
    /// one-point path.
    #[target_feature(enable = "avx2")]
    pub(super) fn capsule(
        ends: [[f64; 3]; 2],
        r: f64,
        c: [&[f64]; 3],
        out: &mut [f64],
        redo: &mut [bool],
    ) {
        let (a, b) = (ends[0], ends[1]);
        let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let sqnab = (ab[0] * ab[0]) + (ab[1] * ab[1]) + (ab[2] * ab[2]);
        let (va, vb, vab) = (
            a.map(|v| _mm256_set1_pd(v)),
            b.map(|v| _mm256_set1_pd(v)),
            ab.map(|v| _mm256_set1_pd(v)),
        );
        let (vsq, vr, zero) = (
            _mm256_set1_pd(sqnab),
            _mm256_set1_pd(r),
            _mm256_setzero_pd(),
        );
        let four = out[..c[0].len()]
            .chunks_exact_mut(4)
            .zip(redo.chunks_exact_mut(4));
        for (i, (o, redo)) in four.enumerate() {
            let p = point(c, 4 * i);
            let ap = [0, 1, 2].map(|k| _mm256_sub_pd(p[k], va[k]));
            let ab_ap = dot(vab, ap);
            let f = _mm256_div_pd(ab_ap, vsq);
            let before = _mm256_cmp_pd::<_CMP_LE_OQ>(ab_ap, zero);
            let after = _mm256_cmp_pd::<_CMP_GE_OQ>(ab_ap, vsq);
            let on = [0, 1, 2].map(|k| {
                let mid = _mm256_add_pd(va[k], _mm256_mul_pd(vab[k], f));
                // `a` where ab·ap ≤ 0, else `b` where ab·ap ≥ |ab|², else the foot.
                _mm256_blendv_pd(_mm256_blendv_pd(mid, vb[k], after), va[k], before)
            });
            let v = [0, 1, 2].map(|k| _mm256_sub_pd(p[k], on[k]));
            let dist = _mm256_sqrt_pd(dot(v, v));
            let rcp = _mm256_div_pd(_mm256_set1_pd(1.0), dist);
            let proj = [0, 1, 2]
                .map(|k| _mm256_add_pd(on[k], _mm256_mul_pd(_mm256_mul_pd(v[k], rcp), vr)));
            // `normalize_and_length` gives length 0 where 1/|v| is not a positive finite
            // number; those points, and the others closer than machine epsilon, are redone.
            let finite = _mm256_cmp_pd::<_CMP_LT_OQ>(rcp, _mm256_set1_pd(f64::INFINITY));
            let positive = _mm256_cmp_pd::<_CMP_GT_OQ>(rcp, zero);
            let far = _mm256_cmp_pd::<_CMP_GE_OQ>(dist, _mm256_set1_pd(f64::EPSILON));
            let ok = lanes(_mm256_and_pd(_mm256_and_pd(finite, positive), far));
            let inside = _mm256_cmp_pd::<_CMP_LE_OQ>(dist, vr);
            o.copy_from_slice(&signed(p, proj, inside));
            for (r, ok) in redo.iter_mut().zip(ok) {
                *r = !ok;
            }
        }
    }

    /// Boxes with half extents `h` about the local origin (`project_cuboid`), as [`ball`];
    /// `redo` marks the points inside, which need the one-point path.
    #[target_feature(enable = "avx2")]
    pub(super) fn cuboid(h: [f64; 3], c: [&[f64]; 3], out: &mut [f64], redo: &mut [bool]) {
        let zero = _mm256_setzero_pd();
        let (lo, hi) = (h.map(|h| _mm256_set1_pd(-h)), h.map(|h| _mm256_set1_pd(h)));
        let four = out[..c[0].len()]
            .chunks_exact_mut(4)
            .zip(redo.chunks_exact_mut(4));
        for (i, (o, redo)) in four.enumerate() {
            let p = point(c, 4 * i);
            // `max(v, 0)` as glam's `if v > 0 { v } else { 0 }`.
            let max0 = |v: V| _mm256_blendv_pd(zero, v, _mm256_cmp_pd::<_CMP_GT_OQ>(v, zero));
            let shift = [0, 1, 2].map(|k| {
                let mins_pt = _mm256_sub_pd(lo[k], p[k]);
                let pt_maxs = _mm256_sub_pd(p[k], hi[k]);
                _mm256_sub_pd(max0(mins_pt), max0(pt_maxs))
            });
            let proj = [0, 1, 2].map(|k| _mm256_add_pd(p[k], shift[k]));
            let unmoved = [0, 1, 2].map(|k| _mm256_cmp_pd::<_CMP_EQ_OQ>(shift[k], zero));
            let inside = _mm256_and_pd(_mm256_and_pd(unmoved[0], unmoved[1]), unmoved[2]);
            o.copy_from_slice(&signed(p, proj, zero));
            redo.copy_from_slice(&lanes(inside));
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers in [−1, 1) from a fixed linear congruential sequence.
    fn numbers(seed: u64, n: usize) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (s >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect()
    }

    /// Four points at a time give the one-point values to the bit, inside and outside, near
    /// the surface, on a capsule's axis and at a box's centre, unrotated and rotated.
    #[test]
    fn four_points_match_one_point_to_the_bit() {
        let shapes = [
            ObstacleShape::ball(0.3),
            ObstacleShape::capsule([0.0, -0.5, 0.0], [0.0, 0.5, 0.0], 0.2),
            ObstacleShape::capsule([0.1, 0.2, -0.3], [0.4, -0.1, 0.2], 0.15),
            ObstacleShape::cuboid([0.3, 0.5, 0.2]),
            ObstacleShape::cylinder(0.4, 0.2),
        ];
        let poses = [([0.0; 3], [0.0; 3]), ([0.2, -0.1, 0.7], [0.3, -0.5, 1.1])];
        for (si, shape) in shapes.iter().enumerate() {
            for (position, rotation) in poses {
                let o = Obstacle::new("o".into(), shape.clone(), position, rotation);
                let r = numbers(si as u64 + 1, 3 * 801);
                let mut pts: Vec<[f64; 3]> = r
                    .chunks_exact(3)
                    .map(|c| std::array::from_fn(|k| position[k] + 0.8 * c[k]))
                    .collect();
                // The pose's own point (a ball's or box's centre, on a capsule's axis).
                pts.push(position);
                let mut four = vec![0.0; pts.len()];
                o.signed_distance_values(&pts, &mut four);
                for (p, d) in pts.iter().zip(&four) {
                    let want = o.signed_distance_value(*p);
                    assert_eq!(d.to_bits(), want.to_bits(), "shape {si} at {p:?}");
                }
                assert!(four.iter().any(|d| *d < 0.0) && four.iter().any(|d| *d > 0.0));
            }
        }
    }
}
