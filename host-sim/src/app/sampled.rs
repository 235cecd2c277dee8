//! The predicted δ as the core's speed samples read it. Each sample is the angle of
//! `encoder.estimator_edges` (K) captured edges over their time, the mean speed over that angle
//! (the angle over `∫dφ/ω`), and the samples start only at the teeth: what a window reads
//! depends on where the teeth stand against the load. With the teeth offset by θ from their
//! own angles (θ added to every tooth's angle, which is the same as shifting the load by −θ),
//! the samples start at θ plus each captured edge's angle, over every edge of the common period
//! of the load and the wheel's revolution, and δ(θ) = 2(max − min)/(max + min) of them.
//! [`delta_through_samples`] gives the least and most of δ(θ) over the offsets and δ(0), the
//! offset the simulator's wheel has (its tooth 0 at shaft angle 0, the load's φ = 0).
//!
//! How: ω of the predicted steady state on a grid over one load period (node and mid-cell,
//! at least 256 cells a cycle of the fastest load or inertia order and 512 a period, at most
//! [`MAX_SAMPLED_POINTS`] evaluations), the time `∫dφ/ω` by Simpson's rule on it and, inside a
//! cell, by the integral of the quadratic through its three values (so a sample can start
//! anywhere); δ(θ) on a grid of offsets over the smallest shift that maps the samples onto
//! themselves (the gcd of the load period and the wheel's symmetry: a uniform disc's captured
//! pitch, a pattern wheel's revolution, or less), then refined by golden section around the
//! least and the most of the grid on the samples that were extreme there, the result checked
//! against every sample.

use drive_monitor::drive::{DriveModel, Horizon};
use std::f64::consts::TAU;

/// Most evaluations of the steady ω the time table takes (two a cell).
pub const MAX_SAMPLED_POINTS: usize = 1 << 22;
/// Most sample evaluations one scan of the offsets takes (the offsets are fewer where the
/// samples are many: then the offset matters little).
pub const SCAN_BUDGET: usize = 1 << 18;
/// Most offsets on the scan's grid.
const MAX_OFFSETS: usize = 1024;
/// Most edges enumerated over the common period of the load and the revolution.
pub const MAX_EDGES: u64 = 1 << 22;

/// The edges the core captures in a revolution of its wheel, on the wheel's grid.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SampleWheel {
    /// Grid positions per revolution.
    pub positions: u32,
    /// Grid positions of the captured edges, ascending, each below `positions` (a uniform
    /// disc's lines, one in `prescaler`; a pattern wheel's teeth).
    pub teeth: Vec<u32>,
}

impl SampleWheel {
    /// A uniform disc of `lines` lines with one edge in `prescaler` captured, from line 0 (the
    /// simulator's: its shaft starts at angle 0, line 0 there, and the capture takes the
    /// `prescaler`-th edge first).
    pub fn uniform(lines: u32, prescaler: u32) -> Self {
        let p = prescaler.max(1);
        SampleWheel {
            positions: lines,
            teeth: (0..lines).step_by(p as usize).collect(),
        }
    }

    /// The smallest rotation, in grid positions, that maps the captured edges onto themselves.
    fn symmetry(&self) -> u32 {
        let n = self.positions;
        let set: std::collections::HashSet<u32> = self.teeth.iter().copied().collect();
        (1..=n)
            .filter(|s| n % s == 0)
            .find(|&s| self.teeth.iter().all(|t| set.contains(&((t + s) % n))))
            .unwrap_or(n)
    }
}

/// δ of the predicted steady state through the speed samples, over the teeth's offset against
/// the load.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledRange {
    /// The least δ the samples read, over the offset.
    pub least: f64,
    /// The offset it is read at, rad (within the range the offsets repeat over).
    pub least_offset: f64,
    /// The most δ the samples read, over the offset.
    pub most: f64,
    /// The offset it is read at, rad.
    pub most_offset: f64,
    /// δ at offset 0: the teeth at their own angles against the load's φ, as the simulator
    /// has them (what `run` measures).
    pub at_zero: f64,
    /// The offsets repeat over this many radians (the scan covers `[0, repeat)`).
    pub repeat: f64,
}

impl SampledRange {
    fn none() -> Self {
        SampledRange {
            least: 0.0,
            least_offset: 0.0,
            most: 0.0,
            most_offset: 0.0,
            at_zero: 0.0,
            repeat: 0.0,
        }
    }
}

