// A workgroup-wide prefix sum, shared by the assignment's list offsets and tile walk and
// the far field's radix sort.

const SCAN_THREADS: u32 = #SCAN_THREADS;
var<workgroup> scan_values: array<u32, SCAN_THREADS>;

// Turns scan_values into its inclusive prefix sums (Hillis-Steele); every thread of the
// workgroup calls it with its own value, from uniform control flow.
fn inclusive_scan(thread: u32, value: u32) {
    scan_values[thread] = value;
    workgroupBarrier();
    for (var stride = 1u; stride < SCAN_THREADS; stride *= 2u) {
        var left = 0u;
        if thread >= stride {
            left = scan_values[thread - stride];
        }
        workgroupBarrier();
        scan_values[thread] += left;
        workgroupBarrier();
    }
}
