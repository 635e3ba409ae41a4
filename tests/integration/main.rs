//! The integration tests, one module per subject, linked into one test binary (one link
//! instead of one per file). Run one subject with `cargo test --release --test integration
//! golden::`.

mod balance;
mod branches;
mod clear_samples;
mod cli_errors;
mod common;
mod contacts;
mod elastica;
mod failure_advice;
mod golden;
mod gradients;
mod grasp;
mod hostile_cases;
mod hostile_logs;
mod invariants;
mod mcap_log;
mod paper_claims;
mod planner;
mod planner_gradients;
mod readme_example;
mod self_contact;
#[path = "../../examples/plan_suite.rs"]
#[allow(dead_code)]
mod suite;
mod suite_sample;
mod threads;
mod time_limit;
mod tracking_slopes;
mod turned_scenes;
mod wide_kernels;