/// The time over the predicted steady state's angle, `∫dφ/ω`, over one load period and
/// periodically beyond it.
#[derive(Debug, Clone)]
pub struct SteadyTime {
    /// The load period P, rad: `2π·revolutions/periods`.
    period: f64,
    /// Whole revolutions of the common period of the load and the revolution.
    revolutions: u64,
    /// Load periods in it.
    periods: u64,
    /// Cell width, rad.
    h: f64,
    /// 1/ω at the cells' ends and middles (2·cells + 1 values).
    f: Vec<f64>,
    /// The time at each cell's start (cells + 1 values), s.
    t: Vec<f64>,
    /// ω is constant: every sample reads it.
    constant: bool,
}

impl SteadyTime {
    /// The time table of `model`'s steady state. `None` without a steady state, for loads
    /// without a common period ([`Horizon::Unbounded`]) or when the grid would take more than
    /// [`MAX_SAMPLED_POINTS`] evaluations.
    pub fn new(model: &DriveModel) -> Option<Self> {
        model.predict().steady()?;
        let period = match model.horizon() {
            Horizon::Constant => {
                return Some(SteadyTime {
                    period: TAU,
                    revolutions: 1,
                    periods: 1,
                    h: TAU,
                    f: Vec::new(),
                    t: Vec::new(),
                    constant: true,
                })
            }
            Horizon::ClosedForm => {
                let order = model
                    .load()
                    .harmonics()
                    .iter()
                    .map(|h| h.order().abs())
                    .filter(|o| *o > 0.0)
                    .reduce(f64::min)?;
                TAU / order
            }
            Horizon::Period { radians, .. }
            | Horizon::Varying { radians, .. }
            | Horizon::Shooting { radians, .. } => radians,
            Horizon::Unbounded => return None,
        };
        let revolutions = model.period_revolutions()?;
        let fastest = model
            .load()
            .harmonics()
            .iter()
            .filter(|h| h.amplitude() != 0.0)
            .map(|h| h.order().abs())
            .chain(model.inertia_harmonics().iter().map(|h| h.order().abs()))
            .fold(0.0f64, f64::max);
        let curve = model.steady_curve();
        Self::tabulate(period, revolutions, fastest, |phi| curve.steady_omega(phi))
    }

    /// The time table of a steady state whose ω repeats over `period` rad (a whole number of
    /// times in `revolutions` whole revolutions, else over those), `fastest` the highest order
    /// of the load and the inertia (cycles per revolution), `omega(φ)` its speed, asked at
    /// ascending angles over one period, from 0 (a host integration's cursor steps on from
    /// the last). `None` when `omega` gives none or the grid would take more than
    /// [`MAX_SAMPLED_POINTS`] evaluations ([`Self::points`]).
    pub fn tabulate(
        period: f64,
        revolutions: u64,
        fastest: f64,
        mut omega: impl FnMut(f64) -> Option<f64>,
    ) -> Option<Self> {
        if !(period > 0.0 && period.is_finite() && revolutions >= 1) {
            return None;
        }
        // P = 2π·a/b; where the horizon's period does not divide the whole revolutions (an
        // order left out of one of them), the revolutions themselves are the period.
        let ratio = TAU * revolutions as f64 / period;
        let (period, periods) =
            if ratio.round() >= 1.0 && (ratio - ratio.round()).abs() <= 1e-9 * ratio {
                (period, ratio.round() as u64)
            } else {
                (TAU * revolutions as f64, 1)
            };
        let cells = Self::points(period, fastest)? / 2;
        let h = period / cells as f64;
        let mut f = Vec::with_capacity(2 * cells + 1);
        for j in 0..2 * cells {
            f.push(1.0 / omega(0.5 * h * j as f64)?);
        }
        f.push(f[0]);
        let mut t = Vec::with_capacity(cells + 1);
        t.push(0.0);
        for c in 0..cells {
            let step = h * (f[2 * c] + 4.0 * f[2 * c + 1] + f[2 * c + 2]) / 6.0;
            t.push(t[c] + step);
        }
        Some(SteadyTime {
            period,
            revolutions,
            periods,
            h,
            f,
            t,
            constant: false,
        })
    }

    /// The evaluations of ω the table of a steady state repeating over `period` rad with
    /// `fastest` its highest order takes (node and mid-cell, 256 cells a cycle of that order
    /// and 512 a period at least); `None` beyond [`MAX_SAMPLED_POINTS`].
    pub fn points(period: f64, fastest: f64) -> Option<usize> {
        let cycles = fastest * period / TAU;
        let cells = (256.0 * cycles).ceil().max(512.0);
        (cells.is_finite() && 2.0 * cells < MAX_SAMPLED_POINTS as f64).then_some(2 * cells as usize)
    }

