//! End orientations as robots write them — a rotation (from a quaternion, or a tangent and a
//! twist about it, or a full set of Euler angles) — turned into the ZYZ Euler angles the rod's
//! fields use, in the branch that continues from a reference frame.
//!
//! One rotation has many Euler spellings: `(φ, θ, ψ)`, `(φ + π, −θ, ψ + π)` and every 2π
//! multiple of each angle. For a rod they are not all the same state: `φ + ψ` adding 2π is one
//! more turn of twist, `θ` adding 2π one more loop. The branch chosen here is, in order:
//! 1. the sign of `θ` nearest the reference's `θ` (`θ ≥ 0` when the reference is on the pole
//!    `θ = 0`): the interpolated path then keeps `θ` off the pole, where the angles degenerate;
//! 2. `φ + ψ` nearest the reference's (the least extra twist);
//! 3. `φ` nearest the written `φ` if the user wrote one, else the reference's `φ`; an exact tie
//!    (the two mirror routes of a symmetric problem) takes the larger `φ`. A written `φ` more
//!    than half a turn from the reference's is taken as its spelling nearest the reference's:
//!    `φ` adding 2π with `ψ` taking it back is the same end frame, and continued from the
//!    reference it would swing the rod once more about the reference's z axis.
//!
//! The reference is the held end's frame for the start and the start shape's end for the goal,
//! so equivalent spellings of a pose give the same angles and the same plan.

use crate::rod::kinematics::{angles_of, rotation};
use std::f64::consts::{PI, TAU};

/// A rotation matrix (row-major).
pub type Matrix = [[f64; 3]; 3];

/// The rotation of a twist-free frame turned to `tangent` and then by `twist` (radians) about
/// it: `A(φ_t, θ_t, twist − φ_t)`, where `(φ_t, θ_t)` are the tangent's spherical angles. At
/// `twist = 0` it is the shortest-arc rotation from the natural state's `+z` to the tangent.
pub fn tangent_twist(tangent: [f64; 3], twist: f64) -> Matrix {
    let n = tangent.iter().map(|v| v * v).sum::<f64>().sqrt();
    let t = tangent.map(|v| v / n);
    let theta = t[2].clamp(-1.0, 1.0).acos();
    let phi = if t[0] == 0.0 && t[1] == 0.0 {
        0.0
    } else {
        t[1].atan2(t[0])
    };
    rotation(phi, theta, twist - phi)
}

/// How far past half a turn from the reference's `φ` a written `φ` is still taken as written
/// (radians): the reference is a solved shape's end, which holds its pose to the solver's
/// tolerance, so that a mirror-image goal written exactly half a turn from a start may lie a
/// little past it.
const HALF_TURN_SLACK: f64 = 1e-6;

/// `x + 2πn` nearest `target`.
pub(crate) fn nearest(x: f64, target: f64) -> f64 {
    x + TAU * ((target - x) / TAU).round()
}

/// The Euler angles of `m` in the branch described in the module documentation, continuing
/// from `reference` (its `(φ, θ, ψ)`); `written_phi` is the `φ` the user wrote, if any.
pub fn euler_branch(m: Matrix, reference: [f64; 3], written_phi: Option<f64>) -> [f64; 3] {
    let [f0, t0, p0] = angles_of(m);
    let [rf, rt, rp] = reference;
    // 1. θ's sign.
    let (f, theta, p) = if t0 > 0.0 && (-t0 - rt).abs() < (t0 - rt).abs() - 1e-12 {
        (f0 + PI, -t0, p0 + PI)
    } else {
        (f0, t0, p0)
    };
    // 2. φ + ψ nearest the reference's.
    let sum = nearest(f + p, rf + rp);
    // 3. φ nearest the written (or the reference's) φ; an exact tie takes the larger. A
    //    written φ more than half a turn from the reference's is another spelling of one
    //    nearer it (the same pose, without the extra swing about the reference's z axis).
    let target = written_phi.unwrap_or(rf);
    let lo = nearest(f, target);
    let hi = if lo < target { lo + TAU } else { lo - TAU };
    let phi = if ((hi - target).abs() - (lo - target).abs()).abs() <= 1e-9 {
        lo.max(hi)
    } else {
        lo
    };
    let phi = if (phi - rf).abs() > PI + HALF_TURN_SLACK {
        nearest(f, rf)
    } else {
        phi
    };
    [phi, theta, sum - phi]
}

