//! What runs write for people and viewers: MCAP logs for Foxglove (feature `mcap`), with their
//! topic names in [`topics`] and Foxglove's scene messages in [`foxglove`], and SVG pictures of
//! those logs (feature `plot`).

#[cfg(feature = "mcap")]
pub mod foxglove;
#[cfg(feature = "mcap")]
pub mod mcap_log;
#[cfg(feature = "plot")]
pub mod plot;
#[cfg(feature = "mcap")]
pub mod topics;