    /// The time at angle `x`, s, counted from angle 0.
    fn time_at(&self, x: f64) -> f64 {
        let cells = self.t.len() - 1;
        let k = (x / self.period).floor();
        let r = (x - k * self.period) / self.h;
        // `as usize` takes a rounding's −0.0… to 0.
        let c = (r.floor() as usize).min(cells - 1);
        let s = r - c as f64;
        let (s2, s3) = (s * s, s * s * s);
        // ∫₀ˢ of the quadratic through (0, f₀), (½, f₁), (1, f₂).
        let w0 = 2.0 * s3 / 3.0 - 1.5 * s2 + s;
        let w1 = -4.0 * s3 / 3.0 + 2.0 * s2;
        let w2 = 2.0 * s3 / 3.0 - 0.5 * s2;
        let f = &self.f[2 * c..2 * c + 3];
        k * self.t[cells] + self.t[c] + self.h * (w0 * f[0] + w1 * f[1] + w2 * f[2])
    }

    /// The mean speed over `[x, x + span]`, rad/s.
    fn speed(&self, x: f64, span: f64) -> f64 {
        span / (self.time_at(x + span) - self.time_at(x))
    }
}

/// One speed sample: where it starts within the load period and the angle it spans, rad.
#[derive(Debug, Clone, Copy)]
struct Sample {
    start: f64,
    span: f64,
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

/// The samples over the common period of the load and the revolution (each distinct start
/// within the load period and span once) and the range of offsets they repeat over, rad.
fn samples(time: &SteadyTime, wheel: &SampleWheel, edges: u16) -> Option<(Vec<Sample>, f64)> {
    let n = u64::from(wheel.positions);
    let teeth = wheel.teeth.len() as u64;
    let k = u64::from(edges.max(1));
    if n == 0 || teeth == 0 || wheel.teeth.iter().any(|&t| u64::from(t) >= n) {
        return None;
    }
    if time.revolutions.checked_mul(teeth)? > MAX_EDGES {
        return None;
    }
    // Units of 2π/l: the grid positions and the load period are whole numbers of them.
    let l = n / gcd(n, time.periods) * time.periods;
    let per_position = l / n;
    let period_units = time.revolutions.checked_mul(l)? / time.periods;
    let unit = TAU / l as f64;
    let at = |g: u64| -> u64 {
        let (rev, idx) = (g / teeth, g % teeth);
        rev * l + u64::from(wheel.teeth[idx as usize]) * per_position
    };
    let mut keys: Vec<(u64, u64)> = (0..time.revolutions * teeth)
        .map(|g| (at(g) % period_units, at(g + k) - at(g)))
        .collect();
    keys.sort_unstable();
    keys.dedup();
    let repeat_units = gcd(u64::from(wheel.symmetry()) * per_position, period_units);
    let list = keys
        .into_iter()
        .map(|(s, w)| Sample {
            start: s as f64 * unit,
            span: w as f64 * unit,
        })
        .collect();
    Some((list, repeat_units as f64 * unit))
}

/// δ(θ) of the samples `which` of `all`.
fn delta_at(
    time: &SteadyTime,
    all: &[Sample],
    which: &mut dyn Iterator<Item = usize>,
    theta: f64,
) -> f64 {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for i in which {
        let s = all[i];
        let w = time.speed(s.start + theta, s.span);
        lo = lo.min(w);
        hi = hi.max(w);
    }
    2.0 * (hi - lo) / (hi + lo)
}

/// The indices of the `n` fastest and `n` slowest samples at `theta`.
fn extreme_samples(time: &SteadyTime, all: &[Sample], theta: f64, n: usize) -> Vec<usize> {
    let mut speeds: Vec<(f64, usize)> = all
        .iter()
        .enumerate()
        .map(|(i, s)| (time.speed(s.start + theta, s.span), i))
        .collect();
    let m = speeds.len();
    let mut out = Vec::with_capacity(2 * n);
    if m <= 2 * n {
        out.extend(0..m);
        return out;
    }
    let by_speed = |a: &(f64, usize), b: &(f64, usize)| a.0.total_cmp(&b.0);
    speeds.select_nth_unstable_by(n, by_speed);
    out.extend(speeds[..n].iter().map(|&(_, i)| i));
    speeds.select_nth_unstable_by(m - n - 1, by_speed);
    out.extend(speeds[m - n..].iter().map(|&(_, i)| i));
    out.sort_unstable();
    out.dedup();
    out
}

/// Golden-section search of `f` over `[a, b]` for its least (`sign` 1) or most (`sign` −1),
/// after a scan of 32 points: the argument found.
fn golden(f: &dyn Fn(f64) -> f64, a: f64, b: f64, sign: f64) -> f64 {
    const POINTS: usize = 32;
    let step = (b - a) / POINTS as f64;
    let best = (0..=POINTS)
        .map(|i| a + step * i as f64)
        .min_by(|&x, &y| (sign * f(x)).total_cmp(&(sign * f(y))))
        .unwrap_or(a);
    let (mut lo, mut hi) = ((best - step).max(a), (best + step).min(b));
    let r = 0.5 * (5f64.sqrt() - 1.0);
    let mut x1 = hi - r * (hi - lo);
    let mut x2 = lo + r * (hi - lo);
    let (mut f1, mut f2) = (sign * f(x1), sign * f(x2));
    for _ in 0..48 {
        if f1 <= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - r * (hi - lo);
            f1 = sign * f(x1);
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + r * (hi - lo);
            f2 = sign * f(x2);
        }
    }
    if f1 <= f2 {
        x1
    } else {
        x2
    }
}

