//! Encoder timestamps by hardware: TIM2 input capture, copied by DMA into a circular buffer.
//!
//! Channel A's rising edge latches TIM2's free-running 32-bit counter into TIM2_CCR1; the
//! capture raises TIM2's CC1 DMA request, which DMAMUX1 channel 0 routes to DMA1 channel 1;
//! the DMA copies CCR1 into the next slot of a ring of [`RING`] and wraps (circular mode). Its
//! half-transfer and transfer-complete interrupts say that one half of the ring has just
//! filled; `main`'s DMA1_CHANNEL1 handler hands that half to the monitor. The index pulse is
//! captured on channel 2 (TIM2_CCR2) with an interrupt: once per revolution, no DMA needed.
//!
//! Register programming follows RM0440 (STM32G4 reference manual); the comments cite its
//! chapters by title, since section numbers move between revisions:
//! - "General-purpose timers (TIM2/TIM3/TIM4/TIM5)": time-base unit, input capture mode,
//!   input filter, TIMx_CCMR1 (input capture mode), TIMx_CCER, TIMx_DIER, TIMx_SR, TIMx_TISEL;
//! - "Direct memory access controller (DMA)": channel configuration procedure, circular mode,
//!   DMA_CCRx, DMA_CNDTRx, DMA_ISR/DMA_IFCR;
//! - "DMA request multiplexer (DMAMUX)": DMAMUX mapping (multiplexer channel x drives DMA1
//!   channel x + 1; request inputs, tim2_ch1 = 56), DMAMUX_CxCR.
//!
//! Register and field names are those of the PAC (`stm32-metapac`, re-exported by
//! embassy-stm32 as `pac`), generated from ST's register descriptions.

use core::cell::UnsafeCell;
use core::sync::atomic::{fence, Ordering};

use embassy_stm32::pac;
use embassy_stm32::pac::bdma::vals::{Dir, Pl, Size};
use embassy_stm32::pac::timer::regs::SrGp16;
use embassy_stm32::pac::timer::vals::{CcmrInputCcs, FilterValue};
use embassy_stm32::peripherals::{DMA1_CH1, TIM2};
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::low_level::Timer;
use embassy_stm32::timer::{Ch1, Ch2};
use embassy_stm32::Peri;

use crate::config::{EDGES_PER_CAPTURE, USE_INDEX};
use crate::ring::{HALF, RING};

/// TIM2's capture/compare channel index (0-based) of encoder A and of the index pulse.
const CH_A: usize = 0;
const CH_INDEX: usize = 1;

/// DMA1 channel 1 is index 0 in the PAC, and is driven by DMAMUX1 channel 0 (RM0440, DMAMUX
/// mapping: DMAMUX1 channels 0.. are connected to DMA1 channels 1..).
const DMA_CH: usize = 0;
const DMAMUX_CH: usize = 0;

/// Input filter on both capture inputs: sampled at f_CK_INT (170 MHz), an edge is accepted
/// after 8 consecutive equal samples (RM0440, TIMx_CCMR1 input capture mode, IC1F = 0011).
/// This rejects pulses shorter than 8 ticks (47 ns at 170 MHz), such as ringing coupled from
/// the motor's PWM switching, while the capture stays on the tick grid: a filter sampled at
/// f_DTS/N would quantize the capture instant to N ticks and multiply δ's noise floor by N.
/// The filter delays every capture by the same 8 ticks, which cancels in intervals.
const INPUT_FILTER: FilterValue = FilterValue::FCK_INT_N8;

/// ICxPSC field for [`EDGES_PER_CAPTURE`] (RM0440, TIMx_CCMR1: 00 every edge, 01 every 2,
/// 10 every 4, 11 every 8 events).
const ICPSC: u8 = match EDGES_PER_CAPTURE {
    1 => 0b00,
    2 => 0b01,
    4 => 0b10,
    8 => 0b11,
    _ => panic!("EDGES_PER_CAPTURE must be 1, 2, 4 or 8"),
};

