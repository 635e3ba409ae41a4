//! # dlo-planner
//!
//! Static modelling and deformation path planning of deformable linear objects (cables, wires,
//! threads, thin strips) after Wakamatsu & Hirai, *Static Modeling of Linear Object Deformation
//! Based on Differential Geometry* (IJRR 2004).
//!
//! A shape is four functions of arc length — Euler angles `φ, θ, ψ` and strain `ε` — each a Ritz
//! combination of `1, s/L, sin(2πis/L), cos(2πis/L)` ([`basis`]). [`model`] precomputes the
//! discretised rod, [`kinematics`] turns coefficients into positions and frames, [`energy`]
//! evaluates eq. (7)–(13) with gradients, [`constraints`] holds the geometric constraints of
//! §3.2, [`optim`] the generic multiplier method and BFGS, and [`statics`] solves static shapes
//! and reports reaction forces and stability. [`path`] and [`planner`] plan deformation paths
//! (§7) and replay them by the controlled end. [`case`] reads case files.
//!
//! The library prints nothing. Its default feature `cli` builds the `dlo` tool and with it
//! `mcap` ([`mcap_log`]: MCAP logs for Foxglove) and `plot` ([`plot`]: SVG pictures of logs); a
//! library user who needs neither depends on it with `default-features = false`.

pub mod case;
pub mod constraints;
pub mod error;
pub mod grasp;
mod kernels;
pub mod optim;
pub mod output;
pub mod planner;
pub mod rod;
pub mod scene;
pub mod statics;

pub use error::Error;
