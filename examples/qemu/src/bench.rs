//! Measuring instructions per call, and checks that end the run with a failure status.
//!
//! Every benchmark line has the form `bench <name> <instructions/call>`, so a script can pick
//! them out of the semihosting output.

use core::arch::asm;
use core::fmt;
use core::hint::black_box;

use cortex_m_semihosting::{debug, hprintln};

use crate::icount;

/// Prints `firmware: FAILED: <why>` and ends the run with a failure status.
pub fn fail(why: fmt::Arguments) -> ! {
    hprintln!("firmware: FAILED: {}", why);
    debug::exit(debug::EXIT_FAILURE);
    // Only reached when no debugger or emulator is attached to act on the exit request.
    loop {
        cortex_m::asm::bkpt();
    }
}

/// Fails the run (see [`fail`]) unless `ok`.
macro_rules! ensure {
    ($ok:expr, $($why:tt)+) => {
        let ok: bool = $ok;
        if !ok {
            $crate::bench::fail(format_args!($($why)+));
        }
    };
}
pub(crate) use ensure;

/// Runs `f` `calls` times and returns the instructions spent, loop included.
#[inline(never)]
fn run<F: FnMut()>(calls: u32, mut f: F) -> u64 {
    let calls = black_box(calls);
    let start = icount::instructions();
    for _ in 0..calls {
        f();
    }
    icount::instructions() - start
}

/// Runs `f` on every input, `reps` times over, keeping each result; returns the instructions
/// spent, loop included.
#[inline(never)]
fn run_each<T: Copy, R, F: FnMut(T) -> R>(inputs: &[T], reps: u32, mut f: F) -> u64 {
    let reps = black_box(reps);
    let start = icount::instructions();
    for _ in 0..reps {
        for &x in inputs {
            black_box(f(black_box(x)));
        }
    }
    icount::instructions() - start
}

/// `(total - overhead) / calls`, rounded to the nearest instruction.
fn per_call(total: u64, overhead: u64, calls: u64) -> u64 {
    (total.saturating_sub(overhead) + calls / 2) / calls.max(1)
}

/// Instructions per call of `f`, over `calls` calls, less the cost of the same loop with an
/// empty body; prints `bench <label> <instructions/call>` and returns the count.
pub fn measure<F: FnMut()>(label: &str, calls: u32, f: F) -> u64 {
    let overhead = run(calls, || black_box(()));
    let total = run(calls, f);
    let n = per_call(total, overhead, u64::from(calls));
    hprintln!("bench {:<28} {:>7}", label, n);
    n
}

/// Instructions per call of `f` over a table of inputs (each result kept with `black_box`),
/// `reps` passes over the table, less the cost of the same loop passing each input through
/// unchanged; prints `bench <label> <instructions/call>` and returns the count.
pub fn measure_each<T: Copy, R, F: FnMut(T) -> R>(
    label: &str,
    inputs: &[T],
    reps: u32,
    f: F,
) -> u64 {
    let overhead = run_each(inputs, reps, |x| x);
    let total = run_each(inputs, reps, f);
    let calls = inputs.len() as u64 * u64::from(reps);
    let n = per_call(total, overhead, calls);
    hprintln!("bench {:<28} {:>7}", label, n);
    n
}

/// Instructions in one pass of [`spin`]'s loop body: eight `nop`s, `subs`, `bne`.
const SPIN_BODY: u64 = 10;

/// Executes exactly `SPIN_BODY * iterations` instructions (plus a constant), `iterations > 0`.
#[inline(never)]
fn spin(iterations: u32) {
    let n = iterations.max(1);
    // SAFETY: a register-only countdown loop; touches no memory and no stack.
    unsafe {
        asm!(
            "2:",
            "nop", "nop", "nop", "nop", "nop", "nop", "nop", "nop",
            "subs {n}, {n}, #1",
            "bne 2b",
            n = inout(reg) n => _,
            options(nomem, nostack),
        );
    }
}

/// Checks the instruction counter against code of known length, and the overhead
/// subtraction of [`measure`] against a body of exactly ten instructions.
///
/// The first spin runs past a SysTick wrap (2^24 counts), so the wrap counting is exercised.
pub fn calibrate() {
    let ticks = |iterations: u32| {
        let start = icount::now();
        spin(iterations);
        icount::now() - start
    };
    // The difference of two runs cancels the call and the counter reads.
    let (short, long) = (100_000u32, 70_100_000u32);
    let d_ticks = ticks(long) - ticks(short);
    let d_instr = SPIN_BODY * u64::from(long - short);
    let milli = d_instr * 1000 / d_ticks.max(1);
    hprintln!(
        "calibrate: {} instructions in {} SysTick counts = {}.{:03} instructions/count",
        d_instr,
        d_ticks,
        milli / 1000,
        milli % 1000
    );
    let expected = d_instr / icount::INSTRUCTIONS_PER_TICK;
    ensure!(
        d_ticks.abs_diff(expected) <= 2,
        "SysTick counted {} for {} instructions, expected {} (is -icount shift=0 set?)",
        d_ticks,
        d_instr,
        expected
    );

    let ten = measure("calibrate::ten_nops", 10_000, || {
        // SAFETY: ten `nop`s; no memory, no stack, no registers.
        unsafe {
            asm!(
                "nop",
                "nop",
                "nop",
                "nop",
                "nop",
                "nop",
                "nop",
                "nop",
                "nop",
                "nop",
                options(nomem, nostack, preserves_flags)
            )
        }
    });
    ensure!(
        ten == 10,
        "measure() reports {} instructions for ten nops",
        ten
    );
}
