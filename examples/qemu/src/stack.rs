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

/// Bytes of stack `f` uses beyond the caller's frame: the free stack below the current stack
/// pointer is painted again, `f` runs, and the deepest overwritten word is found. (The paint
/// below the caller is the only state touched; `peak` afterwards still reports the run's peak.)
#[inline(never)]
pub fn used_by<F: FnOnce()>(f: F) -> usize {
    let bottom = addr_of!(_stack_end) as usize;
    let sp = cortex_m::register::msp::read() as usize;
    // Leave a margin for this function's own frame and the call into `f`.
    let top = sp.saturating_sub(64) & !3;
    let mut p = bottom;
    while p < top {
        // SAFETY: [bottom, top) lies below the live stack (the stack grows down from `sp`,
        // and `top` is under it with a margin), inside the region the linker reserves for the
        // stack; nothing lives there now, so painting it cannot corrupt live data.
        unsafe { core::ptr::write_volatile(p as *mut u32, STACK_PAINT_VALUE) };
        p += 4;
    }
    f();
    let mut p = bottom;
    // SAFETY: the same words as above, read back.
    while p < top && unsafe { read_volatile(p as *const u32) } == STACK_PAINT_VALUE {
        p += 4;
    }
    sp.saturating_sub(p)
}
