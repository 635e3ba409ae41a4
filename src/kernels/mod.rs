//! Small numerical kernels behind the hot loops: sine and cosine together, the runtime
//! choice of wider vector instructions, and stack scratch that is not zeroed first.

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
