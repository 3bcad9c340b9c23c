//! The soak's resident-memory check catches a leak of the size it claims: the schedule of
//! the short soak (`soak.rs`) at one frame a phase, leaking host memory outside the
//! Rust-heap count. A process of its own: resident memory is the whole process's, so it
//! must not share one with the short soak.

use manylights_lab::soak::{SCHEDULE_PERIOD, SoakConfig, run};
use manylights_tests::fail_without_gpu;

#[path = "common/soak_limits.rs"]
mod soak_limits;
use soak_limits::{LEAK_TO_CATCH_PER_PHASE, MAX_RSS_GROWTH_MIB};

/// The same schedule at one frame a phase, leaking [`LEAK_TO_CATCH_PER_PHASE`] bytes of
/// written (so resident) host memory after every phase, outside the Rust-heap count: the
/// resident-memory check alone must fail it.
#[test]
fn resident_check_catches_a_leak_of_the_claimed_size() {
    let config = SoakConfig {
        frames: 3 * SCHEDULE_PERIOD,
        phase_frames: 1,
        max_rss_growth_mib: MAX_RSS_GROWTH_MIB,
        heap_bytes: None,
        ..SoakConfig::default()
    };
    let mut leaked: Vec<Vec<u8>> = Vec::new();
    let report = run(&config, |_| {
        leaked.push(vec![0xA5; LEAK_TO_CATCH_PER_PHASE])
    })
    .unwrap_or_else(|e| fail_without_gpu(e));
    println!("{}", report.summary());
    assert_eq!(leaked.len() as u64, 3 * SCHEDULE_PERIOD);
    let growth_mib = report
        .rss_growth_bytes
        .expect("resident memory was measured") as f64
        / (1024.0 * 1024.0);
    let leaked_per_cycle_mib =
        (LEAK_TO_CATCH_PER_PHASE as u64 * SCHEDULE_PERIOD) as f64 / (1024.0 * 1024.0);
    assert!(
        growth_mib >= 0.9 * leaked_per_cycle_mib,
        "a leak of {leaked_per_cycle_mib} MiB a cycle shows as only {growth_mib:.1} MiB of resident growth"
    );
    assert!(
        !report.passed,
        "a leak of {leaked_per_cycle_mib} MiB a cycle passed"
    );
    assert!(
        report
            .problems
            .iter()
            .any(|p| p.starts_with("resident memory")),
        "the resident check did not report it: {:?}",
        report.problems
    );
}