/// The ring the DMA writes, in `.bss` (SRAM, reachable by DMA1).
pub struct DmaRing(UnsafeCell<[u32; RING]>);

// SAFETY: the CPU only reads the ring, slot by slot with volatile loads (`copy_block`), from
// the interrupt handlers that run one at a time inside a critical section; the only writer is
// the DMA controller.
unsafe impl Sync for DmaRing {}

/// The capture ring.
pub static CAPTURES: DmaRing = DmaRing(UnsafeCell::new([0; RING]));

impl DmaRing {
    fn address(&self) -> u32 {
        self.0.get() as u32
    }

    /// Copies slots `start..end` into the front of `out` and returns that part of `out`.
    ///
    /// Volatile loads: the slots were written by the DMA, outside the program's view. The
    /// caller passes only slots the DMA has already written in the current lap (behind its
    /// write position), so the copy is the captures in order; if the handler ran so late that
    /// the DMA came round again (an overrun, counted by the caller), a slot may hold a newer
    /// capture, which the monitor sees as a missing or extra edge.
    pub fn copy_block<'a>(&self, start: usize, end: usize, out: &'a mut [u32; HALF]) -> &'a [u32] {
        let end = end.min(RING);
        let n = end.saturating_sub(start).min(HALF);
        let base = self.0.get().cast::<u32>();
        for (k, slot) in out.iter_mut().take(n).enumerate() {
            // SAFETY: `start + k < end <= RING`: inside the array; u32 slots are aligned.
            *slot = unsafe { base.add(start + k).read_volatile() };
        }
        &out[..n]
    }
}

/// DMA1 channel 1's flags, read and cleared by its interrupt handler.
#[derive(Clone, Copy, Debug, defmt::Format)]
pub struct DmaEvents {
    /// Half transfer: slots `0..HALF` have just filled.
    pub half: bool,
    /// Transfer complete: slots `HALF..RING` have just filled (the DMA wrapped to slot 0).
    pub complete: bool,
    /// Transfer error (bus error; the DMA disables the channel).
    pub error: bool,
}

/// Reads DMA1 channel 1's half-transfer, transfer-complete and transfer-error flags and
/// clears those that were set (RM0440, DMA_ISR and DMA_IFCR: write 1 to clear). CGIF is left
/// alone: it would also clear a flag raised between the read and the write.
pub fn take_dma_events() -> DmaEvents {
    let isr = pac::DMA1.isr().read();
    let events = DmaEvents {
        half: isr.htif(DMA_CH),
        complete: isr.tcif(DMA_CH),
        error: isr.teif(DMA_CH),
    };
    pac::DMA1.ifcr().write(|w| {
        w.set_htif(DMA_CH, events.half);
        w.set_tcif(DMA_CH, events.complete);
        w.set_teif(DMA_CH, events.error);
    });
    // Reads of the ring that follow must see what the DMA wrote before raising the flag.
    fence(Ordering::Acquire);
    events
}

/// Whether a half-transfer or transfer-complete flag is set: DMA1_CHANNEL1's handler has a
/// block to take.
pub fn dma_block_pending() -> bool {
    let isr = pac::DMA1.isr().read();
    isr.htif(DMA_CH) || isr.tcif(DMA_CH)
}

/// The slot the DMA writes next, `0..RING`: DMA_CNDTR counts the transfers left in the lap
/// and reloads to RING on wrapping in circular mode (RM0440, DMA circular mode).
pub fn write_position() -> usize {
    let left = usize::from(pac::DMA1.ch(DMA_CH).ndtr().read().ndt());
    let position = RING.saturating_sub(left);
    fence(Ordering::Acquire);
    position
}

/// TIM2's counter now.
pub fn now() -> u32 {
    pac::TIM2.cnt().read()
}

