//! What accuracy costs: δ measured by the core's [`DeltaMonitor`] from an analytic pulse
//! train, as a function of encoder lines, capture-timer frequency and the `K`-edge estimator.
//!
//! The shaft runs the kneader-like ripple ω(φ) = ω̄·(1 + ε·sin(φ/8)): one load cycle per 8
//! revolutions and δ = 2(ωmax − ωmin)/(ωmax + ωmin) = 2ε exactly. Edge times are integrated in
//! f64 (midpoint rule per pitch, far below one tick) and quantized to the timer like a capture
//! unit would, then fed through the same core code that runs on the target, with an index
//! pulse before tooth 0 and 8-revolution windows.
//!
//! Each row states, relative to the exact δ:
//! - `error`: the worst |δ_measured − δ|/δ over the valid windows;
//! - `noise_floor`: the floor the monitor itself reports (1/t_fast + 1/t_slow, the ticks of the
//!   window's two extreme speed samples);
//! - `quantization_floor`: the physical limit from the timer alone, 2/N with N = K·(2π/lines)/ω̄
//!   ticks per speed sample at the mean speed (one tick on each of the two extreme samples);
//! - `averaging_bias`: the ripple a K-edge sample averages away, (K·p·n)²/24 for pitch
//!   p = 2π/lines and load order n = 1/8 (the estimator's stated attenuation).
//!
//! The measured error stays within the quantization floor plus the averaging bias; more timer
//! clock shrinks the first, fewer averaged edges (or more lines) the second.

use drive_monitor::alarm::AlarmConfig;
use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator};
use drive_monitor::irregularity::{WindowConfig, WindowLength};
use drive_monitor::monitor::DeltaMonitor;
use drive_monitor::speed::Direction;
use drive_monitor::ConfigError;
use rayon::prelude::*;
use std::f64::consts::TAU;
use std::fmt::Write as _;

/// Largest disc the table handles, lines per revolution.
pub const MAX_LINES: usize = 4096;

/// Load order of the kneader ripple (one cycle per 8 revolutions).
const ORDER: f64 = 1.0 / 8.0;

/// Revolutions per δ window: one load cycle.
const WINDOW_REVS: u16 = 8;

/// The sweep: the shaft, and the grid of encoder lines × timer frequencies × estimators.
#[derive(Debug, Clone, PartialEq)]
pub struct AccuracySweep {
    /// Mean speed ω̄, rad/s.
    pub omega_mean: f64,
    /// Ripple amplitude ε (δ = 2ε).
    pub epsilon: f64,
    /// Encoder lines per revolution (each 2 to [`MAX_LINES`]).
    pub lines: Vec<u16>,
    /// Capture-timer frequencies, Hz.
    pub timer_hz: Vec<f64>,
    /// Edges averaged per speed sample.
    pub k: Vec<u16>,
    /// Valid δ windows measured per case (each after one revolution to frame the disc).
    pub windows: u16,
}

impl Default for AccuracySweep {
    /// The kneader scene: ω̄ = 134 rad/s, ε = 0.0153 (δ = 0.0306); 64 to 4096 lines; 1, 10, 84
    /// and 170 MHz timers; K = 1, 4, 16; three windows per case.
    fn default() -> Self {
        AccuracySweep {
            omega_mean: 134.0,
            epsilon: 0.0153,
            lines: vec![64, 256, 1024, 4096],
            timer_hz: vec![1e6, 10e6, 84e6, 170e6],
            k: vec![1, 4, 16],
            windows: 3,
        }
    }
}

/// One case of the sweep: what the monitor measured and the floors it is judged against
/// (all relative to the exact δ).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AccuracyRow {
    /// Encoder lines per revolution.
    pub lines: u16,
    /// Capture-timer frequency, Hz.
    pub timer_hz: f64,
    /// Edges averaged per speed sample.
    pub k: u16,
    /// The exact δ, 2ε.
    pub delta_exact: f64,
    /// Mean δ over the valid windows.
    pub delta_mean: f64,
    /// Worst |δ − δ_exact|/δ_exact over the valid windows.
    pub error: f64,
    /// The noise floor the monitor reports, mean over the windows, relative to δ_exact.
    pub noise_floor: f64,
    /// 2/N relative to δ_exact, N the ticks per speed sample at the mean speed.
    pub quantization_floor: f64,
    /// Ripple attenuation of the K-edge average, (K·p·n)²/24.
    pub averaging_bias: f64,
    /// Valid windows measured.
    pub windows: u32,
}

