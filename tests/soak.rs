//! The short soak (issue 9): three cycles of the soak schedule at 3 frames per phase (540
//! frames, every pipeline, layout, lighting path, debug view, depth convention, grid, light
//! count and light source, frame size changes) on the GPU at hand. GPU allocations must be
//! identical at identical settings one cycle apart and resident memory must not rise from
//! the second cycle to the third. The long version is `manylights soak` (100,000 frames).
//! That the resident-memory check catches a leak of its claimed size is
//! `soak_leak_check.rs`'s, a process of its own: resident memory is the whole process's.

use manylights_lab::soak::{SCHEDULE_PERIOD, SoakConfig, run};
use manylights_tests::fail_without_gpu;
use stats_alloc::{INSTRUMENTED_SYSTEM, StatsAlloc};

#[global_allocator]
static GLOBAL: &StatsAlloc<std::alloc::System> = &INSTRUMENTED_SYSTEM;

fn live_heap_bytes() -> u64 {
    manylights_lab::soak::live_heap_bytes(GLOBAL.stats())
}

#[path = "common/soak_limits.rs"]
mod soak_limits;
use soak_limits::MAX_RSS_GROWTH_MIB;

#[test]
fn short_soak_keeps_memory_flat() {
    // One frame more a phase than may be in flight: every phase runs the frame pacing's
    // wait (for the frame MAX_FRAMES_IN_FLIGHT back) and reads back timings and lists of
    // frames rendered with its own settings. (It was 4: the fourth frame cost 26 s of lavapipe
    // over the 180 phases, 163 s against 137 s.)
    let phase_frames = manylights::MAX_FRAMES_IN_FLIGHT as u64 + 1;
    let config = SoakConfig {
        frames: 3 * SCHEDULE_PERIOD * phase_frames,
        phase_frames,
        max_rss_growth_mib: MAX_RSS_GROWTH_MIB,
        heap_bytes: Some(live_heap_bytes),
        ..SoakConfig::default()
    };
    let report = run(&config, |_| {}).unwrap_or_else(|e| fail_without_gpu(e));
    println!("{}", report.summary());
    assert_eq!(report.samples.len() as u64, 3 * SCHEDULE_PERIOD);
    assert!(
        report
            .samples
            .iter()
            .all(|s| s.gpu_allocated_bytes.is_some()),
        "the Vulkan backend reports GPU allocations; without them the check is empty"
    );
    assert!(
        report.rss_growth_bytes.is_some(),
        "resident memory was measured"
    );
    assert!(
        report.heap_growth_bytes.is_some(),
        "the Rust heap was counted"
    );
    assert!(report.passed, "{}", report.summary());
}