/// Flags of TIM2 read by the handlers.
#[derive(Clone, Copy, Debug, Default, defmt::Format)]
pub struct TimerEvents {
    /// An index timestamp, if one was captured since the last call.
    pub index: Option<u32>,
    /// An index capture was lost: a second index pulse came before the first was read.
    pub index_overcapture: bool,
    /// An encoder capture was lost: a second edge came before the DMA read CCR1.
    pub capture_overcapture: bool,
}

/// Takes TIM2's index capture, if any, and its overcapture flags.
///
/// Reading TIMx_CCR2 clears CC2IF (RM0440, TIMx_SR: CCxIF is cleared by reading TIMx_CCRx in
/// input capture mode). The overcapture flags are cleared by writing 0 to them and 1 to every
/// other bit, so no flag set meanwhile is lost (TIMx_SR bits are rc_w0: writing 1 has no
/// effect).
pub fn take_timer_events() -> TimerEvents {
    let tim = pac::TIM2;
    let sr = tim.sr().read();
    let mut events = TimerEvents {
        index: None,
        index_overcapture: sr.ccof(CH_INDEX),
        capture_overcapture: sr.ccof(CH_A),
    };
    if sr.ccif(CH_INDEX) {
        events.index = Some(tim.ccr(CH_INDEX).read());
    }
    if events.index_overcapture || events.capture_overcapture {
        let mut clear = SrGp16(u32::MAX);
        clear.set_ccof(CH_INDEX, !events.index_overcapture);
        clear.set_ccof(CH_A, !events.capture_overcapture);
        tim.sr().write_value(clear);
    }
    events
}

/// The running capture hardware. Dropping it would switch TIM2's clock off and the pins back
/// to analog, so `main` keeps it for ever.
pub struct Capture {
    timer: Timer<'static, TIM2>,
    _dma: Peri<'static, DMA1_CH1>,
    _pins: (
        CapturePin<'static, TIM2, Ch1>,
        CapturePin<'static, TIM2, Ch2>,
    ),
    counter_hz: u32,
}

