//! Example firmware: runs the drive-monitor core on a Cortex-M4F and reports what it costs.
//!
//! Built for QEMU's `mps2-an386` board (the top-level `memory.x`); `cargo run --release`
//! runs it there through the runner in `.cargo/config.toml`. Output goes to the host over
//! semihosting: `bench <name> <instructions/call>` lines, checks, and a final
//! `firmware: OK`. Any failed check (or panic) ends QEMU with a non-zero exit status.
//!
//! Sections run in order from [`main`]; each is a module with a `run()` that measures with
//! [`bench::measure`] / [`bench::measure_each`] and checks with `bench::ensure!`.

#![no_std]
#![no_main]

mod balancer_bench;
mod bench;
mod drive_bench;
mod entry_points;
mod icount;
mod math_bench;
mod monitor_bench;
mod stack;
mod supports_bench;
mod three_mass_table;

use cortex_m_rt::entry;
use cortex_m_semihosting::{debug, hprintln};
use panic_semihosting as _;

#[entry]
fn main() -> ! {
    let Some(peripherals) = cortex_m::Peripherals::take() else {
        bench::fail(format_args!("core peripherals already taken"));
    };
    icount::start(peripherals.SYST);
    hprintln!("drive-monitor firmware: Cortex-M4F, instructions counted by SysTick");

    bench::calibrate();
    math_bench::run();
    monitor_bench::run();
    balancer_bench::run();
    supports_bench::run();
    drive_bench::run();

    let (used, available) = stack::peak();
    hprintln!("stack: peak {} bytes (of {} available)", used, available);

    hprintln!("firmware: OK");
    debug::exit(debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::bkpt();
    }
}
