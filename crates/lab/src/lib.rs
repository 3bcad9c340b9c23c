//! The manylights application, between the facade and the `manylights` binary: the command
//! line ([`cli`]: `render` and the arguments of every command; [`terminal`]: running
//! `bench` and `soak` with progress bars), the lab ([`lab`]: a benchmark matrix timed per
//! pass and measured against the f64 reference, with its reports and charts) and the soak
//! test ([`soak`]). `lab`, `report` and `soak` depend on the facade alone (the lab builds
//! its frames on [`manylights::FrameSettings::default`], as `render` does); the
//! command line parses into the lab's types, never the other way round (a test,
//! `the_lab_does_not_know_the_command_line`, holds it).

pub mod cli;
#[cfg(test)]
mod every_dial_tests;
pub mod lab;
pub mod report;
pub mod soak;
#[cfg(not(target_arch = "wasm32"))]
pub mod terminal;

/// The lab, its reports and the soak are the facade's users, not the command line's: the
/// command line parses into them (its flags into [`manylights::FrameSettings`] and the lab's
/// matrix), so that a page or another program can run the lab without clap.
#[cfg(test)]
#[test]
fn the_lab_does_not_know_the_command_line() {
    let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = vec![src.join("soak.rs")];
    for folder in ["lab", "report"] {
        for entry in std::fs::read_dir(src.join(folder)).expect("the crate's sources") {
            files.push(entry.expect("a source file").path());
        }
    }
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a source file");
        for forbidden in ["crate::cli", "crate::terminal", "clap::"] {
            assert!(
                !text.contains(forbidden),
                "{} uses `{forbidden}`: the lab depends on the facade, not on the command line",
                file.display()
            );
        }
    }
    assert!(files.len() > 10, "read {} files", files.len());
}