/// δ of the steady state of `time` through speed samples of `edges` captured edges of
/// `wheel`, over the teeth's offset against the load (module docs), the scan of the offsets
/// taking about `budget` sample evaluations (at least one offset; [`SCAN_BUDGET`] for a
/// report). `None` where the edges over the common period of the load and the revolution are
/// more than 4 M.
pub fn sampled_range(
    time: &SteadyTime,
    wheel: &SampleWheel,
    edges: u16,
    budget: usize,
) -> Option<SampledRange> {
    if time.constant {
        return Some(SampledRange::none());
    }
    let (all, repeat) = samples(time, wheel, edges)?;
    let offsets = (budget / all.len().max(1)).clamp(1, MAX_OFFSETS);
    let d = repeat / offsets as f64;
    let (mut lo, mut hi) = (
        vec![f64::INFINITY; offsets],
        vec![f64::NEG_INFINITY; offsets],
    );
    for s in &all {
        for i in 0..offsets {
            let w = time.speed(s.start + d * i as f64, s.span);
            lo[i] = lo[i].min(w);
            hi[i] = hi[i].max(w);
        }
    }
    let grid: Vec<f64> = (0..offsets)
        .map(|i| 2.0 * (hi[i] - lo[i]) / (hi[i] + lo[i]))
        .collect();
    let at_zero = grid[0];
    let arg = |sign: f64| {
        (0..offsets)
            .min_by(|&a, &b| (sign * grid[a]).total_cmp(&(sign * grid[b])))
            .unwrap_or(0)
    };
    let every = |theta: f64| delta_at(time, &all, &mut (0..all.len()), theta);
    // Refine around the grid's least and most on the samples extreme there and at the
    // neighbouring offsets; the offset found is judged on every sample.
    let refine = |i: usize, sign: f64| -> (f64, f64) {
        let (a, b) = (d * (i as f64 - 1.0), d * (i as f64 + 1.0));
        let mut near: Vec<usize> = [a, d * i as f64, b]
            .iter()
            .flat_map(|&t| extreme_samples(time, &all, t, 3))
            .collect();
        near.sort_unstable();
        near.dedup();
        let f = |t: f64| delta_at(time, &all, &mut near.iter().copied(), t);
        let theta = golden(&f, a, b, sign);
        (theta.rem_euclid(repeat), every(theta))
    };
    let (i_least, i_most) = (arg(1.0), arg(-1.0));
    let (mut least, mut least_offset) = (grid[i_least], d * i_least as f64);
    let (mut most, mut most_offset) = (grid[i_most], d * i_most as f64);
    let (t, v) = refine(i_least, 1.0);
    if v < least {
        (least, least_offset) = (v, t);
    }
    let (t, v) = refine(i_most, -1.0);
    if v > most {
        (most, most_offset) = (v, t);
    }
    Some(SampledRange {
        least,
        least_offset,
        most,
        most_offset,
        at_zero,
        repeat,
    })
}

/// [`sampled_range`] of `model`'s steady state (`None` where [`SteadyTime::new`] or
/// [`sampled_range`] gives none).
pub fn delta_through_samples(
    model: &DriveModel,
    wheel: &SampleWheel,
    edges: u16,
) -> Option<SampledRange> {
    sampled_range(&SteadyTime::new(model)?, wheel, edges, SCAN_BUDGET)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rotation that maps the captured edges onto themselves: a disc's captured pitch, a
    /// pattern's revolution, or a pattern's own repeat.
    #[test]
    fn a_wheel_repeats_over_its_captured_pitch_or_its_pattern() {
        assert_eq!(SampleWheel::uniform(24, 1).symmetry(), 1);
        assert_eq!(SampleWheel::uniform(24, 2).symmetry(), 2);
        let gap = SampleWheel {
            positions: 36,
            teeth: (0..34).collect(),
        };
        assert_eq!(gap.symmetry(), 36);
        let twice = SampleWheel {
            positions: 12,
            teeth: vec![0, 1, 6, 7],
        };
        assert_eq!(twice.symmetry(), 6);
    }
}
