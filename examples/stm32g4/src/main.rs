//! Example firmware for an STM32G4 motor-control MCU: the drive-monitor core on real encoder
//! captures.
//!
//! - TIM2 (32-bit, counting at its 170 MHz kernel clock) captures encoder channel A's rising
//!   edges; DMA1 channel 1, routed by DMAMUX1, copies each capture into a circular buffer of
//!   [`ring::RING`] timestamps ([`capture`]).
//! - The DMA's half-transfer and transfer-complete interrupt hands the half that has just
//!   filled to the monitor ([`feed::Feeder::feed`], the one place the core takes captures).
//! - The index pulse is captured on TIM2_CH2, with an interrupt; its timestamp goes to the
//!   monitor just before the first capture after it.
//! - SysTick polls at [`POLL_HZ`]: the part of a half filled so far is fed, and the monitor
//!   checks for a stopped shaft.
//! - Each δ window is logged over defmt-rtt; the δ alarm drives a GPIO through the core's
//!   `AlarmOutput`.
//!
//! The chip (STM32G474 or STM32G431) is the one `--cfg chip` line of `.cargo/config.toml`;
//! the pins are in [`board`], the monitor's configuration in [`config`].

#![no_std]
#![no_main]

mod board;
mod capture;
mod config;
mod feed;
mod ring;

use core::cell::RefCell;

use cortex_m::peripheral::scb::SystemHandler;
use cortex_m::peripheral::syst::SystClkSource;
use cortex_m_rt::{entry, exception};
use critical_section::Mutex;
use defmt_rtt as _;
use drive_monitor::alarm::AlarmOutput;
use embassy_stm32::interrupt;
use embassy_stm32::interrupt::{InterruptExt, Priority};
use panic_probe as _;
use static_cell::ConstStaticCell;

use crate::config::Monitor;
use crate::feed::Feeder;

/// Standstill checks per second. The monitor needs one at least every counter period (2^32
/// ticks, 25 s at 170 MHz); 100 Hz notices a stopped shaft within 10 ms of its timeout.
const POLL_HZ: u32 = 100;

/// Seconds between two diagnostics lines in the log.
const DIAGNOSTICS_EVERY_S: u32 = 10;

/// Interrupt priorities (4 bits on the STM32G4; lower is more urgent). The index capture comes
/// first so that its timestamp is queued before the DMA block that follows it; every handler
/// also collects it itself before feeding, so the order is kept whatever the priorities.
const INDEX_PRIORITY: Priority = Priority::P1;
const FEED_PRIORITY: Priority = Priority::P2;

/// The monitor lives in a static, built by the compiler as `DeltaMonitor::unconfigured()` and
/// configured in place at start-up (`config::CONFIG`, applied): it never passes through the
/// stack.
static MONITOR: ConstStaticCell<Monitor> = ConstStaticCell::new(Monitor::unconfigured());

/// The feeder, shared by the three interrupt handlers.
static FEEDER: Mutex<RefCell<Option<Feeder>>> = Mutex::new(RefCell::new(None));