/// The planar angle `θ` of a rotation about `y` (`m = Ry(θ)`), `2πn` from the one nearest
/// `reference`; `None` when `m` is not a rotation about `y` (to 1e-6). A half-turn either way
/// from `reference` (a mirror-image goal, within 1e-6 rad) is a tie, which goes to the branch
/// nearer `held` (the held end's angle): the rod then winds less, and the choice does not hang
/// on the rounding of `reference`.
pub fn planar_branch(m: Matrix, reference: f64, held: f64) -> Option<f64> {
    let about_y = (m[1][1] - 1.0).abs() <= 1e-6
        && m[0][1].abs() <= 1e-6
        && m[2][1].abs() <= 1e-6
        && m[1][0].abs() <= 1e-6
        && m[1][2].abs() <= 1e-6;
    about_y.then(|| {
        let theta = nearest(m[0][2].atan2(m[2][2]), reference);
        let d = theta - reference;
        let other = theta - TAU * d.signum();
        if (d.abs() - PI).abs() <= 1e-6 && (other - held).abs() < (theta - held).abs() {
            other
        } else {
            theta
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn same(a: Matrix, b: Matrix) -> bool {
        (0..3).all(|i| (0..3).all(|j| (a[i][j] - b[i][j]).abs() < 1e-12))
    }

    #[test]
    fn branches_keep_the_rotation() {
        for (f, t, p) in [
            (0.3, 1.1, -0.7),
            (3.0, -0.4, 2.0),
            (-1.0, 3.1, 0.4),
            (0.2, 0.0, 0.5),
        ] {
            let m = rotation(f, t, p);
            for r in [[0.0, 0.0, 0.0], [3.0, -1.0, 0.0], [-2.0, 2.0, 7.0]] {
                let [a, b, c] = euler_branch(m, r, None);
                assert!(same(rotation(a, b, c), m), "{f} {t} {p} from {r:?}");
            }
        }
    }

    /// The bar case's goal in three spellings gives its hand-written angles.
    #[test]
    fn equivalent_spellings_give_one_branch() {
        let start = [0.0, 0.4, 0.5];
        let written = [PI, 0.4, -PI - 0.5];
        let m = rotation(written[0], written[1], written[2]);
        let tangent = [m[0][2], m[1][2], m[2][2]];
        for (mat, phi) in [
            (m, Some(PI)),
            (rotation(0.0, -0.4, -0.5), Some(0.0)),
            (tangent_twist(tangent, -0.5), None),
        ] {
            let got = euler_branch(mat, start, phi);
            for i in 0..3 {
                assert!((got[i] - written[i]).abs() < 1e-12, "{got:?}");
            }
        }
    }

    /// A written φ a turn (or more than half a turn) from the reference's is the same frame
    /// spelled another way: it takes the branch nearest the reference, where a written φ within
    /// half a turn of it (a mirror-image goal's π or −π included) is kept.
    #[test]
    fn a_written_phi_past_half_a_turn_is_taken_nearest_the_reference() {
        let start = [0.2, 0.4, 0.5];
        for (written, phi) in [
            ([0.2 + TAU, 0.4, 0.5 - TAU], 0.2),
            ([0.2 - 2.0 * TAU, 0.4, 0.5 + 2.0 * TAU], 0.2),
            ([-PI + 0.1, 0.7, 0.3], PI + 0.1),
            ([PI + 0.1, 0.7, 0.3], PI + 0.1),
            ([-PI + 0.3, 0.7, 0.3], -PI + 0.3),
        ] {
            let m = rotation(written[0], written[1], written[2]);
            let got = euler_branch(m, start, Some(written[0]));
            assert!(same(rotation(got[0], got[1], got[2]), m), "{got:?}");
            assert!((got[0] - phi).abs() < 1e-12, "{written:?}: {got:?}");
            assert!((got[1] - written[1]).abs() < 1e-12, "{written:?}: {got:?}");
            // The least extra twist, as before.
            assert!(
                (got[0] + got[2] - (start[0] + start[2])).abs() <= PI,
                "{got:?}"
            );
        }
        // The mirror-image goal of the bar case, φ = ±π from a start at 0 (a little either side
        // of it, as a solved start holds it), keeps the φ written.
        for r in [-1e-8, 0.0, 1e-8] {
            for w in [PI, -PI] {
                let got = euler_branch(rotation(w, 0.4, -0.5 - w), [r, 0.4, 0.5], Some(w));
                assert!((got[0] - w).abs() < 1e-12, "{w} from {r}: {got:?}");
            }
        }
    }

    #[test]
    fn tangent_twist_points_the_tangent() {
        let m = tangent_twist([1.0, 2.0, -0.5], 0.3);
        let n = (1.0f64 + 4.0 + 0.25).sqrt();
        assert!((m[0][2] - 1.0 / n).abs() < 1e-15);
        assert!((m[1][2] - 2.0 / n).abs() < 1e-15);
        assert!((m[2][2] + 0.5 / n).abs() < 1e-15);
    }

    #[test]
    fn planar_rotation_is_about_y() {
        let m = rotation(0.0, 0.5, 0.0);
        assert!((planar_branch(m, 6.0, 0.0).unwrap() - (0.5 + TAU)).abs() < 1e-12);
        assert!(planar_branch(rotation(0.3, 0.5, 0.0), 0.0, 0.0).is_none());
        // A mirror-image goal, a half-turn either way from the start's π/2 (up to rounding on
        // either side): the branch nearer the held end's 0, whichever way the rounding went.
        let down = rotation(0.0, -FRAC_PI_2, 0.0);
        for eps in [-1e-10, 0.0, 1e-10] {
            let t = planar_branch(down, FRAC_PI_2 + eps, 0.0).unwrap();
            assert!((t + FRAC_PI_2).abs() < 1e-12, "{t}");
        }
        // Held pointing down (θ(0) = π): the other branch is the one that winds less.
        let t = planar_branch(down, FRAC_PI_2, PI).unwrap();
        assert!((t - 3.0 * FRAC_PI_2).abs() < 1e-12, "{t}");
    }
}
