//! The manylights application, between the facade and the `manylights` binary: the command
//! line ([`cli`]: `render` and the arguments of every command; [`terminal`]: running
//! `bench` and `soak` with progress bars), the lab ([`lab`]: a benchmark matrix timed per
//! pass and measured against the f64 reference, with its reports and charts) and the soak
//! test ([`soak`]). `report` depends on `lab`'s result types, `soak` only on the facade;
//! `cli` and `lab` still import each other (the lab builds its frames through
//! `cli::frame_settings`, and the command line parses into the lab's matrix): untangling
//! them, so that the lab depends on the facade alone, is issue 43's open part.

pub mod cli;
pub mod lab;
pub mod report;
pub mod soak;
#[cfg(not(target_arch = "wasm32"))]
pub mod terminal;