#[entry]
fn main() -> ! {
    let p = embassy_stm32::init(board::clocks());
    let board = board::take(p);
    let clocks = embassy_stm32::rcc::clocks(&board.rcc);
    let Some(hclk) = clocks.hclk1.to_hertz() else {
        defmt::panic!("HCLK is not running");
    };

    let capture = capture::Capture::configure(board.tim2, board.dma, board.encoder_a, board.index);
    let counter_hz = capture.counter_hz();
    defmt::info!(
        "drive-monitor on STM32G4: HCLK {=u32} Hz; TIM2 counts at {=u32} Hz, {=u8}-bit; {=u16}-line disc, index {=bool}, {=u8} edges per capture; DMA ring of {=usize} captures",
        hclk.0,
        counter_hz,
        config::COUNTER_BITS,
        config::LINES,
        config::USE_INDEX,
        config::EDGES_PER_CAPTURE,
        ring::RING
    );

    let Some(monitor) = MONITOR.try_take() else {
        defmt::panic!("monitor already taken");
    };
    // The configuration was validated by the compiler for this clock: check it is the real one.
    if counter_hz != config::TIMER_HZ {
        defmt::panic!(
            "TIM2 counts at {=u32} Hz, the configuration was built for {=u32} Hz (config::TIMER_HZ)",
            counter_hz,
            config::TIMER_HZ
        );
    }
    if let Err(e) = monitor.apply(&config::CONFIG) {
        defmt::panic!("configuration rejected: {}", e);
    }
    defmt::info!(
        "monitor: {=usize} bytes in a static, {=u16} captures per revolution, {} framing, δ windows of {=u16} rev",
        core::mem::size_of::<Monitor>(),
        monitor.encoder().edges(),
        monitor.encoder().framing(),
        monitor.window_revolutions()
    );
    let alarm = AlarmOutput::new(board.alarm, true);
    critical_section::with(|cs| {
        FEEDER
            .borrow_ref_mut(cs)
            .replace(Feeder::new(monitor, alarm, counter_hz));
    });

    // The DMA interrupt was enabled by `embassy_stm32::init`; TIM2's is enabled here.
    interrupt::DMA1_CHANNEL1.set_priority(FEED_PRIORITY);
    interrupt::TIM2.set_priority(INDEX_PRIORITY);
    interrupt::TIM2.unpend();
    // SAFETY: the handler below only touches state behind the critical section.
    unsafe { interrupt::TIM2.enable() };

    // The feeder is in place: captures may start.
    capture.start();

    let Some(mut core) = cortex_m::Peripherals::take() else {
        defmt::panic!("core peripherals already taken");
    };
    // SAFETY: SysTick's handler shares state with the others only inside critical sections.
    unsafe {
        core.SCB
            .set_priority(SystemHandler::SysTick, u8::from(FEED_PRIORITY))
    };
    core.SYST.set_clock_source(SystClkSource::Core);
    core.SYST.set_reload(hclk.0 / POLL_HZ - 1);
    core.SYST.clear_current();
    core.SYST.enable_interrupt();
    core.SYST.enable_counter();

    // Everything else happens in the interrupt handlers; `capture` keeps TIM2 clocked.
    let _capture = capture;
    loop {
        cortex_m::asm::wfi();
    }
}

/// The feeder, in a critical section: `None` until `main` has built it. Every handler borrows
/// it only inside its own critical section, so it is never already borrowed; `try_borrow_mut`
/// says so without a panic branch on the interrupt path.
fn feeder(cs: critical_section::CriticalSection<'_>) -> Option<core::cell::RefMut<'_, Feeder>> {
    let cell = FEEDER.borrow(cs).try_borrow_mut().ok()?;
    core::cell::RefMut::filter_map(cell, Option::as_mut).ok()
}

/// DMA1 channel 1: half transfer or transfer complete, a block of captures to feed.
#[interrupt]
fn DMA1_CHANNEL1() {
    critical_section::with(|cs| {
        let events = capture::take_dma_events();
        if let Some(mut feeder) = feeder(cs) {
            feeder.on_dma(events);
        }
    });
}

/// TIM2: the index capture (CC2), queued for the edge that follows it.
#[interrupt]
fn TIM2() {
    critical_section::with(|cs| {
        let events = capture::take_timer_events();
        if let Some(mut feeder) = feeder(cs) {
            feeder.on_timer_events(events);
        }
    });
}

/// SysTick, [`POLL_HZ`] times a second: feeds the captures waiting in the current half, checks
/// for standstill, and now and then logs the counters.
#[exception]
fn SysTick() {
    static mut TICKS: u32 = 0;
    *TICKS = TICKS.wrapping_add(1);
    let log = *TICKS % (POLL_HZ * DIAGNOSTICS_EVERY_S) == 0;
    critical_section::with(|cs| {
        if let Some(mut feeder) = feeder(cs) {
            feeder.on_poll();
            if log {
                let monitor = feeder.monitor();
                defmt::info!(
                    "shaft {} ({}) at {=f32} rad/s, alarm {=bool} | {} | {}",
                    monitor.shaft_state(),
                    monitor.sync_state(),
                    monitor.speed(),
                    monitor.alarm_active(),
                    monitor.diagnostics(),
                    feeder.stats()
                );
            }
        }
    });
}
