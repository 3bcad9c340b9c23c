//! The manylights application, between the facade and the `manylights` binary: the command
//! line ([`cli`]: `render` and the arguments of every command; [`terminal`]: running
//! `bench` and `soak` with progress bars), the lab ([`lab`]: a benchmark matrix timed per
//! pass and measured against the f64 reference, with its reports and charts) and the soak
//! test ([`soak`]). Modules depend one way: `cli` on `lab`, `report` and `soak`; `report`
//! on `lab`'s result types; `lab` and `soak` only on the facade.

pub mod cli;
pub mod lab;
pub mod report;
pub mod soak;
#[cfg(not(target_arch = "wasm32"))]
pub mod terminal;
