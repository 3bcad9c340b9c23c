//! The soak tests' memory limits (`soak.rs`, `soak_leak_check.rs`).

use manylights_lab::soak::SCHEDULE_PERIOD;

/// What the resident-memory check claims to catch: host memory that neither the Rust-heap
/// count nor the GPU allocator sees (a driver object or C allocation kept per settings
/// change), at 1 MiB per phase, which is 60 MiB a cycle of [`SCHEDULE_PERIOD`] phases. The
/// limit is half a cycle of that leak, so the leak exceeds it twice over (proved by
/// `resident_check_catches_a_leak_of_the_claimed_size`). Lavapipe (Mesa 22.3.6) itself
/// grows by about 14 MiB a cycle of this schedule (measured: +13.8 and +14.1 MiB; flat on
/// NVIDIA with the same code; heaptrack puts it in lavapipe's threads and JIT code), under
/// the limit by 2x. Smaller leaks of Rust or GPU memory are the exact checks' job: the Rust
/// heap may grow by at most 1 MiB and GPU allocations must repeat byte for byte.
pub const LEAK_TO_CATCH_PER_PHASE: usize = 1 << 20;
pub const MAX_RSS_GROWTH_MIB: f64 =
    (LEAK_TO_CATCH_PER_PHASE as f64 * SCHEDULE_PERIOD as f64) / 2.0 / (1024.0 * 1024.0);
