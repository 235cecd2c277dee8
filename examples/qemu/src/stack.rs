//! Peak stack depth, read back from the paint that cortex-m-rt's `paint-stack` feature
//! leaves between the end of the statics (`_stack_end`) and the top of RAM (`_stack_start`).

use core::ptr::{addr_of, read_volatile};

use cortex_m_rt::STACK_PAINT_VALUE;

extern "C" {
    static _stack_start: u32;
    static _stack_end: u32;
}

/// `(peak bytes of stack used so far, bytes available to the stack)`.
///
/// Scans up from the stack's lowest address to the first word whose paint has been
/// overwritten.
pub fn peak() -> (usize, usize) {
    // Only the addresses of the linker symbols are taken, never their values.
    let (top, bottom) = (
        addr_of!(_stack_start) as usize,
        addr_of!(_stack_end) as usize,
    );
    let mut p = bottom;
    // SAFETY: every word in [bottom, top) is RAM reserved for the stack by the linker script,
    // word-aligned (link.x asserts it), and was written at reset.
    while p < top && unsafe { read_volatile(p as *const u32) } == STACK_PAINT_VALUE {
        p += 4;
    }
    (top - p, top - bottom)
}
