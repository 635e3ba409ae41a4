//! Small numerical kernels behind the hot loops: sine and cosine together, the runtime
//! choice of wider vector instructions, stack scratch that is not zeroed first, and a test for
//! an all-zero slice.

pub(crate) mod trig;
pub(crate) mod wide;

use std::mem::MaybeUninit;

/// The written prefix of a stack scratch array as values: hot loops gather a batch into an
/// uninitialised array (zeroing all of it cost more than the gathering on short batches).
///
/// # Safety
/// Every element of `s` has been written.
pub(crate) unsafe fn written<T>(s: &[MaybeUninit<T>]) -> &[T] {
    // SAFETY: `MaybeUninit<T>` has `T`'s layout, and the caller vouches for the values.
    unsafe { &*(s as *const [MaybeUninit<T>] as *const [T]) }
}

/// Whether every element of `v` is ±0 (`v.iter().all(|x| *x == 0.0)`, NaN counting as
/// nonzero), without a branch per element: the multiplier vectors it tests are mostly zero and
/// thousands long.
#[inline]
pub(crate) fn all_zero(v: &[f64]) -> bool {
    v.chunks(16)
        .all(|b| b.iter().fold(0u64, |acc, x| acc | (x.to_bits() << 1)) == 0)
}

#[cfg(test)]
mod tests {
    use super::all_zero;

    /// Agrees with the element-wise test on signed zeros, NaN, infinities, subnormals and
    /// lengths around the block size.
    #[test]
    fn all_zero_agrees_with_the_elementwise_test() {
        let specials = [
            0.0,
            -0.0,
            1.0,
            f64::NAN,
            f64::INFINITY,
            -f64::MIN_POSITIVE / 4.0,
        ];
        for len in [0usize, 1, 15, 16, 17, 40] {
            for (i, &x) in specials.iter().enumerate() {
                for at in [0, len / 2, len.saturating_sub(1)] {
                    let mut v = vec![if i % 2 == 0 { 0.0 } else { -0.0 }; len];
                    if len > 0 {
                        v[at] = x;
                    }
                    assert_eq!(all_zero(&v), v.iter().all(|y| *y == 0.0), "{v:?}");
                }
            }
        }
    }
}