/// Capture timestamps (raw 32-bit counter values) of `revs` revolutions of a `lines`-line
/// disc on the shaft ω(φ) = ω̄(1 + ε sin(φ/8)); edge i is at angle (i + 1)·2π/lines.
pub fn pulse_train(
    omega_mean: f64,
    epsilon: f64,
    lines: u16,
    timer_hz: f64,
    revs: u32,
) -> Vec<u32> {
    let pitch = TAU / f64::from(lines);
    let n = usize::from(lines) * revs as usize;
    let mut t = 0.0f64;
    (0..n)
        .map(|i| {
            let mid = (i as f64 + 0.5) * pitch;
            t += pitch / (omega_mean * (1.0 + epsilon * (ORDER * mid).sin()));
            (t * timer_hz) as u64 as u32
        })
        .collect()
}

/// Measures one case.
pub fn measure_case(
    omega_mean: f64,
    epsilon: f64,
    lines: u16,
    timer_hz: f64,
    k: u16,
    windows: u16,
) -> Result<AccuracyRow, ConfigError> {
    if usize::from(lines) > MAX_LINES {
        return Err(ConfigError::Capacity("lines"));
    }
    let mut c = EncoderConfig::indexed(lines, timer_hz);
    c.estimator = Estimator::Edges(k);
    c.min_speed = omega_mean / 10.0;
    let encoder = Encoder::new(c)?;
    let window = WindowConfig {
        length: WindowLength::Revolutions(WINDOW_REVS),
        steady_tolerance: 0.02,
    };
    let mut monitor = Box::new(DeltaMonitor::<MAX_LINES>::new(
        encoder,
        window,
        Some(AlarmConfig::new((4.0 * epsilon) as f32)),
    )?);
    let revs = u32::from(WINDOW_REVS) * u32::from(windows) + 2;
    let ticks = pulse_train(omega_mean, epsilon, lines, timer_hz, revs);
    let delta = 2.0 * epsilon;
    let (mut n, mut sum, mut worst, mut floor) = (0u32, 0.0, 0.0f64, 0.0);
    for (i, &t) in ticks.iter().enumerate() {
        if i % usize::from(lines) == 0 {
            // The index pulse one tick before the edge that follows it.
            monitor.on_index(t.wrapping_sub(1));
        }
        if let Some(o) = monitor.on_edge(t, Some(Direction::Forward)) {
            if let Some(r) = o.report.measurement() {
                n += 1;
                sum += f64::from(r.delta);
                worst = worst.max((f64::from(r.delta) / delta - 1.0).abs());
                floor += f64::from(r.noise_floor);
            }
        }
    }
    let pitch = TAU / f64::from(lines);
    let ticks_per_sample = f64::from(k) * pitch / omega_mean * timer_hz;
    let n_f = f64::from(n.max(1));
    Ok(AccuracyRow {
        lines,
        timer_hz,
        k,
        delta_exact: delta,
        delta_mean: sum / n_f,
        error: if n > 0 { worst } else { f64::INFINITY },
        noise_floor: floor / n_f / delta,
        quantization_floor: 2.0 / ticks_per_sample / delta,
        averaging_bias: (f64::from(k) * pitch * ORDER).powi(2) / 24.0,
        windows: n,
    })
}

/// Measures every case of the sweep (in parallel), ordered by lines, then timer, then K.
/// Cases the encoder rejects (e.g. K above the lines) are skipped.
pub fn accuracy_table(sweep: &AccuracySweep) -> Vec<AccuracyRow> {
    let mut cases = Vec::new();
    for &lines in &sweep.lines {
        for &hz in &sweep.timer_hz {
            for &k in &sweep.k {
                cases.push((lines, hz, k));
            }
        }
    }
    cases
        .par_iter()
        .filter_map(|&(lines, hz, k)| {
            measure_case(sweep.omega_mean, sweep.epsilon, lines, hz, k, sweep.windows).ok()
        })
        .collect()
}