impl Capture {
    /// Programs TIM2, DMAMUX1 and DMA1 channel 1 for capturing encoder A (and the index if
    /// `config::USE_INDEX`) on the pins `board::take` switched to TIM2's channels; nothing is
    /// captured before [`Capture::start`]. The DMA1/DMAMUX1 clocks are enabled by
    /// `embassy_stm32::init`.
    pub fn configure(
        tim2: Peri<'static, TIM2>,
        dma: Peri<'static, DMA1_CH1>,
        encoder_a: CapturePin<'static, TIM2, Ch1>,
        index: CapturePin<'static, TIM2, Ch2>,
    ) -> Capture {
        // Enables and resets TIM2 (RCC_APB1ENR1.TIM2EN, RCC_APB1RSTR1.TIM2RST): every TIM2
        // register starts from its reset value, the counter stopped.
        let timer = Timer::new(tim2);
        let tim = timer.regs_gp32();

        // Time base (RM0440, time-base unit): counting up (CR1.DIR = 0, CMS = 00 at reset),
        // PSC = 0 so the counter advances once per kernel clock tick, ARR at its maximum so the
        // counter wraps modulo 2^32, as the monitor's `counter_bits = 32` assumes. PSC is
        // preloaded: the update event generated here loads it (URS set so it raises no flag).
        tim.psc().write_value(0);
        tim.arr().write_value(u32::MAX);
        timer.generate_update_event();

        // Inputs: TIMx_TISEL = 0 selects the TIM2_CH1/TIM2_CH2 pins as TI1/TI2 (reset value,
        // written for clarity).
        tim.tisel().write_value(Default::default());

        // Input capture mode (RM0440, input capture mode; TIMx_CCMR1 input capture mode):
        // CCxS = 01 maps ICx on TIx; ICxF the filter above; ICxPSC the prescaler. CCxS is
        // writable only while CCxE = 0, as it is after the reset.
        tim.ccmr_input(0).modify(|w| {
            w.set_ccs(CH_A, CcmrInputCcs::TI4); // 01: "normal mapping, ICx mapped on TIx"
            w.set_icf(CH_A, INPUT_FILTER);
            w.set_icpsc(CH_A, ICPSC);
            if USE_INDEX {
                w.set_ccs(CH_INDEX, CcmrInputCcs::TI4);
                w.set_icf(CH_INDEX, INPUT_FILTER);
                w.set_icpsc(CH_INDEX, 0b00);
            }
        });

        // Polarity and enable (TIMx_CCER): CCxNP:CCxP = 00 captures rising edges only (one
        // capture per line: both edges would make every other interval depend on the duty
        // cycle), CCxE = 1 enables the capture.
        tim.ccer().modify(|w| {
            w.set_ccnp(CH_A, false);
            w.set_ccp(CH_A, false);
            w.set_cce(CH_A, true);
            if USE_INDEX {
                w.set_ccnp(CH_INDEX, false);
                w.set_ccp(CH_INDEX, false);
                w.set_cce(CH_INDEX, true);
            }
        });

        // DMA request routing (RM0440, DMAMUX): multiplexer channel 0 (→ DMA1 channel 1)
        // takes TIM2's CC1 request, no synchronization or event generation. The request number
        // comes from embassy-stm32's chip data (the `timer::Dma<TIM2, Ch1>` impl of DMA1_CH1):
        // 56, tim2_ch1 in RM0440's DMAMUX request table.
        let request = <DMA1_CH1 as embassy_stm32::timer::Dma<TIM2, Ch1>>::request(&dma);
        pac::DMAMUX1
            .ccr(DMAMUX_CH)
            .write(|w| w.set_dmareq_id(request));

        // DMA channel (RM0440, DMA channel configuration procedure): with the channel
        // disabled, peripheral address = TIM2_CCR1, memory address = the ring, count = RING,
        // then DMA_CCR: peripheral-to-memory, 32-bit on both sides, memory increment,
        // circular, priority very high, interrupts on half transfer, transfer complete and
        // transfer error. `start` sets EN.
        let ch = pac::DMA1.ch(DMA_CH);
        ch.cr().write(|w| w.set_en(false));
        ch.par().write_value(tim.ccr(CH_A).as_ptr() as u32);
        ch.mar().write_value(CAPTURES.address());
        ch.ndtr().write(|w| w.set_ndt(RING as u16));
        ch.cr().write(|w| {
            w.set_dir(Dir::FROM_PERIPHERAL);
            w.set_psize(Size::BITS32);
            w.set_msize(Size::BITS32);
            w.set_pinc(false);
            w.set_minc(true);
            w.set_circ(true);
            w.set_pl(Pl::VERY_HIGH);
            w.set_htie(true);
            w.set_tcie(true);
            w.set_teie(true);
        });

        let counter_hz = timer.get_clock_frequency().0 / (u32::from(tim.psc().read()) + 1);
        Capture {
            timer,
            _dma: dma,
            _pins: (encoder_a, index),
            counter_hz,
        }
    }

    /// Starts capturing: the DMA channel on, then (TIMx_DIER) CC1DE = 1, a DMA request on each
    /// channel-A capture, and CC2IE = 1, an interrupt on each index capture; then the counter.
    pub fn start(&self) {
        pac::DMA1.ch(DMA_CH).cr().modify(|w| w.set_en(true));
        let tim = self.timer.regs_gp32();
        tim.dier().modify(|w| {
            w.set_ccde(CH_A, true);
            if USE_INDEX {
                w.set_ccie(CH_INDEX, true);
            }
        });
        self.timer.start();
    }

    /// TIM2's counting rate, Hz: its kernel clock from the RCC setup (read back from
    /// embassy-stm32's clock tree) divided by PSC + 1.
    pub fn counter_hz(&self) -> u32 {
        self.counter_hz
    }
}
