//! What differs between the two boards: the pins. Everything else (clock tree, TIM2, DMA1,
//! DMAMUX1) is the same on the STM32G474 and the STM32G431, both described by RM0440.
//!
//! The chip is chosen by the `--cfg chip="..."` line in `.cargo/config.toml`.
//!
//! | signal               | NUCLEO-G474RE (`g474`)   | B-G431B-ESC1 (`g431`)                  |
//! |----------------------|--------------------------|----------------------------------------|
//! | encoder A → TIM2_CH1 | PA0 (AF1), Arduino A0    | PA15 (AF1), the kit's PWM input pad    |
//! | index Z → TIM2_CH2   | PA1 (AF1), Arduino A1    | PB3 (AF1), the J3 pad of USART2 TX     |
//! | δ alarm output       | PA5, green user LED LD2  | PC6, green user LED LD2                |
//!
//! On the B-G431B-ESC1 the encoder connector (A+/B+/Z+ on PB6/PB7/PB8) is wired to TIM4, a
//! 16-bit timer; this example wants TIM2's 32-bit counter, so A comes in on PA15 instead. PB3
//! is also the ST-LINK virtual COM port's line; this firmware uses no UART.
//! The pin-to-alternate-function pairs are checked at compile time: `CapturePin::new` only
//! accepts a pin that embassy-stm32's chip data lists as a TIM2 channel of that chip.

use embassy_stm32::gpio::{Level, Output, Pull, Speed};
use embassy_stm32::peripherals::{DMA1_CH1, RCC, TIM2};
use embassy_stm32::timer::input_capture::CapturePin;
use embassy_stm32::timer::{Ch1, Ch2};
use embassy_stm32::{Peri, Peripherals};

#[cfg(not(any(chip = "g474", chip = "g431")))]
compile_error!(
    "no chip selected: build from examples/stm32g4, whose .cargo/config.toml sets \
     `--cfg chip=\"g474\"` (or \"g431\"); a RUSTFLAGS variable replaces that line"
);

/// The peripherals this firmware uses, with the pins already switched to their function.
pub struct Board {
    /// Reset and clock control, to read the clock tree back.
    pub rcc: Peri<'static, RCC>,
    /// The capture timer (32-bit on the STM32G4).
    pub tim2: Peri<'static, TIM2>,
    /// The DMA channel that copies TIM2_CCR1 into the ring (DMAMUX1 channel 0).
    pub dma: Peri<'static, DMA1_CH1>,
    /// Encoder channel A, captured on its rising edges.
    pub encoder_a: CapturePin<'static, TIM2, Ch1>,
    /// Index (Z) pulse, captured on its rising edge.
    pub index: CapturePin<'static, TIM2, Ch2>,
    /// The δ alarm output, low at reset (alarm off).
    pub alarm: Output<'static>,
}

/// Encoder inputs: a push-pull encoder output (or line receiver) at 3.3 V logic drives them,
/// so no pull resistor is enabled.
const INPUT_PULL: Pull = Pull::None;

/// Takes the pins of the NUCLEO-G474RE.
#[cfg(chip = "g474")]
pub fn take(p: Peripherals) -> Board {
    Board {
        rcc: p.RCC,
        tim2: p.TIM2,
        dma: p.DMA1_CH1,
        encoder_a: CapturePin::new(p.PA0, INPUT_PULL),
        index: CapturePin::new(p.PA1, INPUT_PULL),
        alarm: Output::new(p.PA5, Level::Low, Speed::Low),
    }
}

/// Takes the pins of the B-G431B-ESC1.
#[cfg(chip = "g431")]
pub fn take(p: Peripherals) -> Board {
    Board {
        rcc: p.RCC,
        tim2: p.TIM2,
        dma: p.DMA1_CH1,
        encoder_a: CapturePin::new(p.PA15, INPUT_PULL),
        index: CapturePin::new(p.PB3, INPUT_PULL),
        alarm: Output::new(p.PC6, Level::Low, Speed::Low),
    }
}

/// The clock tree: SYSCLK = HCLK = PCLK1 = PCLK2 = 170 MHz, the G4's maximum, from the internal
/// 16 MHz HSI (no dependence on a board crystal) through the PLL: 16 MHz / 4 = 4 MHz at the
/// PLL input, × 85 = 340 MHz VCO, / 2 (PLLR) = 170 MHz. Above 150 MHz the core regulator must
/// run in range 1 boost mode (RM0440, "Reset and clock control (RCC)" and "Power control
/// (PWR)": dynamic voltage scaling); embassy-stm32 also sets the flash wait states.
///
/// TIM2's kernel clock is PCLK1 when the APB1 prescaler is 1 (×2 otherwise; RM0440 RCC clock
/// tree, timer clock), so 170 MHz here. The firmware reads the real value back from
/// embassy-stm32 after this setup rather than assuming it (`capture::Capture::configure`
/// reads it, `main` compares it with `config::TIMER_HZ`).
///
/// HSI16 is trimmed to ±1 % over temperature, so absolute speeds carry up to 1 % error; δ is a
/// ratio of speeds measured with the same clock and does not.
pub fn clocks() -> embassy_stm32::Config {
    use embassy_stm32::rcc::{
        AHBPrescaler, APBPrescaler, Pll, PllMul, PllPreDiv, PllRDiv, PllSource, Sysclk,
    };
    let mut config = embassy_stm32::Config::default();
    config.rcc.hsi = true;
    config.rcc.pll = Some(Pll {
        source: PllSource::HSI,
        prediv: PllPreDiv::DIV4,
        mul: PllMul::MUL85,
        divp: None,
        divq: None,
        divr: Some(PllRDiv::DIV2),
    });
    config.rcc.sys = Sysclk::PLL1_R;
    config.rcc.ahb_pre = AHBPrescaler::DIV1;
    config.rcc.apb1_pre = APBPrescaler::DIV1;
    config.rcc.apb2_pre = APBPrescaler::DIV1;
    config.rcc.boost = true;
    config
}
