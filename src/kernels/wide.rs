//! Runtime selection of wider vector instructions for the hot loops.
//!
//! The crate is built for the baseline x86-64 instruction set (two doubles per vector
//! instruction), so that one binary runs on every x86-64 processor. The loops over quadrature
//! nodes are independent lane by lane, so where the processor has AVX2 they are worth running
//! four doubles wide: [`avx2`] says whether it has, and the kernels that take the wide path are
//! compiled twice, once with `#[target_feature(enable = "avx2")]`. The results are bit for bit
//! the same on both paths: Rust neither fuses nor reorders floating-point operations, so the
//! wider instructions compute the same IEEE operations in the same order (a test checks this
//! on a planning run).

/// Whether the wide kernels run (x86-64 with AVX2, and `DLO_NO_AVX2` unset).
#[inline]
pub fn avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        use std::sync::atomic::{AtomicU8, Ordering};
        // 0: not yet known, 1: no, 2: yes.
        static STATE: AtomicU8 = AtomicU8::new(0);
        match STATE.load(Ordering::Relaxed) {
            1 => false,
            2 => true,
            _ => {
                let on = std::arch::is_x86_feature_detected!("avx2")
                    && std::env::var_os("DLO_NO_AVX2").is_none();
                STATE.store(if on { 2 } else { 1 }, Ordering::Relaxed);
                on
            }
        }
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Defines `$name` as a dispatcher between two compilations of the `#[inline(always)]`
/// function `$body`: one with AVX2 (taken when [`avx2`] holds) and the baseline one.
macro_rules! dispatch {
    ($(#[$meta:meta])* $vis:vis fn $name:ident $(<$lt:lifetime>)? ($($arg:ident : $ty:ty),* $(,)?) $(-> $ret:ty)? => $body:path) => {
        $(#[$meta])*
        $vis fn $name $(<$lt>)? ($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx2")]
                fn wide $(<$lt>)? ($($arg: $ty),*) $(-> $ret)? {
                    $body($($arg),*)
                }
                if $crate::kernels::wide::avx2() {
                    // SAFETY: the processor has AVX2 (checked at run time).
                    return unsafe { wide($($arg),*) };
                }
            }
            $body($($arg),*)
        }
    };
}
pub(crate) use dispatch;

/// Calls `$this.$f::<C, A, B>(args…)` with the sums' vector count `C` (3 for at most 12 basis
/// functions per field, else 4) and the two field flags `A`, `B` as constants: the kernels
/// that keep their sums in registers are compiled for each layout, so that each keeps only
/// the sums its layout has.
macro_rules! by_layout {
    ($wide:expr, $a:expr, $b:expr, $this:ident . $f:ident ( $($arg:expr),* $(,)? )) => {
        match ($wide, $a, $b) {
            (false, false, false) => $this.$f::<3, false, false>($($arg),*),
            (false, false, true) => $this.$f::<3, false, true>($($arg),*),
            (false, true, false) => $this.$f::<3, true, false>($($arg),*),
            (false, true, true) => $this.$f::<3, true, true>($($arg),*),
            (true, false, false) => $this.$f::<4, false, false>($($arg),*),
            (true, false, true) => $this.$f::<4, false, true>($($arg),*),
            (true, true, false) => $this.$f::<4, true, false>($($arg),*),
            (true, true, true) => $this.$f::<4, true, true>($($arg),*),
        }
    };
}
pub(crate) use by_layout;
