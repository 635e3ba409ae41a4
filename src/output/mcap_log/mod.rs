//! MCAP logs for Foxglove: a streaming writer ([`writer`]), Foxglove scene messages
//! ([`scene`]), the JSON channels' schemas ([`json_schemas`]), the planner's observer ([`plan_log`]), and tools for finished or broken files
//! ([`reader`], [`inspect`], [`recover`]).

pub mod file;
pub mod inspect;
pub mod json_schemas;
pub mod plan_log;
pub mod reader;
pub mod recover;
pub mod scene;
pub mod writer;

pub use plan_log::{PlanLog, SharedWriter, lock, log_margin, log_static};
pub use writer::{LogError, McapWriter};
