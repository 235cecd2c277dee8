//! Instruction counter built on SysTick.
//!
//! Under QEMU with `-icount shift=0` every instruction advances virtual time by exactly 1 ns.
//! SysTick on the core clock source counts at the board's 25 MHz, so one SysTick count is
//! [`INSTRUCTIONS_PER_TICK`] instructions. The 24-bit counter wraps every 2^24 counts
//! (about 0.67 s of virtual time); the SysTick exception counts the wraps, and [`now`] joins
//! the two into a 64-bit tick count. (QEMU does not emulate the DWT cycle counter, which reads
//! 0, so it cannot be used.) The calibration in `bench::calibrate` checks the ratio at run time.
//!
//! Instructions are not cycles: on a real Cortex-M4 loads, taken branches, divisions and
//! `vsqrt` take more than one cycle each.

use core::sync::atomic::{AtomicU32, Ordering};

use cortex_m::peripheral::{syst::SystClkSource, SCB, SYST};
use cortex_m_rt::exception;

/// SysTick reload value: the full 24-bit range.
const RELOAD: u32 = 0x00FF_FFFF;
/// Counts per SysTick period.
const PERIOD: u64 = RELOAD as u64 + 1;

/// Instructions per SysTick count: 1 ns per instruction (`-icount shift=0`) at 25 MHz.
pub const INSTRUCTIONS_PER_TICK: u64 = 40;

/// SysTick periods completed since [`start`].
static WRAPS: AtomicU32 = AtomicU32::new(0);

#[exception]
fn SysTick() {
    WRAPS.fetch_add(1, Ordering::Relaxed);
}

/// Starts SysTick on the core clock with the full reload and its wrap exception enabled.
pub fn start(mut syst: SYST) {
    syst.disable_counter();
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();
    // The cleared counter reads 0 until its first count reloads it; that 0 would read as a
    // full period elapsed, so time starts only once the counter has reloaded.
    while SYST::get_current() == 0 {}
    WRAPS.store(0, Ordering::Relaxed);
}

/// SysTick counts elapsed since [`start`].
///
/// The wrap count and the 24-bit down-counter are read separately, so a wrap can fall between
/// the two reads. The wrap count is read before and after the counter and the read is retried
/// if it changed; and if the counter has already reloaded while its exception is still pending
/// (not yet counted), that wrap is added here: a pending SysTick with a counter value in the
/// upper half of its range means the reload happened before the counter was read.
pub fn now() -> u64 {
    loop {
        let before = WRAPS.load(Ordering::Acquire);
        let current = SYST::get_current();
        let pending = SCB::is_pendst_pending();
        let after = WRAPS.load(Ordering::Acquire);
        if before != after {
            continue;
        }
        let uncounted = u64::from(pending && current > RELOAD / 2);
        let wraps = u64::from(before) + uncounted;
        return wraps * PERIOD + u64::from(RELOAD - current);
    }
}

/// Instructions elapsed since [`start`] (exact to ±[`INSTRUCTIONS_PER_TICK`]).
pub fn instructions() -> u64 {
    now() * INSTRUCTIONS_PER_TICK
}