/// The rows as a Markdown table (errors and floors in percent of δ).
pub fn markdown(rows: &[AccuracyRow]) -> String {
    let mut s = String::from(
        "| lines | timer | K | δ measured | error | reported floor | quantization floor | averaging bias | windows |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let pct = |x: f64| format!("{:.3} %", 100.0 * x);
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} MHz | {} | {:.6} | {} | {} | {} | {} | {} |",
            r.lines,
            r.timer_hz / 1e6,
            r.k,
            r.delta_mean,
            pct(r.error),
            pct(r.noise_floor),
            pct(r.quantization_floor),
            pct(r.averaging_bias),
            r.windows
        );
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Allowance beyond the two floors: missing the crest between two samples (at most half a
    /// pitch from it: (p·n/2)²/2 ≈ 2e-5 of the ripple for 64 lines) and the edge integration.
    const MARGIN: f64 = 1e-4;

    #[test]
    fn error_stays_within_the_floors_and_falls_with_the_timer_clock() {
        let sweep = AccuracySweep::default();
        let rows = accuracy_table(&sweep);
        assert_eq!(rows.len(), 4 * 4 * 3);
        for r in &rows {
            assert_eq!(r.windows, 3, "{r:?}");
            assert!(
                r.error <= r.quantization_floor + r.averaging_bias + MARGIN,
                "{r:?}"
            );
            // The floor the monitor reports is the analytic one: the extreme samples' ticks
            // give 2/N at the mean of their speeds, within ε²/2 of the mean speed, each
            // latched to a tick (relative 1/N, N ticks a sample; 2/N is
            // `quantization_floor`·δ).
            let ticks = r.quantization_floor * r.delta_exact;
            assert!(
                (r.noise_floor / r.quantization_floor - 1.0).abs() < 1e-3 + ticks,
                "{r:?}"
            );
        }
        for &lines in &sweep.lines {
            for &k in &sweep.k {
                let case: Vec<&AccuracyRow> = rows
                    .iter()
                    .filter(|r| r.lines == lines && r.k == k)
                    .collect();
                let (slow, fast) = (case[0], case[case.len() - 1]);
                assert!(slow.timer_hz < fast.timer_hz);
                assert!(fast.quantization_floor < slow.quantization_floor / 100.0);
                // Where the timer dominates at the slowest clock, 170× the clock buys at least
                // a tenfold smaller error.
                if slow.quantization_floor > 10.0 * slow.averaging_bias {
                    assert!(fast.error < slow.error / 10.0, "{slow:?}\n{fast:?}");
                }
            }
        }
    }

    #[test]
    fn averaging_many_edges_of_a_coarse_disc_shows_its_bias() {
        // 16 edges of a 64-line disc span 1/4 turn: the sample averages the ripple down by
        // (K·p·n)²/24 ≈ 0.16 %, far above the 170 MHz quantization floor.
        let r = measure_case(134.0, 0.0153, 64, 170e6, 16, 3).unwrap();
        assert!(r.averaging_bias > 20.0 * r.quantization_floor, "{r:?}");
        let signed = r.delta_mean / r.delta_exact - 1.0;
        assert!(
            (signed + r.averaging_bias).abs() <= r.quantization_floor + MARGIN,
            "{r:?}"
        );
        // Without averaging the same disc and clock is unbiased.
        let r1 = measure_case(134.0, 0.0153, 64, 170e6, 1, 3).unwrap();
        assert!(r1.error <= r1.quantization_floor + MARGIN, "{r1:?}");
        assert!(r1.error < r.error / 4.0, "{r1:?}\n{r:?}");
    }

    #[test]
    fn rejected_cases_are_skipped_and_the_table_renders_every_row() {
        let sweep = AccuracySweep {
            lines: vec![8, 64],
            timer_hz: vec![84e6],
            k: vec![16],
            windows: 1,
            ..AccuracySweep::default()
        };
        // K = 16 exceeds an 8-line disc: only the 64-line case remains.
        let rows = accuracy_table(&sweep);
        assert_eq!(rows.len(), 1);
        assert_eq!(rows[0].lines, 64);
        assert!(measure_case(134.0, 0.0153, 8, 84e6, 16, 1).is_err());
        assert!(measure_case(134.0, 0.0153, 8192, 84e6, 1, 1).is_err());
        let table = markdown(&rows);
        assert_eq!(table.lines().count(), 3);
        assert!(table
            .lines()
            .nth(2)
            .unwrap()
            .starts_with("| 64 | 84 MHz | 16 |"));
    }
}
