//! Small numerical kernels behind the hot loops: sine and cosine together, and the runtime
//! choice of wider vector instructions.

pub(crate) mod trig;
pub(crate) mod wide;
