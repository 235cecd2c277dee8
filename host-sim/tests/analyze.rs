//! Captures written by the simulator and read back by `drive-sim analyze`: the formats round
//! trip, bad lines are named, and the core run on the captures of cranking engines is checked
//! against the simulation's ground truth (every edge: tooth, glitch, dropped).

use host_sim::app::analyze::{analyze, configure, AnalyzeOptions, AnalyzeReport, DecisionKind};
use host_sim::app::logic::{CaptureError, CaptureFormat, CaptureReader, Level, TimeUnit};
use host_sim::app::run::{run_with, CaptureTarget, Overrides, RunOptions, RunReport};
use host_sim::app::scene::Scene;
use host_sim::engine::encoder::Edge;
use std::path::{Path, PathBuf};

/// A file `name` in a scratch directory of its own, removed with the returned guard (when the
/// test ends, a failing one's too).
fn tmp(name: &str) -> (tempfile::TempDir, PathBuf) {
    let dir = tempfile::Builder::new()
        .prefix("analyze-test-")
        .tempdir()
        .unwrap();
    let file = dir.path().join(name);
    (dir, file)
}

/// Simulates `text` writing a capture in `format` to `file`; the report keeps every edge.
fn simulate(text: &str, format: CaptureFormat, file: &Path) -> RunReport {
    let scene = Scene::parse(text, Path::new("test.toml")).unwrap();
    let options = RunOptions {
        capture: Some(CaptureTarget {
            path: file.to_path_buf(),
            format,
        }),
        keep_edges: true,
        ..RunOptions::default()
    };
    run_with(
        &scene,
        Path::new("test.toml"),
        Overrides::default(),
        options,
    )
    .unwrap()
}

/// A decision of the core, as the tests compare it.
#[derive(Debug, Clone, Copy)]
enum Seen {
    Tooth { time: f64, tooth: u16, synced: bool },
    Fault { time: f64, fault: &'static str },
}

fn run_analyze(file: &Path, options: AnalyzeOptions) -> (AnalyzeReport, Vec<Seen>) {
    let cfg = configure(&options).unwrap();
    let mut reader = CaptureReader::open(file, None, None).unwrap();
    let mut seen = Vec::new();
    let report = analyze(&mut reader, &cfg, &mut |d| {
        seen.push(match d.kind {
            DecisionKind::Tooth { tooth, synced, .. } => Seen::Tooth {
                time: d.time,
                tooth,
                synced,
            },
            DecisionKind::Fault(f) => Seen::Fault {
                time: d.time,
                fault: f.name(),
            },
        })
    })
    .unwrap();
    (report, seen)
}

/// A reader of the capture `text`, as if read from the file `name` (its format told from its
/// first lines), with `sample_rate` for a sigrok file without its samplerate comment.
fn text_reader(
    text: String,
    name: &str,
    sample_rate: Option<f64>,
) -> Result<CaptureReader<std::io::Cursor<String>>, CaptureError> {
    CaptureReader::new(
        std::io::Cursor::new(text),
        Path::new(name),
        None,
        sample_rate,
    )
}

fn wheel(w: &str) -> AnalyzeOptions {
    AnalyzeOptions {
        wheel: Some(w.into()),
        ..AnalyzeOptions::default()
    }
}

/// The real tooth edges the capture shows (rising, on the encoder channel, not dropped).
fn teeth(edges: &[Edge]) -> Vec<Edge> {
    edges
        .iter()
        .filter(|e| e.rising && !e.index && !e.glitch && !e.dropped)
        .copied()
        .collect()
}

/// The core's number of the tooth at grid position `pos` on an N-M wheel: teeth at positions
/// 0 … N−M−1, tooth 0 the one after the gap (position 0).
fn core_tooth(pos: u32) -> u16 {
    pos as u16
}

/// The largest tooth-to-tooth ratio of the per-pitch intervals (either way), skipping the
/// first `skip` intervals.
fn worst_ratio(teeth: &[Edge], lines: u32, skip: usize) -> f64 {
    let per_pitch: Vec<f64> = teeth
        .windows(2)
        .map(|w| {
            let p = (w[1].tooth + lines - w[0].tooth) % lines;
            (w[1].true_time - w[0].true_time) / f64::from(p.max(1))
        })
        .collect();
    per_pitch
        .windows(2)
        .skip(skip)
        .map(|r| (r[1] / r[0]).max(r[0] / r[1]))
        .fold(1.0, f64::max)
}

/// Where a capture records an edge: at the first sample at or after it.
fn sampled(t: f64, rate: f64) -> f64 {
    (t * rate).ceil() / rate
}

/// Cranking from rest: the mean speed ramps from 0 to 25 rad/s in 0.5 s and holds; ±40 %
/// ripple, two compression strokes per revolution.
fn cranking(wheel: &str, capture: &str, duration: f64, extra: &str) -> String {
    format!(
        "[simulation]\nduration = {duration}\nseed = 3\n\
         [motor]\nmodel = \"profile\"\npoints = [[0.0, 0.0], [0.5, 25.0]]\n\
         [cranking]\nripple = 0.4\nstrokes = 2.0\nphase = 0.3\n\
         [encoder]\nwheel = \"{wheel}\"\ntimer_hz = 1e6\nestimator_edges = 1\n{extra}\n\
         [monitor]\nwindow_revolutions = 1\n\
         [capture]\n{capture}\n"
    )
}

/// The truth's δ over the edges of a window: per-tooth speed samples (angle over time, K = 1)
/// from the true times, their extremes.
fn truth_delta(teeth: &[Edge], lines: u32, start: f64, end: f64, rate: f64) -> f64 {
    let pitch = std::f64::consts::TAU / f64::from(lines);
    let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
    for w in teeth.windows(2) {
        let t1 = sampled(w[1].seen_time, rate);
        if t1 <= start + 1e-12 || t1 > end + 1e-12 {
            continue;
        }
        let p = f64::from((w[1].tooth + lines - w[0].tooth) % lines);
        let omega = p * pitch / (w[1].true_time - w[0].true_time);
        lo = lo.min(omega);
        hi = hi.max(omega);
    }
    2.0 * (hi - lo) / (hi + lo)
}

/// The checks of a clean cranking capture of an N-M wheel: no fault, sync at the right teeth,
/// every revolution after sync counted, δ within its noise floor of the truth.
fn check_clean(run: &RunReport, report: &AnalyzeReport, seen: &[Seen], lines: u32, rate: f64) {
    let truth = teeth(&run.edge_list);
    // Clean: every tooth present, ratios within 0.45–2.2 (the first intervals of a start from
    // rest are the core's time references, not judged).
    let worst = worst_ratio(&truth, lines, 3);
    assert!(worst < 2.2, "the signal is not clean: ratio {worst}");
    let faults: Vec<&Seen> = seen
        .iter()
        .filter(|s| matches!(s, Seen::Fault { .. }))
        .collect();
    assert!(faults.is_empty(), "{faults:?}");
    assert_eq!(
        (
            report.glitches,
            report.missing,
            report.extra,
            report.missing_frames
        ),
        (0, 0, 0, 0)
    );
    // Every accepted tooth is a real edge, and once synced it carries the truth's number.
    let mut first_synced = None;
    let mut k = 0usize;
    for s in seen {
        let Seen::Tooth {
            time,
            tooth,
            synced,
        } = *s
        else {
            continue;
        };
        while k < truth.len() && sampled(truth[k].seen_time, rate) < time - 1e-9 {
            k += 1;
        }
        let e = truth.get(k).unwrap_or_else(|| panic!("no edge at {time}"));
        assert!((sampled(e.seen_time, rate) - time).abs() < 1e-9, "{time}");
        if synced {
            first_synced.get_or_insert(k);
            assert_eq!(tooth, core_tooth(e.tooth), "tooth at {time}");
        }
    }
    let first = first_synced.expect("sync acquired");
    let teeth_per_rev = truth.iter().filter(|e| e.revolution == 2).count();
    assert!(
        first < truth.iter().position(|e| e.revolution >= 1).unwrap() + 2 * teeth_per_rev,
        "sync acquired at edge {first}"
    );
    // Every revolution after the first synced edge is counted (up to the last edge judged: the
    // last edges of a capture may still wait for the two that would confirm them).
    let last = seen
        .iter()
        .filter_map(|s| match s {
            Seen::Tooth { time, .. } => Some(*time),
            Seen::Fault { .. } => None,
        })
        .fold(f64::NEG_INFINITY, f64::max);
    let frames = truth[first + 1..]
        .iter()
        .filter(|e| e.tooth == 0 && sampled(e.seen_time, rate) <= last + 1e-9)
        .count();
    assert_eq!(report.revolutions as usize, frames);
    assert_eq!(report.invalid_windows, 0);
    assert!(report.valid_windows as usize + 1 >= frames, "{report:?}");
    for w in &report.windows {
        let d = w.delta.unwrap();
        let floor = w.noise_floor.unwrap();
        let truth = truth_delta(&truth, lines, w.start, w.end, rate);
        // The floor bounds the timer's quantization; the capture's sampling adds at most one
        // sample period per timestamp (timer 1 MHz, sampling 50× faster: 2 % of the floor).
        assert!(
            (d - truth).abs() <= floor * 1.02,
            "window {:.4}–{:.4}: δ {d} truth {truth} floor {floor}",
            w.start,
            w.end
        );
    }
}

/// A clean crank of `wheel` (`positions` of it) simulated for `duration` s, captured in `format`
/// (`capture`: the scene's [capture] table, sampling at `rate`) and analysed: the format read
/// is the one written, and every decision is right (`check_clean`).
fn clean_crank(
    wheel_name: &str,
    positions: u32,
    (capture, rate): (&str, f64),
    duration: f64,
    format: CaptureFormat,
) -> AnalyzeReport {
    let (_scratch, file) = tmp(&format!("crank-{wheel_name}.{}", format.name()));
    let run = simulate(&cranking(wheel_name, capture, duration, ""), format, &file);
    let (report, seen) = run_analyze(&file, wheel(wheel_name));
    assert_eq!(report.format, format.name());
    check_clean(&run, &report, &seen, positions, rate);
    report
}

#[test]
fn clean_cranking_of_a_36_2_wheel_from_a_saleae_capture() {
    let report = clean_crank(
        "36-2",
        36,
        ("sample_rate = 50e6", 50e6),
        2.0,
        CaptureFormat::Saleae,
    );
    assert!(report.revolutions >= 4, "{}", report.revolutions);
}

#[test]
fn clean_cranking_of_an_8_1_wheel_from_a_sigrok_capture() {
    let report = clean_crank(
        "8-1",
        8,
        ("sample_rate = 50e6\ndedup = true", 50e6),
        3.0,
        CaptureFormat::Sigrok,
    );
    assert!(report.revolutions >= 6, "{}", report.revolutions);
}

#[test]
fn clean_cranking_from_a_plain_capture_of_a_60_2_wheel() {
    clean_crank(
        "60-2",
        60,
        ("sample_rate = 50e6", 50e6),
        1.5,
        CaptureFormat::Plain,
    );
}

#[test]
fn clean_cranking_of_a_36_1_wheel_from_a_value_change_dump() {
    let report = clean_crank(
        "36-1",
        36,
        ("sample_rate = 24e6", 24e6),
        2.0,
        CaptureFormat::Vcd,
    );
    // The rate from the dump's comment (24 MHz: a period of 41.67 ns, times in fs).
    assert_eq!(report.sample_rate, Some(24e6));
    assert!(report.revolutions >= 4, "{}", report.revolutions);
}

/// Start from rest, crank, stall: the only fault is the timeout once the shaft has stopped
/// (the capture goes on for a second after it).
#[test]
fn a_stall_after_cranking_is_one_timeout_and_nothing_else() {
    let (_scratch, file) = tmp("stall.csv");
    let text = cranking("36-2", "sample_rate = 50e6", 3.5, "").replace(
        "points = [[0.0, 0.0], [0.5, 25.0]]",
        "points = [[0.0, 0.0], [0.5, 25.0], [1.8, 25.0], [2.4, 0.0]]",
    );
    let run = simulate(&text, CaptureFormat::Saleae, &file);
    let truth = teeth(&run.edge_list);
    assert!(worst_ratio(&truth, 36, 3) < 2.2);
    let (report, seen) = run_analyze(&file, wheel("36-2"));
    let faults: Vec<&Seen> = seen
        .iter()
        .filter(|s| matches!(s, Seen::Fault { .. }))
        .collect();
    assert_eq!(faults.len(), 1, "{faults:?}");
    assert!(
        matches!(faults[0], Seen::Fault { fault: "timeout", time } if *time > truth.last().unwrap().true_time)
    );
    assert_eq!(report.sync_losses, 1);
}

/// Noise pulses at 30–70 % of a tooth interval are glitches, each one, and no valid window
/// spans one; the real teeth behind them keep their numbers.
#[test]
fn noise_pulses_are_counted_as_glitches() {
    let (_scratch, file) = tmp("noise.csv");
    let text = cranking(
        "36-2",
        "sample_rate = 50e6\nnoise_width = 2e-6",
        2.0,
        "glitch_probability = 0.01\nglitch_window = [0.3, 0.7]",
    );
    let run = simulate(&text, CaptureFormat::Saleae, &file);
    let glitches: Vec<f64> = run
        .edge_list
        .iter()
        .filter(|e| e.glitch)
        .map(|e| e.seen_time)
        .collect();
    assert!(glitches.len() >= 3, "{}", glitches.len());
    let (report, seen) = run_analyze(&file, wheel("36-2"));
    // Noise before the core runs (the first edges are time references) cannot be judged.
    let judged: Vec<f64> = glitches
        .iter()
        .copied()
        .filter(|&t| t > report.sync_acquired.unwrap_or(f64::INFINITY))
        .collect();
    let found: Vec<f64> = seen
        .iter()
        .filter_map(|s| match s {
            Seen::Fault {
                fault: "glitch",
                time,
            } => Some(*time),
            _ => None,
        })
        .filter(|&t| t > report.sync_acquired.unwrap_or(f64::INFINITY))
        .collect();
    assert_eq!(
        found.len(),
        judged.len(),
        "found {found:?}, truth {judged:?}"
    );
    for (f, g) in found.iter().zip(&judged) {
        // The pulse's rising edge: at its start, or at its end when it is a dip on a tooth.
        assert!((f - g).abs() < 3e-6, "{f} {g}");
    }
    assert_eq!((report.missing, report.extra), (0, 0), "{report:?}");
    // Noise between teeth is no ringing.
    assert_eq!(report.ringing, None);
    for w in report.windows.iter().filter(|w| w.valid) {
        assert!(
            !glitches.iter().any(|&g| g > w.start && g < w.end),
            "valid window {}–{} spans a glitch",
            w.start,
            w.end
        );
    }
}

/// Dropped teeth are missing edges, each one.
#[test]
fn dropped_teeth_are_counted_as_missing() {
    let (_scratch, file) = tmp("dropped.csv");
    let text = cranking("36-2", "sample_rate = 50e6", 3.0, "drop_probability = 0.02");
    let run = simulate(&text, CaptureFormat::Saleae, &file);
    let (report, seen) = run_analyze(&file, wheel("36-2"));
    let after = report.sync_acquired.unwrap();
    let dropped: Vec<&Edge> = run
        .edge_list
        .iter()
        .filter(|e| e.dropped && e.rising && e.true_time > after)
        .collect();
    assert!(dropped.len() >= 2, "{}", dropped.len());
    let missing: Vec<f64> = seen
        .iter()
        .filter_map(|s| match s {
            Seen::Fault {
                fault: "missing-edge",
                time,
            } => Some(*time),
            _ => None,
        })
        .collect();
    assert_eq!(missing.len(), dropped.len(), "{missing:?} {dropped:?}");
    assert_eq!((report.glitches, report.extra), (0, 0));
}

/// A capture sampled too slowly for the pulses of a shaft that runs up (from 20 rad/s, where
/// 800 S/s takes five samples of a level, to 134 rad/s, where a level lasts less than one): the
/// file lacks level changes, and the run counts them exactly (each channel's changes in the
/// file and those lost add up to the edges the encoder delivered) and says so in a WARNING;
/// at 50 MS/s nothing is lost and nothing is said.
#[test]
fn level_changes_lost_to_the_sampling_are_counted_exactly() {
    let scene = |rate: &str| {
        format!(
            "[simulation]\nduration = 3.0\nsettle = 2.0\n\
             [shaft]\ninertia = 0.323\ninitial_speed = 20.0\n\
             [motor]\nmodel = \"parabola\"\nno_load_speed = 145.0\nbreakdown_speed = 36.0\n\
             breakdown_torque = 158.0\n\
             [load]\nmean = 24.0\n\
             [encoder]\nlines = 24\ntimer_hz = 1e6\nestimator_edges = 1\n\
             [capture]\nsample_rate = {rate}\n"
        )
    };
    for (rate, lossy) in [("800", true), ("50e6", false)] {
        let (_scratch, file) = tmp("runup.csv");
        let run = simulate(&scene(rate), CaptureFormat::Saleae, &file);
        // The level changes of the signal the encoder delivered (a pulse the shaft starts in
        // ends without having begun).
        let delivered = |index: bool| {
            let mut edges: Vec<&Edge> = run
                .edge_list
                .iter()
                .filter(|e| !e.dropped && e.index == index)
                .collect();
            edges.sort_by(|a, b| a.seen_time.total_cmp(&b.seen_time));
            let mut high = false;
            edges
                .iter()
                .filter(|e| std::mem::replace(&mut high, e.rising) != e.rising)
                .count() as u64
        };
        // The level changes the file shows, channel by channel.
        let mut reader = CaptureReader::open(&file, None, None).unwrap();
        let (mut prev, mut shown) = (Vec::new(), [0u64; 2]);
        while let Some((_, levels)) = reader.next_row().unwrap() {
            for (c, n) in shown.iter_mut().enumerate() {
                if prev.get(c).is_some_and(|p| *p != levels[c]) {
                    *n += 1;
                }
            }
            prev = levels.to_vec();
        }
        assert_eq!(run.capture_channels.len(), 2, "{:?}", run.capture_channels);
        for (c, ch) in run.capture_channels.iter().enumerate() {
            assert_eq!(ch.changes, delivered(c == 1), "{rate}: {ch:?}");
            assert_eq!(shown[c] + ch.lost, ch.changes, "{rate}: {ch:?}");
        }
        let encoder = &run.capture_channels[0];
        if lossy {
            assert!(encoder.lost * 10 > encoder.changes, "{encoder:?}");
            let warning = run.capture_warning.as_deref().unwrap();
            assert!(
                warning.contains(&format!(
                    "{} of the {} level changes of channel `Channel 0`",
                    encoder.lost, encoder.changes
                )) && warning.contains("`capture.sample_rate = 800`"),
                "{warning}"
            );
        } else {
            assert!(
                run.capture_channels.iter().all(|c| c.lost == 0),
                "{:?}",
                run.capture_channels
            );
            assert_eq!(run.capture_warning, None);
        }
    }
}

/// A scene of a 24-line disc with an index pulse on its own channel, at 40 rad/s for
/// `duration` s, captured at 10 MS/s.
fn index_disc(duration: f64) -> String {
    format!(
        "[simulation]\nduration = {duration}\n[motor]\nmodel = \"speed\"\nspeed = 40.0\n\
         [encoder]\nlines = 24\nframing = \"index\"\ntimer_hz = 1e6\nestimator_edges = 1\n\
         [capture]\nsample_rate = 10e6\n"
    )
}

/// Analysis of an index disc of `lines` lines.
fn index_lines(lines: u16) -> AnalyzeOptions {
    AnalyzeOptions {
        lines: Some(lines),
        framing: Some(host_sim::app::analyze::FramingArg::Index),
        ..AnalyzeOptions::default()
    }
}

/// An index disc (24 lines and an index pulse on its own channel): synced by the index,
/// every revolution counted, no fault.
#[test]
fn an_index_disc_from_two_channels() {
    let (_scratch, file) = tmp("index.csv");
    let run = simulate(&index_disc(1.0), CaptureFormat::Saleae, &file);
    let (report, seen) = run_analyze(&file, index_lines(24));
    assert_eq!(report.index_channel.as_deref(), Some("Channel 1"));
    assert!(seen.iter().all(|s| matches!(s, Seen::Tooth { .. })));
    let index = run.edge_list.iter().filter(|e| e.index && e.rising).count() as u64;
    assert_eq!(report.index_pulses, index);
    let synced = report.sync_acquired.unwrap();
    let frames = teeth(&run.edge_list)
        .iter()
        .filter(|e| e.tooth == 0 && e.true_time > synced + 1e-9)
        .count();
    assert_eq!(report.revolutions as usize, frames);
    assert!(frames >= 4);
}

/// `--lines N` without `--framing` takes the disc as unframed, as a capture need not hold an
/// index channel, where a scene's `lines = N` is framed by its index: the report says so, and
/// names a channel whose pulses come once every N edges (an index pulse's), not the quadrature
/// B channel's; with `--framing` given it says nothing.
#[test]
fn lines_without_framing_say_the_disc_is_taken_unframed() {
    use host_sim::app::analyze::{Channel, FramingArg};
    let (_scratch, file) = tmp("index.csv");
    simulate(&index_disc(1.0), CaptureFormat::Saleae, &file);
    let bare = AnalyzeOptions {
        lines: Some(24),
        ..AnalyzeOptions::default()
    };
    let (report, _) = run_analyze(&file, bare.clone());
    assert_eq!(report.wheel, "24 lines, no frame marker");
    let note = report.framing_note.as_deref().unwrap();
    assert!(
        note.starts_with("framing: none, the default without --framing"),
        "{note}"
    );
    assert!(
        note.contains("`Channel 1` pulses once every 24 edges of `Channel 0`")
            && note.contains("once a revolution of 24 lines")
            && note.contains("--framing index frames each revolution")
            && !note.contains("--index-channel"),
        "{note}"
    );
    let said = host_sim::app::analyze::text(&report);
    assert!(said.contains(note), "{said}");
    for framing in [FramingArg::None, FramingArg::Index] {
        let (report, _) = run_analyze(
            &file,
            AnalyzeOptions {
                framing: Some(framing),
                ..bare.clone()
            },
        );
        assert_eq!(report.framing_note, None);
    }
    // A quadrature capture: B pulses every pitch, the index Z once a revolution.
    let rev = std::f64::consts::TAU;
    let (text, _, _) = quadrature(50, 40.0, &[8.0 * rev]);
    let cfg = configure(&AnalyzeOptions {
        channel: Some(Channel::Name("A".into())),
        lines: Some(50),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let mut reader = text_reader(text, "q.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    let note = report.framing_note.unwrap();
    assert!(
        note.contains("`Z` pulses once every 50 edges of `A` (7 of its 7 spacings)")
            && note.contains("--framing index --index-channel 2"),
        "{note}"
    );
    assert!(!note.contains("`B`"), "{note}");
}

/// An index that pulses once every 24 edges, read with `--lines 25`: the note says the pulses
/// come every 24, not every 25, and what that makes of the speeds (a count of pulses against
/// edges alone read them as once a revolution of 25, and a 1000-line disc's index as once a
/// revolution of 1024). Read the other way round, the index as the encoder: a WARNING says the
/// channel read pulses once every 24 edges of the other (the speed read was 24 times low,
/// without a word).
#[test]
fn an_index_against_the_wrong_line_count_or_read_as_the_encoder_is_named() {
    use host_sim::app::analyze::Channel;
    let (_scratch, file) = tmp("index-lines.csv");
    simulate(&index_disc(1.0), CaptureFormat::Saleae, &file);
    let (report, _) = run_analyze(
        &file,
        AnalyzeOptions {
            lines: Some(25),
            ..AnalyzeOptions::default()
        },
    );
    let note = report.framing_note.as_deref().unwrap();
    assert!(
        note.contains("`Channel 1` pulses once every 24 edges of `Channel 0`")
            && note.contains("not every 25 as an index of --lines 25 would")
            && note.contains("the disc has 24 lines (--lines 24 --framing index)")
            && !note.contains("once a revolution of 25"),
        "{note}"
    );
    assert!(report
        .warnings
        .iter()
        .all(|w| !w.contains("the channel read")));
    // The index channel read as the encoder of a disc of `lines` lines: the report's text and
    // the WARNING about it.
    let read_index = |lines: u16| {
        let (report, _) = run_analyze(
            &file,
            AnalyzeOptions {
                lines: Some(lines),
                channel: Some(Channel::Name("Channel 1".into())),
                ..AnalyzeOptions::default()
            },
        );
        let w = report
            .warnings
            .iter()
            .find(|w| w.contains("the channel read"))
            .unwrap()
            .clone();
        (host_sim::app::analyze::text(&report), w)
    };
    let (text, w) = read_index(24);
    assert!(
        w.contains("`Channel 1`, the channel read, pulses once every 24 edges of `Channel 0`")
            && w.contains("read it with --channel 0")
            && w.contains("--framing index --index-channel 1")
            && w.contains("the speeds are about 24 times too low"),
        "{w}"
    );
    assert!(text.contains(w.as_str()));
    // Read as a disc of 60 lines, each pulse is a 60th of a revolution: the speeds are 60
    // times too low, not 24 (the factor said was the other channel's count).
    let (_, w) = read_index(60);
    assert!(
        w.contains("pulses once every 24 edges of `Channel 0`")
            && w.contains("one of the 60 pitches a revolution configured")
            && w.contains("the speeds are about 60 times too low"),
        "{w}"
    );
}

/// A capture taken through the timer's input prescaler (one capture in 4 line edges): the
/// simulation and the analysis of its recording (which holds every line edge) capture one edge
/// in four, so the speed is the shaft's and every revolution is framed by its index. (Every
/// line edge was fed: the speed read 4 times the shaft's, and every window of an index disc
/// was invalid, a missing frame.)
#[test]
fn a_prescaled_capture_takes_one_edge_in_four() {
    let (_scratch, file) = tmp("index-prescaled.csv");
    let text = index_disc(2.0).replace("lines = 24", "lines = 24\nprescaler = 4");
    let run = simulate(&text, CaptureFormat::Saleae, &file);
    let speed = run.speed_measured.unwrap();
    assert!((speed - 40.0).abs() < 1e-3, "{speed}");
    assert!(run.windows >= 10 && run.invalid_windows == 0, "{run:?}");
    let options = AnalyzeOptions {
        prescaler: Some(4),
        ..index_lines(24)
    };
    let (report, seen) = run_analyze(&file, options);
    let line_edges = teeth(&run.edge_list).len() as u64;
    assert_eq!(report.edges, line_edges);
    assert_eq!(report.captured, line_edges / 4);
    assert!(seen.iter().all(|s| matches!(s, Seen::Tooth { .. })));
    assert_eq!(report.missing_frames, 0);
    let synced = report.sync_acquired.unwrap();
    let frames = teeth(&run.edge_list)
        .iter()
        .filter(|e| e.tooth == 0 && e.true_time > synced + 1e-9)
        .count();
    assert_eq!(report.revolutions as usize, frames);
    for w in report.windows.iter().filter(|w| w.valid) {
        let mean = w.omega_mean.unwrap();
        assert!((mean - 40.0).abs() < 1e-3, "{mean}");
    }
    assert!(report.valid_windows >= 10 && report.invalid_windows == 0);
}

/// A capture whose times are Unix times (1.76e9 s: an f64 resolves only 0.24 µs there) reads
/// as exactly as the same capture from 0: the same decisions at the same times (counted from
/// the first time's whole seconds, which the report names) and the same δ in every window.
/// (Read as plain f64, every interval was off by up to 240 ticks of the 1 GHz timer.)
#[test]
fn unix_times_read_as_exactly_as_times_from_zero() {
    let (_scratch, file) = tmp("index-from-zero.csv");
    simulate(&index_disc(1.0), CaptureFormat::Plain, &file);
    let text = std::fs::read_to_string(&file).unwrap();
    let mut shifted = String::new();
    for (i, line) in text.lines().enumerate() {
        let (time, rest) = line.split_once(',').unwrap();
        if i == 0 {
            shifted.push_str(line);
        } else {
            // Whole seconds added as text: the file says exactly the same instants, later.
            let (whole, fraction) = time.split_once('.').unwrap_or((time, "0"));
            let whole: u64 = whole.parse().unwrap();
            shifted.push_str(&format!("{}.{fraction},{rest}", whole + 1_764_130_000));
        }
        shifted.push('\n');
    }
    let (_scratch, epoch) = tmp("index-unix-times.csv");
    std::fs::write(&epoch, shifted).unwrap();
    let options = AnalyzeOptions {
        timer_hz: Some(1e9),
        ..index_lines(24)
    };
    let (a, seen_a) = run_analyze(&file, options.clone());
    let (b, seen_b) = run_analyze(&epoch, options);
    assert_eq!((a.time_origin, b.time_origin), (0, 1_764_130_000));
    assert_eq!(seen_a.len(), seen_b.len());
    for (x, y) in seen_a.iter().zip(&seen_b) {
        assert_eq!(format!("{x:?}"), format!("{y:?}"));
    }
    let deltas = |r: &AnalyzeReport| r.windows.iter().map(|w| w.delta).collect::<Vec<_>>();
    assert!(a.valid_windows >= 3, "{}", a.valid_windows);
    assert_eq!(deltas(&a), deltas(&b));
}

/// A sample rate that could not have recorded the file (rows closer than one sample period)
/// is an error naming the row, not a floor widened by the wrong factor.
#[test]
fn a_sample_rate_too_slow_for_the_rows_is_refused() {
    let (_scratch, file) = tmp("index-rate.csv");
    simulate(&index_disc(0.2), CaptureFormat::Saleae, &file);
    let cfg = configure(&index_lines(24)).unwrap();
    for (rate, ok) in [(1e3, false), (10e6, true)] {
        let mut reader = CaptureReader::open(&file, None, Some(rate)).unwrap();
        let r = analyze(&mut reader, &cfg, &mut |_| {});
        match r {
            Ok(_) => assert!(ok, "{rate}"),
            Err(e) => {
                assert!(!ok, "{rate}: {e}");
                let e = e.to_string();
                assert!(
                    e.contains("index-rate.csv:") && e.contains("less than one period"),
                    "{e}"
                );
            }
        }
    }
}

/// Rows one sample period apart late in a capture (a one-sample noise pulse at 2.718 s, 50 MHz)
/// are one period apart, whatever the rounding of their times: they were refused as closer.
#[test]
fn rows_one_sample_apart_late_in_a_capture_are_not_refused() {
    let text = "Time [s],Channel 0\n0.000000000,0\n2.718281820,1\n2.718281840,0\n\
                3.000000000,1\n3.000000020,0\n"
        .to_string();
    let cfg = configure(&AnalyzeOptions {
        lines: Some(12),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let mut reader = text_reader(text.clone(), "late.csv", Some(50e6)).unwrap();
    assert!(analyze(&mut reader, &cfg, &mut |_| {}).is_ok());
    // At twice the rate they are two periods apart; half a period apart is still refused.
    let mut reader = text_reader(text, "late.csv", Some(100e6)).unwrap();
    assert!(analyze(&mut reader, &cfg, &mut |_| {}).is_ok());
    let closer = "Time [s],Channel 0\n0.000000000,0\n2.718281820,1\n2.718281830,0\n";
    let mut reader = text_reader(closer.to_string(), "late.csv", Some(50e6)).unwrap();
    let e = analyze(&mut reader, &cfg, &mut |_| {})
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("late.csv:4") && e.contains("less than one period"),
        "{e}"
    );
}

/// A capture shorter than one window says so, with both lengths, rather than "0 valid, 0
/// invalid" alone.
#[test]
fn a_capture_shorter_than_a_window_says_so() {
    let (_scratch, file) = tmp("index-short.csv");
    simulate(&index_disc(1.0), CaptureFormat::Saleae, &file);
    let options = AnalyzeOptions {
        window_revolutions: Some(100),
        ..index_lines(24)
    };
    let (report, _) = run_analyze(&file, options);
    assert!(report.revolutions >= 4, "{}", report.revolutions);
    let text = host_sim::app::analyze::text(&report);
    assert!(
        text.contains(&format!(
            "windows: 0 valid, 0 invalid (a window is 100 revolution(s) and the capture has {} \
             in sync)",
            report.revolutions
        )),
        "{text}"
    );
}

#[test]
fn an_index_disc_configured_with_the_wrong_lines_says_so() {
    // A 24-line disc analyzed as 20 or 25 lines never syncs; the report counts the missing
    // frames and says how many captures come between index pulses.
    let (_scratch, file) = tmp("index-wrong-lines.csv");
    simulate(&index_disc(3.0), CaptureFormat::Saleae, &file);
    for lines in [20u16, 24, 25] {
        let (report, _) = run_analyze(&file, index_lines(lines));
        let period = report.index_period.expect("index pulses");
        assert_eq!((period.captures, period.expected), (24, lines));
        assert!(period.of >= 15 && period.times == period.of, "{period:?}");
        let said = host_sim::app::analyze::text(&report);
        if lines == 24 {
            assert!(report.sync_acquired.is_some());
            assert_eq!(report.missing_frames, 0);
            assert!(!said.contains("index: "), "{said}");
        } else {
            assert!(report.sync_acquired.is_none());
            assert!(report.missing_frames >= 4, "{}", report.missing_frames);
            // Counted while searching, without a fault event of the core's: listed all the
            // same, each with its time.
            let listed = report
                .faults
                .iter()
                .filter(|f| f.fault == "missing-frame")
                .count();
            assert_eq!(
                listed, report.missing_frames as usize,
                "{:?}",
                report.faults
            );
            assert!(
                said.contains(&format!(
                    "index: 24 captures from one index pulse to the next ({} of {} times), \
                     but a revolution of the configured wheel is {lines}",
                    period.times, period.of
                )),
                "{said}"
            );
            // The index line says why; no second line claims that nothing does.
            assert!(
                !said.contains("no sync: none of the usual causes"),
                "{said}"
            );
        }
    }
}

/// Every format writes and reads back the same transitions, to its time resolution: the
/// sample grid (sigrok, plain and VCD exactly; Saleae's nine decimals to half a nanosecond).
#[test]
fn captures_round_trip_in_every_format() {
    let text = cranking("8-1", "sample_rate = 1e6", 0.7, "glitch_probability = 0.05")
        .replace("[capture]\n", "[capture]\nnoise_width = 1e-3\n");
    for format in [
        CaptureFormat::Saleae,
        CaptureFormat::Sigrok,
        CaptureFormat::Plain,
        CaptureFormat::Vcd,
    ] {
        let (_scratch, file) = tmp(&format!("round-{}.csv", format.name()));
        let run = simulate(&text, format, &file);
        // The level the writer was given, sample by sample: the tooth signal (set by each
        // pulse edge) exclusive-or the noise pulses; a transition where it changes.
        let mut events: Vec<(f64, Option<bool>)> = Vec::new();
        for e in run.edge_list.iter().filter(|e| !e.dropped && !e.index) {
            if e.glitch {
                events.push((e.seen_time, None));
                events.push((e.seen_time + 1e-3, None));
            } else {
                events.push((e.seen_time, Some(e.rising)));
            }
        }
        events.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut tooth, mut noise, mut out) = (false, false, false);
        let mut exp: Vec<f64> = Vec::new();
        let mut k = 0;
        while k < events.len() {
            let at = sampled(events[k].0, 1e6);
            while k < events.len() && sampled(events[k].0, 1e6) == at {
                match events[k].1 {
                    Some(l) => tooth = l,
                    None => noise = !noise,
                }
                k += 1;
            }
            if (tooth ^ noise) != out {
                out = tooth ^ noise;
                exp.push(at);
            }
        }
        let mut reader = CaptureReader::open(&file, None, None).unwrap();
        assert_eq!(reader.format(), format);
        let mut got = Vec::new();
        let mut prev = Level::Low;
        while let Some((t, levels)) = reader.next_row().unwrap() {
            if levels[0] != prev {
                got.push(t);
                prev = levels[0];
            }
        }
        if got.len() != exp.len() {
            for (i, (g, e)) in got.iter().zip(&exp).enumerate() {
                if (g - e).abs() > 1e-9 {
                    panic!(
                        "{}: #{i}: {g} vs {e}\n{:?}\n{:?}",
                        format.name(),
                        &got[i.saturating_sub(3)..(i + 3).min(got.len())],
                        &exp[i.saturating_sub(3)..(i + 3).min(exp.len())]
                    );
                }
            }
        }
        assert_eq!(got.len(), exp.len(), "{}", format.name());
        let tol = if format == CaptureFormat::Saleae {
            5.1e-10
        } else {
            1e-12
        };
        for (g, e) in got.iter().zip(&exp) {
            assert!((g - e).abs() <= tol, "{}: {g} vs {e}", format.name());
        }
    }
}

fn reader_error(text: &str) -> String {
    match text_reader(text.to_string(), "cap.csv", None) {
        Err(e) => e.to_string(),
        Ok(mut r) => loop {
            match r.next_row() {
                Ok(Some(_)) => continue,
                Ok(None) => panic!("no error in {text}"),
                Err(e) => break e.to_string(),
            }
        },
    }
}

#[test]
fn each_parser_names_the_bad_line() {
    let e = reader_error("Time [s],Channel 0\n0.000000000,0\n0.001000000,1\n0.002,2\n");
    assert!(
        e.starts_with("cap.csv:4:") && e.contains("`2`") && e.contains("not a logic level"),
        "{e}"
    );
    let e = reader_error("Time [s],Channel 0,Channel 1\n0.0,0,0\n0.1,1\n");
    assert!(
        e.starts_with("cap.csv:3:") && e.contains("expected 3 fields"),
        "{e}"
    );
    let e = reader_error("time_s,level\n0,0\nabc,1\n");
    assert!(
        e.starts_with("cap.csv:3:") && e.contains("not a time in seconds"),
        "{e}"
    );
    let e = reader_error("time_s,level\n0.5,0\n0.4,1\n");
    assert!(
        e.starts_with("cap.csv:3:") && e.contains("before the previous row"),
        "{e}"
    );
    let sigrok =
        "; CSV generated by libsigrok 0.6.0\n; from Demo device on Thu Jan  1 00:00:00 1970\n\
                  ; Channels (2/8): D0, D1\n; Samplerate: 1 MHz\nmicroseconds,logic,logic\n\
                  1,0,0\n2,1,0\n3,1,x\n";
    let e = reader_error(sigrok);
    assert!(
        e.starts_with("cap.csv:8:") && e.contains("channel `D1`"),
        "{e}"
    );
    let e = reader_error("; CSV\nTime,D0\n1,0\n");
    assert!(
        e.contains("cap.csv:2:") && e.contains("--sample-rate"),
        "{e}"
    );
    let e = reader_error("hello,world\n1,2\n");
    assert!(e.starts_with("cap.csv:1:") && e.contains("--format"), "{e}");
    // A European locale's exports: `;` between fields, decimal commas (they had been called
    // "not a time in seconds", or "found 2 fields: a file of edge times has one column").
    for (text, line, want) in [
        ("Time [s];Channel 0\n0;0\n0,0001;1\n", 1, "separated by `;`"),
        ("time_s;level\n0,0001;1\n", 1, "separated by `;`"),
        (
            "0,000100000\n0,001147198\n",
            1,
            "`0,000100000` has a decimal comma",
        ),
        (
            "time_s\n0,000100000\n0,001147198\n",
            2,
            "`0,000100000` has a decimal comma",
        ),
    ] {
        let e = reader_error(text);
        assert!(
            e.starts_with(&format!("cap.csv:{line}:")) && e.contains(want) && e.contains("decimal"),
            "{e}"
        );
    }
    let long = format!("time_s,level\n0,{}\n", "0".repeat(5000));
    let e = reader_error(&long);
    assert!(
        e.starts_with("cap.csv:2:") && e.contains("longer than"),
        "{e}"
    );
}

#[test]
fn sigrok_channel_names_and_sample_times_follow_libsigrok() {
    let text = "; CSV generated by libsigrok 0.6.0\n; from Demo on Thu Jan  1 00:00:00 1970\n\
                ; Channels (2/8): D0, D1\n; Samplerate: 3 MHz\nnanoseconds,logic,logic\n\
                333,0,0\n666,1,0\n999,1,1\n";
    let mut r = text_reader(text.to_string(), "s.csv", None).unwrap();
    assert_eq!(r.channels(), ["D0", "D1"]);
    // Sample i is written (i+1)·333 ns at 3 MHz (the period truncated): read back i/3e6.
    let mut times = Vec::new();
    while let Some((t, _)) = r.next_row().unwrap() {
        times.push(t);
    }
    assert_eq!(times, vec![0.0, 1.0 / 3e6, 2.0 / 3e6]);
}

#[test]
fn scene_wheel_keys_are_checked_by_name() {
    let err = |enc: &str| {
        let text =
            format!("[motor]\nmodel = \"speed\"\nspeed = 10.0\n[encoder]\ntimer_hz = 1e6\n{enc}\n");
        Scene::parse(&text, Path::new("w.toml"))
            .err()
            .map(|e| e.to_string())
            .unwrap_or_default()
    };
    assert!(err("wheel = \"36-2\"").is_empty());
    assert!(err("lines = 36\ngaps = [[0, 2], [12, 2], [27, 2]]").is_empty());
    assert!(err(
        "lines = 24\nteeth = [0, 2, 4, 6, 7, 8, 10, 12, 14, 16, 18, 20, 22]\nestimator_edges = 1"
    )
    .is_empty());
    let e = err("wheel = \"24+1\"");
    assert!(
        e.contains("encoder.wheel") && e.contains("ambiguous"),
        "{e}"
    );
    let e = err("wheel = \"36-2\"\nlines = 60");
    assert!(
        e.contains("`encoder.lines = 60`") && e.contains("36-2"),
        "{e}"
    );
    let e = err("lines = 36\ngaps = [[40, 2]]");
    assert!(e.contains("`encoder.gaps[1][1] = 40`"), "{e}");
    // Gaps that overlap, repeat or touch are one gap of another length: refused, both named
    // (they were merged into a 36-3 or a 36-2 wheel without a word).
    for (gaps, second, how) in [
        (
            "[[0, 2], [1, 2]]",
            "[1, 2]",
            "overlaps encoder.gaps[1] = [0, 2]",
        ),
        (
            "[[0, 2], [0, 2]]",
            "[0, 2]",
            "overlaps encoder.gaps[1] = [0, 2]",
        ),
        (
            "[[0, 2], [2, 1]]",
            "[2, 1]",
            "touches encoder.gaps[1] = [0, 2]",
        ),
        (
            "[[34, 2], [0, 1]]",
            "[0, 1]",
            "touches encoder.gaps[1] = [34, 2]",
        ),
    ] {
        let e = err(&format!("lines = 36\ngaps = {gaps}"));
        assert!(
            e.contains(&format!("`encoder.gaps[2] = {second}`")) && e.contains(how),
            "{gaps}: {e}"
        );
    }
    assert!(err("lines = 36\ngaps = [[0, 2], [3, 1]]").is_empty());
    let e = err("lines = 24\nteeth = [0, 2, 2]");
    assert!(
        e.contains("`encoder.teeth[3] = 2`") && e.contains("twice"),
        "{e}"
    );
    let e = err("wheel = \"36-2\"\ntolerances = { accept = 3.0 }");
    assert!(e.contains("`encoder.tolerances.accept = 3.0`"), "{e}");
    let e = err("lines = 100\nprescaler = 3");
    assert!(e.contains("`encoder.prescaler = 3`"), "{e}");
    // A pattern the core cannot frame: named by its keys, with the core's reason.
    let text = "[motor]\nmodel = \"speed\"\nspeed = 10.0\n[encoder]\ntimer_hz = 1e6\n\
                lines = 36\ngaps = [[0, 2], [12, 2], [24, 2]]\n";
    let scene = Scene::parse(text, Path::new("w.toml")).unwrap();
    let e = host_sim::app::run::core_encoder(&scene, Path::new("w.toml"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("encoder.gaps")
            && e.contains("rotationally symmetric")
            && !e.contains("encoder.teeth"),
        "{e}"
    );
}

/// A UTF-8 byte order mark (what a Windows editor or a spreadsheet's "CSV UTF-8" writes first)
/// is not part of the header: every format is still told and its channels named.
#[test]
fn a_byte_order_mark_before_the_header_is_skipped() {
    let files = [
        (
            "\u{feff}Time [s],Channel 0\r\n0.000000000,0\r\n0.001000000,1\r\n",
            CaptureFormat::Saleae,
            "Channel 0",
        ),
        (
            "\u{feff}; CSV generated by libsigrok 0.5.2\n; Channels (1/8): D0\n\
             ; Samplerate: 1 MHz\nmicroseconds,logic\n1,0\n2,1\n",
            CaptureFormat::Sigrok,
            "D0",
        ),
        (
            "\u{feff}time_s,level\n0,0\n0.001,1\n",
            CaptureFormat::Plain,
            "level",
        ),
    ];
    for (text, format, channel) in files {
        let mut r =
            text_reader(text.to_string(), "bom.csv", None).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(r.format(), format);
        assert_eq!(r.channels(), [channel]);
        let mut rows = 0;
        while r.next_row().unwrap().is_some() {
            rows += 1;
        }
        assert_eq!(rows, 2);
    }
}

fn sigrok_times(text: &str, sample_rate: Option<f64>) -> Result<Vec<f64>, String> {
    let mut r = text_reader(text.to_string(), "s.csv", sample_rate).map_err(|e| e.to_string())?;
    let mut times = Vec::new();
    while let Some((t, _)) = r.next_row().map_err(|e| e.to_string())? {
        times.push(t);
    }
    Ok(times)
}

/// A sigrok file's sample rate is its comment's or `--sample-rate`'s, never guessed: without
/// the comment (`sigrok-cli -O csv:header=false`) a `nanoseconds` column holds the period
/// rounded down to whole units (24 MHz: 41 ns instead of 41.67, so every time 1.6 % short),
/// and a `--sample-rate` that disagrees with the comment is not silently overridden.
#[test]
fn a_sigrok_sample_rate_is_never_guessed() {
    let rows = "nanoseconds,logic\n41,0\n82,1\n123,0\n";
    let e = sigrok_times(rows, None).unwrap_err();
    assert!(
        e.starts_with("s.csv:1:") && e.contains("`nanoseconds`") && e.contains("--sample-rate"),
        "{e}"
    );
    assert_eq!(
        sigrok_times(rows, Some(24e6)).unwrap(),
        vec![0.0, 1.0 / 24e6, 2.0 / 24e6]
    );
    // No header row either (label=off): the time column is there, its unit is not.
    let e = sigrok_times("; Channels (1/8): D0\n41,0\n82,1\n", None).unwrap_err();
    assert!(e.contains("--sample-rate"), "{e}");
    let commented = format!("; CSV generated by libsigrok 0.5.2\n; Samplerate: 24 MHz\n{rows}");
    assert_eq!(
        sigrok_times(&commented, None).unwrap(),
        vec![0.0, 1.0 / 24e6, 2.0 / 24e6]
    );
    assert!(sigrok_times(&commented, Some(24e6)).is_ok());
    let e = sigrok_times(&commented, Some(12e6)).unwrap_err();
    assert!(
        e.starts_with("s.csv:2:")
            && e.contains("Samplerate: 24 MHz")
            && e.contains("12000000 Hz")
            && e.contains("--sample-rate"),
        "{e}"
    );
}

/// `--channel 3` counts channels from 0; on an export whose channels are named by the
/// analyzer's own numbers from another start (Channel 0 not exported) that is another
/// channel than the one named 3: refused, naming both, instead of analyzing the wrong one.
#[test]
fn a_channel_number_that_another_channel_is_named_by_is_refused() {
    let header = "Time [s],Channel 1,Channel 2,Channel 3,Channel 4\n0.0,0,0,0,0\n0.001,1,0,1,0\n";
    let try_channel = |channel: host_sim::app::analyze::Channel, text: &str| {
        let cfg = configure(&AnalyzeOptions {
            channel: Some(channel),
            ..wheel("36-2")
        })
        .unwrap();
        let mut reader = text_reader(text.to_string(), "c.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {})
            .map(|r| r.channel)
            .map_err(|e| e.to_string())
    };
    use host_sim::app::analyze::Channel;
    let e = try_channel(Channel::Column(2), header).unwrap_err();
    assert!(
        e.contains("--channel 2 is ambiguous")
            && e.contains("`Channel 3`")
            && e.contains("`Channel 2`")
            && e.contains("--channel \"Channel 2\""),
        "{e}"
    );
    let e = try_channel(Channel::Column(4), header).unwrap_err();
    assert!(e.contains("--channel \"Channel 4\""), "{e}");
    assert_eq!(
        try_channel(Channel::Name("Channel 3".into()), header).unwrap(),
        "Channel 3"
    );
    // Numbers and names agree (every channel exported): the number is the channel.
    let all = "Time [s],Channel 0,Channel 1,Channel 2\n0.0,0,0,0\n0.001,1,0,1\n";
    assert_eq!(try_channel(Channel::Column(2), all).unwrap(), "Channel 2");
}

/// The index channel left at its default (1) on an export of Channel 1..4: ambiguous, and the
/// error says the default was taken, not that an `--index-channel 1` was given.
#[test]
fn a_default_index_channel_that_is_ambiguous_says_it_is_the_default() {
    let text = "Time [s],Channel 1,Channel 2,Channel 3,Channel 4\n0.0,0,0,0,0\n0.001,1,0,1,0\n";
    let run = |index_channel: Option<host_sim::app::analyze::Channel>| {
        let cfg = configure(&AnalyzeOptions {
            channel: Some(host_sim::app::analyze::Channel::Name("Channel 2".into())),
            index_channel,
            ..index_lines(50)
        })
        .unwrap();
        let mut reader = text_reader(text.to_string(), "i.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {})
            .map(|r| r.index_channel)
            .map_err(|e| e.to_string())
    };
    let e = run(None).unwrap_err();
    assert!(
        e.contains("no --index-channel was given, so the default applies")
            && e.contains("--index-channel 1 is ambiguous"),
        "{e}"
    );
    let e = run(Some(host_sim::app::analyze::Channel::Column(1))).unwrap_err();
    assert!(
        !e.contains("default") && e.contains("--index-channel 1 is ambiguous"),
        "{e}"
    );
    let named = Some(host_sim::app::analyze::Channel::Name("Channel 1".into()));
    assert_eq!(run(named).unwrap().as_deref(), Some("Channel 1"));
}

/// A channel that never changes (the wrong `--channel`, a probe not connected) gives no edge:
/// the report says so and names the channels that do change, instead of only "sync: never
/// acquired".
#[test]
fn a_channel_without_edges_is_named_with_the_channels_that_change() {
    let mut text = String::from("Time [s],Channel 0,Channel 1,Channel 2\n");
    for k in 0..40 {
        let _ = std::fmt::Write::write_fmt(
            &mut text,
            format_args!("{:.9},1,{},{}\n", f64::from(k) * 1e-3, k % 2, (k / 4) % 2),
        );
    }
    let run = |options: AnalyzeOptions| {
        let cfg = configure(&options).unwrap();
        let mut reader = text_reader(text.clone(), "q.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {}).unwrap()
    };
    let r = run(wheel("36-2"));
    assert_eq!(r.edges, 0);
    let changes: Vec<u64> = r.channel_changes.iter().map(|c| c.changes).collect();
    assert_eq!(changes, [0, 39, 9]);
    let said = host_sim::app::analyze::text(&r);
    assert!(
        said.contains(
            "no rising edge on --channel `Channel 0` in the capture: check --channel; channels \
             that change: Channel 1 (39 changes), Channel 2 (9 changes)"
        ),
        "{said}"
    );
    // An index disc whose index channel is the quiet one.
    let r = run(AnalyzeOptions {
        channel: Some(host_sim::app::analyze::Channel::Column(1)),
        index_channel: Some(host_sim::app::analyze::Channel::Column(0)),
        ..index_lines(24)
    });
    assert_eq!((r.edges, r.index_pulses), (20, 0));
    let said = host_sim::app::analyze::text(&r);
    assert!(
        said.contains("no rising edge on --index-channel `Channel 0`")
            && !said.contains("on --channel"),
        "{said}"
    );
}

/// A window whose mean speed moved from the previous one's (a run-down) is valid but not
/// steady, and the report says so: its δ includes the change of speed, not the ripple alone.
#[test]
fn windows_of_a_run_down_are_reported_not_steady() {
    let (_scratch, file) = tmp("rundown.csv");
    let text = cranking("36-2", "sample_rate = 50e6", 4.0, "").replace(
        "points = [[0.0, 0.0], [0.5, 25.0]]",
        "points = [[0.0, 0.0], [0.5, 25.0], [2.5, 25.0], [3.3, 2.0]]",
    );
    simulate(&text, CaptureFormat::Saleae, &file);
    let (report, _) = run_analyze(&file, wheel("36-2"));
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    let plateau: Vec<_> = valid
        .iter()
        .filter(|w| w.start > 0.6 && w.end < 2.5)
        .collect();
    let down: Vec<_> = valid.iter().filter(|w| w.end > 2.6).collect();
    assert!(plateau.len() >= 3 && !down.is_empty(), "{valid:?}");
    assert!(
        plateau[1..].iter().all(|w| w.steady == Some(true)),
        "{plateau:?}"
    );
    assert!(down.iter().all(|w| w.steady == Some(false)), "{down:?}");
    let said = host_sim::app::analyze::text(&report);
    let lines: Vec<&str> = said.lines().filter(|l| l.contains("valid")).collect();
    assert!(
        lines.iter().any(|l| l.ends_with("valid, not steady"))
            && lines.iter().any(|l| l.ends_with("  valid")),
        "{said}"
    );
}

/// A Saleae capture of a quadrature disc of `lines` lines (A, B a quarter pitch behind, and
/// an index pulse Z at tooth 0) turning at `omega` rad/s through the angle `stops`: forward
/// from 0 to `stops[0]`, back to `stops[1]`, forward to `stops[2]`... The times at which the
/// direction changes are returned with the text and the number of A's rising edges while
/// running backwards.
fn quadrature(lines: u32, omega: f64, stops: &[f64]) -> (String, Vec<f64>, usize) {
    let p = std::f64::consts::TAU / f64::from(lines);
    // (angle, channel, level after crossing it going forward)
    let boundaries = |lo: f64, hi: f64| {
        let mut b = Vec::new();
        let k0 = (lo / p).floor() as i64 - 1;
        let k1 = (hi / p).ceil() as i64 + 1;
        for k in k0..=k1 {
            let x = k as f64 * p;
            b.extend([
                (x, 0usize, true),
                (x + p / 2.0, 0, false),
                (x + p / 4.0, 1, true),
                (x + 3.0 * p / 4.0, 1, false),
            ]);
            if k.rem_euclid(i64::from(lines)) == 0 {
                b.extend([(x - p / 8.0, 2, true), (x + p / 8.0, 2, false)]);
            }
        }
        b.retain(|&(a, _, _)| a > lo && a <= hi);
        b
    };
    let mut events: Vec<(f64, usize, bool)> = Vec::new();
    let (mut from, mut t0) = (0.3 * p, 0.0);
    let mut turns = Vec::new();
    let mut backwards_rising = 0;
    for (i, &to) in stops.iter().enumerate() {
        let forward = i % 2 == 0;
        let (lo, hi) = if forward { (from, to) } else { (to, from) };
        for (a, c, up) in boundaries(lo, hi) {
            let level = if forward { up } else { !up };
            events.push((t0 + (a - from).abs() / omega, c, level));
            if !forward && c == 0 && level {
                backwards_rising += 1;
            }
        }
        t0 += (to - from).abs() / omega;
        turns.push(t0);
        from = to;
    }
    events.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut levels = [false, false, false];
    let mut text = String::from("Time [s],A,B,Z\n0.000000000,0,0,0\n");
    for (t, c, l) in events {
        levels[c] = l;
        let _ = std::fmt::Write::write_fmt(
            &mut text,
            format_args!(
                "{t:.9},{},{},{}\n",
                u8::from(levels[0]),
                u8::from(levels[1]),
                u8::from(levels[2])
            ),
        );
    }
    turns.pop();
    (text, turns, backwards_rising)
}

/// A shaft at rest rocking by a fraction of a pitch across A's line edge (B never changes),
/// or across A's and B's (each changes twice a cycle): every rising edge of A comes with B
/// saying forward (the backward crossings are edges not captured), and it read as running at
/// a steady speed, synced, with valid windows. The quadrature count says no pitch: the
/// captures are fed as reverse, one reversal is counted where the shaft stops running, and no
/// valid window reaches into the rocking.
#[test]
fn a_shaft_rocking_across_a_line_edge_is_not_running() {
    use host_sim::app::analyze::{Channel, Lead};
    let rev = std::f64::consts::TAU;
    let p = rev / 50.0;
    for centre in [0.0, p / 8.0] {
        // Forward to 6 revolutions (an A rising edge), then 200 swings of ±0.2 pitch about it
        // (or about the middle between it and B's rising edge).
        let mut stops = vec![6.0 * rev + centre + 0.2 * p];
        for _ in 0..100 {
            stops.extend([6.0 * rev + centre - 0.2 * p, 6.0 * rev + centre + 0.2 * p]);
        }
        let (text, turns, _) = quadrature(50, 40.0, &stops);
        // Unframed (the index pulse, rocked across too at the edge of revolution 6, is left
        // out: without the fix its missing frames would hide what is checked here).
        let cfg = configure(&AnalyzeOptions {
            channel: Some(Channel::Name("A".into())),
            direction_channel: Some(Channel::Name("B".into())),
            forward: Some(Lead::ALeads),
            lines: Some(50),
            framing: Some(host_sim::app::analyze::FramingArg::None),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut reader = text_reader(text, "q.csv", None).unwrap();
        let r = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
        assert!(
            r.windows.iter().any(|w| w.valid),
            "centre {centre}: {:?}",
            r.windows
        );
        for w in r.windows.iter().filter(|w| w.valid) {
            assert!(w.end <= turns[0] + 1e-3, "centre {centre}: {w:?}");
        }
        assert!(r.no_pitch >= 90, "centre {centre}: {r:?}");
        assert_eq!(r.backward_pitches, 0, "centre {centre}");
        assert!(r.reversals <= 1, "centre {centre}: {:?}", r.faults);
        let said = host_sim::app::analyze::text(&r);
        assert!(
            said.contains("no step forward of the quadrature count")
                && !said.contains("turned the other way"),
            "{said}"
        );
    }
}

/// A disc turning steadily the other way than `--forward` says (a forward run read with B
/// leading, or a reverse run): every capture is a pitch backward of the one before, which the
/// report says, with the `--forward` that reads it as forward, and not as a shaft at rest
/// rocking across a line edge (which it said of every capture). A run that turns back for a
/// while only says it turned the other way there.
#[test]
fn a_disc_turning_the_other_way_is_not_taken_for_rocking() {
    use host_sim::app::analyze::{Channel, Lead};
    let rev = std::f64::consts::TAU;
    let off = 0.37 * rev / 50.0;
    let analyze_with = |stops: &[f64], forward: Lead| {
        let (text, _, backwards) = quadrature(50, 40.0, stops);
        let cfg = configure(&AnalyzeOptions {
            channel: Some(Channel::Name("A".into())),
            direction_channel: Some(Channel::Name("B".into())),
            forward: Some(forward),
            lines: Some(50),
            framing: Some(host_sim::app::analyze::FramingArg::None),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut reader = text_reader(text, "q.csv", None).unwrap();
        let r = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
        let said = host_sim::app::analyze::text(&r);
        (r, said, backwards)
    };
    // Forward for 8 revolutions, read with B leading: every edge backward.
    let (r, said, _) = analyze_with(&[8.0 * rev + off], Lead::BLeads);
    assert_eq!(r.accepted, 0);
    assert!(r.backward_pitches + 1 >= r.captured, "{r:?}");
    assert_eq!(r.no_pitch, 0, "{r:?}");
    assert!(!said.contains("rocking across a line edge), fed"), "{said}");
    assert!(
        said.contains("the disc turned the other way for most of the capture")
            && said.contains("if it turned forward, give --forward a-leads"),
        "{said}"
    );
    let hint = r.sync_hint.unwrap().causes.join("\n");
    assert!(
        hint.contains("the edges ran backward") && !hint.contains("none of the usual causes"),
        "{hint}"
    );
    // Read as wired, it runs forward: nothing backward.
    let (r, said, _) = analyze_with(&[8.0 * rev + off], Lead::ALeads);
    assert_eq!((r.backward_pitches, r.reverse_edges), (0, 0), "{said}");
    // Forward 8 revolutions, back 4, forward to 12: the 4 back are said, no --forward offered.
    let (r, said, backwards) = analyze_with(
        &[8.0 * rev + off, 4.0 * rev + off, 12.0 * rev + off],
        Lead::ALeads,
    );
    assert!(
        r.backward_pitches + 2 >= backwards as u64 && r.backward_pitches <= backwards as u64,
        "{} of {backwards}",
        r.backward_pitches
    );
    assert!(
        said.contains("the disc turned the other way\n") && !said.contains("--forward b-leads"),
        "{said}"
    );
}

/// A reversal on a quadrature capture: with the B channel named, the core sees the direction
/// of every edge, counts the reversal, takes no backwards edge as a tooth and no revolution
/// run backwards; without it every edge counts as forward.
#[test]
fn a_reversal_is_seen_with_the_quadrature_b_channel() {
    use host_sim::app::analyze::{Channel, Lead};
    let rev = std::f64::consts::TAU;
    let off = 0.37 * rev / 50.0;
    let stops = [8.0 * rev + off, 4.0 * rev + off, 12.0 * rev + off];
    let (text, turns, backwards) = quadrature(50, 40.0, &stops);
    let run = |direction: Option<&str>, forward: Option<Lead>| {
        let cfg = configure(&AnalyzeOptions {
            channel: Some(Channel::Name("A".into())),
            index_channel: Some(Channel::Name("Z".into())),
            direction_channel: direction.map(|d| Channel::Name(d.into())),
            forward,
            ..index_lines(50)
        })
        .unwrap();
        let mut reader = text_reader(text.clone(), "q.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {}).unwrap()
    };
    let r = run(Some("B"), None);
    assert_eq!(r.direction_channel.as_deref(), Some("B"));
    assert_eq!((r.reversals, r.direction_unknown), (1, 0), "{r:?}");
    assert_eq!(r.reverse_edges as usize, backwards);
    assert!(r
        .faults
        .iter()
        .any(|f| f.fault == "reversal" && f.time > turns[0] && f.time < turns[1]));
    // Forward from 0 to 8 revolutions and from 4 to 12: at most 8 + 8 frames after sync.
    assert!(
        r.revolutions <= 15 && r.revolutions >= 12,
        "{}",
        r.revolutions
    );
    for w in r.windows.iter().filter(|w| w.valid) {
        assert!(w.end <= turns[0] || w.start >= turns[1], "{w:?}");
        assert!((w.omega_mean.unwrap() - 40.0).abs() < 0.1, "{w:?}");
    }
    let said = host_sim::app::analyze::text(&r);
    assert!(
        said.contains("direction from B (forward: A leads)"),
        "{said}"
    );
    // The other lead: the forward running is the reverse, and the reversal is where the shaft
    // comes back.
    let r = run(Some("B"), Some(Lead::BLeads));
    assert_eq!(r.reversals, 1, "{:?} {turns:?}", r.faults);
    assert!(
        r.faults
            .iter()
            .any(|f| f.fault == "reversal" && f.time > turns[1]),
        "{:?} {turns:?}",
        r.faults
    );
    // The direction channel is not the encoder's own; --forward needs it.
    let e = configure(&AnalyzeOptions {
        direction_channel: Some(Channel::Name("A".into())),
        ..index_lines(50)
    })
    .map(|cfg| {
        let mut reader = text_reader(text.clone(), "q.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {})
            .map(|_| ())
            .map_err(|e| e.to_string())
    })
    .unwrap()
    .unwrap_err();
    assert!(
        e.contains("--direction-channel is the encoder channel"),
        "{e}"
    );
    assert!(configure(&AnalyzeOptions {
        forward: Some(Lead::ALeads),
        ..index_lines(50)
    })
    .unwrap_err()
    .contains("--forward goes with --direction-channel"));
}

/// A noise pulse on the direction channel B across a rising edge of A (B up 2 µs before it,
/// back 2 µs after) reads B's level at the edge as reverse; the quadrature count says the
/// shaft stepped forward (B's three steps back and one forward in 4 µs of a 3 ms pitch are
/// no motion): the edge is fed forward and the pulse counted as a glitch of B, not a
/// reversal. The real reversal in the same capture is still one.
#[test]
fn a_pulse_on_the_direction_channel_at_an_edge_is_no_reversal() {
    use host_sim::app::analyze::{Channel, Lead};
    let rev = std::f64::consts::TAU;
    let off = 0.37 * rev / 50.0;
    let stops = [8.0 * rev + off, 4.0 * rev + off, 12.0 * rev + off];
    let (text, turns, backwards) = quadrature(50, 40.0, &stops);
    // Rows "t,A,B,Z": a pulse on B across A's rising edges at 2 and 6 revolutions (forward,
    // before the turn) and at 10 (forward again after it).
    let at = [
        2.0 * rev / 40.0,
        6.0 * rev / 40.0,
        turns[1] + 6.0 * rev / 40.0,
    ];
    // (`h`: B up `h` before A's edge and back `h` after it.)
    let pulsed = |h: f64| {
        let mut rows: Vec<(f64, [u8; 3])> = text
            .lines()
            .skip(1)
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                let v = |i: usize| f[i].parse::<u8>().unwrap();
                (f[0].parse().unwrap(), [v(1), v(2), v(3)])
            })
            .collect();
        for &a in &at {
            let k = (1..rows.len())
                .find(|&k| rows[k].0 >= a && rows[k - 1].1[0] == 0 && rows[k].1[0] == 1)
                .unwrap();
            let (t, mut l) = rows[k];
            let before = rows[k - 1].1;
            l[1] ^= 1;
            rows[k].1 = l;
            let mut back = l;
            back[1] ^= 1;
            let mut early = before;
            early[1] ^= 1;
            rows.splice(k..k, [(t - h, early)]);
            rows.insert(k + 2, (t + h, back));
        }
        let mut glitched = String::from("Time [s],A,B,Z\n");
        for (t, l) in &rows {
            glitched.push_str(&format!("{t:.9},{},{},{}\n", l[0], l[1], l[2]));
        }
        glitched
    };
    let run = |text: &str| {
        let cfg = configure(&AnalyzeOptions {
            channel: Some(Channel::Name("A".into())),
            index_channel: Some(Channel::Name("Z".into())),
            direction_channel: Some(Channel::Name("B".into())),
            forward: Some(Lead::ALeads),
            ..index_lines(50)
        })
        .unwrap();
        let mut reader = text_reader(text.to_string(), "q.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {}).unwrap()
    };
    let clean = run(&text);
    let r = run(&pulsed(2e-6));
    assert_eq!(clean.direction_glitches, 0);
    assert_eq!(
        (r.reversals, r.direction_glitches, r.reverse_edges as usize),
        (1, 3, backwards),
        "{:?}",
        r.faults
    );
    assert!(r
        .faults
        .iter()
        .all(|f| f.fault != "reversal" || (f.time > turns[0] && f.time < turns[1])));
    // As the clean capture: the same sync, revolutions and windows.
    assert_eq!(
        (
            r.sync_losses,
            r.revolutions,
            r.valid_windows,
            r.invalid_windows
        ),
        (
            clean.sync_losses,
            clean.revolutions,
            clean.valid_windows,
            clean.invalid_windows
        )
    );
    let said = host_sim::app::analyze::text(&r);
    assert!(
        said.contains("direction channel: 3 glitch(es) on B at edges of A, read as forward"),
        "{said}"
    );
    // A pulse wider than an eighth of a pitch (3.1 ms here) is not taken for noise: B's
    // level at the edge is read as it is, a reverse edge.
    let r = run(&pulsed(0.25e-3));
    assert_eq!(r.direction_glitches, 0);
    assert!(r.reversals > 1, "{:?}", r.faults);
}

/// A file cut off in the middle of its last row (a recording or a copy interrupted) is an
/// error that says so and what to do; the same row with its line end is an ordinary bad row,
/// and a complete last row without a line end is read.
#[test]
fn a_file_cut_off_in_the_middle_of_a_row_says_so() {
    let e = reader_error("Time [s],Channel 0,Channel 1\n0.000000000,0,0\n0.001000000,1");
    assert!(
        e.starts_with("cap.csv:3:")
            && e.contains("expected 3 fields")
            && e.contains("cut off")
            && e.contains("delete that line"),
        "{e}"
    );
    let e = reader_error("Time [s],Channel 0,Channel 1\n0.000000000,0,0\n0.001000000,1\n");
    assert!(
        e.contains("expected 3 fields") && !e.contains("cut off"),
        "{e}"
    );
    let e = reader_error("time_s,level\n0,0\n0.00");
    assert!(e.starts_with("cap.csv:3:") && e.contains("cut off"), "{e}");
    let mut r = text_reader("time_s,level\n0,0\n0.001,1".to_string(), "cap.csv", None).unwrap();
    assert!(r.next_row().unwrap().is_some());
    assert_eq!(r.next_row().unwrap().map(|(t, _)| t), Some(0.001));
    assert!(r.next_row().unwrap().is_none());
}

/// A capture sampled more coarsely than the emulated timer ticks (300 kS/s against 84 MHz):
/// δ is resolved to the sampling, not to the timer, and the floor the report gives includes
/// it; the timer's floor alone is exceeded many times over.
#[test]
fn a_coarsely_sampled_capture_widens_the_noise_floor() {
    let (_scratch, file) = tmp("coarse.csv");
    let run = simulate(
        &cranking("36-2", "sample_rate = 3e5\ndedup = true", 3.0, ""),
        CaptureFormat::Sigrok,
        &file,
    );
    let (report, _) = run_analyze(
        &file,
        AnalyzeOptions {
            timer_hz: Some(84e6),
            ..wheel("36-2")
        },
    );
    assert_eq!(report.sample_rate, Some(3e5));
    let truth = teeth(&run.edge_list);
    let mut beyond_timer = 0;
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    assert!(valid.len() >= 4, "{}", valid.len());
    for w in &valid {
        let (d, timer, both) = (
            w.delta.unwrap(),
            w.noise_floor.unwrap(),
            w.floor_with_sampling.unwrap(),
        );
        assert!((both / timer - (1.0 + 84e6 / 3e5)).abs() < 1e-9);
        let err = (d - truth_delta(&truth, 36, w.start, w.end, 3e5)).abs();
        assert!(err <= both, "window {}: error {err}, floor {both}", w.start);
        if err > timer {
            beyond_timer += 1;
        }
    }
    assert!(
        beyond_timer * 2 > valid.len(),
        "{beyond_timer} of {}",
        valid.len()
    );
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("sampling: 300000 Hz") && said.contains("281.000 times the timer's alone"),
        "{said}"
    );
}

/// The rising edges of an N-M wheel turning at `omega` rad/s from t = 0 to `stop` s (teeth at
/// grid positions 0 … N−M−1, the gap after them), drawn directly from the angle, not through
/// the simulator's encoder model.
fn wheel_teeth(n: u32, m: u32, omega: f64, stop: f64) -> Vec<f64> {
    let pitch = std::f64::consts::TAU / f64::from(n);
    (0..)
        .map(|k: u32| (k, f64::from(k) * pitch / omega))
        .take_while(|&(_, t)| t < stop)
        .filter(|&(k, _)| k % n < n - m)
        .map(|(_, t)| t)
        .collect()
}

/// A Saleae Logic 2 export of one channel sampled at `rate`, rising at `rising` and falling
/// halfway to the next rise; the recording ends at `end`.
fn saleae_of_rising(rising: &[f64], rate: f64, end: f64) -> String {
    let mut s = String::from("Time [s],Channel 0\n0.000000000,0\n");
    for (i, &t) in rising.iter().enumerate() {
        let next = rising.get(i + 1).copied().unwrap_or(t + 1e-3);
        let (up, down) = (sampled(t, rate), sampled(0.5 * (t + next), rate));
        s.push_str(&format!("{up:.9},1\n{down:.9},0\n"));
    }
    s.push_str(&format!("{end:.9},0\n"));
    s
}

/// A capture of more windows than are listed (20 500 revolutions of a 4-line disc, a window
/// each): the counts and the text count every window, --json says how many it lists of how
/// many, the text says where the others are (in no list), and the δ plot covers the whole
/// capture, decimated (it stopped at the last listed window, and the text counted "more
/// windows" from the listed ones).
#[test]
fn windows_past_the_listed_are_counted_and_plotted() {
    use host_sim::app::analyze::MAX_LISTED;
    let omega = 100.0;
    let pitch = std::f64::consts::TAU / 4.0 / omega;
    let rising: Vec<f64> = (0..4 * 20_500).map(|k| 1e-3 + k as f64 * pitch).collect();
    let end = rising.last().unwrap() + pitch;
    let cfg = configure(&AnalyzeOptions {
        lines: Some(4),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let mut reader = text_reader(saleae_of_rising(&rising, 1e8, end), "long.csv", None).unwrap();
    let r = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    let total = u64::from(r.valid_windows + r.invalid_windows);
    assert!(total > 20_000, "{total}");
    assert_eq!(r.windows_total, total);
    assert_eq!(r.windows.len(), MAX_LISTED);
    assert_eq!(r.windows_listed, MAX_LISTED as u64);
    assert_eq!(r.faults_total, r.faults_listed);
    let json = serde_json::to_value(&r).unwrap();
    assert_eq!(json["windows_total"], total);
    assert_eq!(json["windows_listed"], MAX_LISTED as u64);
    let said = host_sim::app::analyze::text(&r);
    assert!(
        said.contains(&format!(
            "  ... {} more windows: --json lists the first {MAX_LISTED} of the {total} windows \
             (the counts above count them all); the other {} are in no list, and the δ plot \
             (--plot) shows them all",
            total - 40,
            total - MAX_LISTED as u64
        )),
        "{said}"
    );
    // The δ plot: to the end of the capture, one window in 2, and it says so.
    assert_eq!(r.delta_every, 2);
    let last = r.delta_trace.last().unwrap().0;
    assert!(last > end - 3.0 * 4.0 * pitch, "{last} of {end}");
    assert!(
        r.delta_trace.len() as u64 >= total / 2 - 1,
        "{}",
        r.delta_trace.len()
    );
    let (_dir, file) = tmp("plots");
    std::fs::create_dir_all(&file).unwrap();
    host_sim::app::analyze::plots(&r, "long", &file).unwrap();
    let svg = std::fs::read_to_string(file.join("long-delta.svg")).unwrap();
    assert!(
        svg.contains(&format!("one window in 2 of {total}: decimated")),
        "{}",
        &svg[..svg.len().min(2000)]
    );
}

/// Lines faster than the timer ticks (an edge every 0.77 ticks of a 1 MHz timer: 8192 lines at
/// 1000 rad/s) come two to a tick, which the core cannot tell apart (glitches and missing
/// edges on a clean disc): the report says so and how to fix it, and says nothing at 2 MHz
/// (1.5 ticks an edge).
#[test]
fn edges_faster_than_the_timer_are_warned_of() {
    let rising: Vec<f64> = (0..5000).map(|i| f64::from(i) * 0.77e-6).collect();
    for (hz, warned) in [(1e6, true), (2e6, false)] {
        let cfg = configure(&AnalyzeOptions {
            lines: Some(512),
            timer_hz: Some(hz),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let text = saleae_of_rising(&rising, 100e6, 0.01);
        let mut reader = text_reader(text, "fast.csv", None).unwrap();
        let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
        assert_eq!(report.captures_at_one_tick > 1000, warned, "{hz}");
        let said = host_sim::app::analyze::text(&report);
        assert_eq!(said.contains("raise --timer-hz"), warned, "{said}");
    }
}

/// A file of edge times with one row repeated (0 s apart) was warned of as "captures at the
/// same timer tick ... raise --timer-hz" even at 1 GHz, where the pitch is 174 000 ticks. The
/// report now names the line and says it repeats the edge before; the timer warning is left
/// for edges that are distinct in the file.
#[test]
fn a_repeated_row_is_named_not_blamed_on_the_timer() {
    let pitch = std::f64::consts::TAU / 360.0 / 100.0;
    let mut rows: Vec<String> = (0..2000)
        .map(|i| format!("{:.12}", f64::from(i) * pitch))
        .collect();
    rows.insert(100, rows[99].clone());
    let cfg = configure(&AnalyzeOptions {
        lines: Some(360),
        timer_hz: Some(1e9),
        estimator_edges: Some(1),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let mut reader = text_reader(rows.join("\n") + "\n", "dup.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    let repeated = report.repeated_times.clone().unwrap();
    assert_eq!((repeated.rows, repeated.first_line), (1, 101));
    assert_eq!(report.captures_at_one_tick, 0);
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains(&format!(
            "WARNING: line 101 repeats the time of the edge before it, {} s (1 row repeats the \
             one before): a duplicated row in the file",
            rows[99].parse::<f64>().unwrap()
        )) && !said.contains("raise --timer-hz"),
        "{said}"
    );
}

/// A shaft that stops before the recording does: the timeout is where the firmware's poll
/// would see it (the core's timeout after the last tooth), not at the end of the file, and so
/// is the end of the window it makes invalid.
#[test]
fn a_stop_before_the_end_of_the_recording_times_out_where_it_happens() {
    let rising = wheel_teeth(36, 2, 40.0, 1.5);
    let last = *rising.last().unwrap();
    let cfg = configure(&wheel("36-2")).unwrap();
    let timeout = {
        let e = drive_monitor::encoder::Encoder::new(cfg.encoder).unwrap();
        f64::from(e.timeout_ticks()) / cfg.encoder.timer_hz
    };
    let mut reader = text_reader(saleae_of_rising(&rising, 50e6, 4.0), "stop.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert_eq!(report.timeouts, 1);
    let at = report
        .faults
        .iter()
        .find(|f| f.fault == "timeout")
        .unwrap()
        .time;
    assert!(
        at > last + timeout - 2e-3 && at < last + timeout + 2e-3,
        "timeout at {at} s, last tooth {last} s, timeout {timeout} s"
    );
    let w = report.windows.last().unwrap();
    assert!(!w.valid && (w.end - at).abs() < 1e-9, "{w:?}");
    assert!(
        report.sync.last().is_some_and(|s| s.time == at),
        "{:?}",
        report.sync
    );
}

/// A Saleae export states no sample rate, but its times show the sampling: every one on a
/// 5 µs grid (200 kS/s). A steady shaft (true δ 0) measured with an 84 MHz timer shows δ of
/// the sampling's size, hundreds of times the timer's floor: the floor given includes the
/// grid, and the report says the grid was taken as the sample period.
#[test]
fn the_time_grid_of_a_capture_without_a_rate_widens_the_floor() {
    let rising = wheel_teeth(36, 2, 40.0, 2.0);
    let text = saleae_of_rising(&rising, 2e5, 2.0);
    let cfg = configure(&AnalyzeOptions {
        timer_hz: Some(84e6),
        ..wheel("36-2")
    })
    .unwrap();
    let mut reader = text_reader(text, "coarse.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert_eq!(report.sample_rate, None);
    assert!(
        report.time_grid.is_some_and(|g| (g - 5e-6).abs() < 1e-15),
        "{:?}",
        report.time_grid
    );
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    assert!(valid.len() >= 5, "{}", valid.len());
    let mut beyond_timer = 0;
    for w in &valid {
        let (d, timer) = (w.delta.unwrap(), w.noise_floor.unwrap());
        let both = w.floor_with_sampling.unwrap();
        assert!((both / timer - (1.0 + 84e6 * 5e-6)).abs() < 1e-9);
        assert!(
            d <= both,
            "window {}: δ {d} (truth 0), floor {both}",
            w.start
        );
        if d > timer {
            beyond_timer += 1;
        }
    }
    assert_eq!(beyond_timer, valid.len());
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("every transition's time lies on a 5.000e-6 s grid"),
        "{said}"
    );
    // Times not on a common grid of 2 ns or more (full precision) give none.
    let fine: String = saleae_of_rising(&rising, 2e5, 2.0)
        .lines()
        .enumerate()
        .map(|(i, l)| match (i, l.split_once(',')) {
            (0, _) | (_, None) => format!("{l}\n"),
            (_, Some((t, v))) => format!(
                "{:.12},{v}\n",
                t.parse::<f64>().unwrap() + 1.3e-10 * i as f64
            ),
        })
        .collect();
    let mut reader = text_reader(fine, "fine.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert_eq!(report.time_grid, None);
    assert!(report
        .windows
        .iter()
        .all(|w| w.floor_with_sampling.is_none()));
}

/// An analyser at 12 MS/s (an FX2-based one) samples every 83.33 ns, and a Saleae export
/// writes its times to the nanosecond: they share no whole-nanosecond step, but every one lies
/// within a nanosecond of the 12 MHz grid, which is taken as the sample period: the floor is
/// the one a stated --sample-rate 12e6 gives. Times at 1 GS/s (any nanosecond) lie on none.
#[test]
fn a_grid_of_a_rate_whose_period_is_not_whole_nanoseconds_is_found() {
    let rising = wheel_teeth(36, 2, 40.0, 2.0);
    let cfg = configure(&AnalyzeOptions {
        timer_hz: Some(84e6),
        ..wheel("36-2")
    })
    .unwrap();
    let text = saleae_of_rising(&rising, 12e6, 2.0);
    let mut reader = text_reader(text.clone(), "fx2.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert_eq!(report.sample_rate, None);
    assert!(
        report
            .time_grid
            .is_some_and(|g| (g * 12e6 - 1.0).abs() < 1e-12),
        "{:?}",
        report.time_grid
    );
    let mut reader = text_reader(text, "fx2.csv", Some(12e6)).unwrap();
    let stated = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    let valid = report.windows.iter().filter(|w| w.valid).count();
    assert!(valid >= 5, "{valid}");
    assert_eq!(report.windows.len(), stated.windows.len());
    for (w, s) in report.windows.iter().zip(&stated.windows) {
        assert_eq!((w.valid, w.resolved), (s.valid, s.resolved), "{}", w.start);
        if let (Some(a), Some(b)) = (w.floor_with_sampling, s.floor_with_sampling) {
            assert!((a / b - 1.0).abs() < 1e-9, "{}: {a} against {b}", w.start);
        } else {
            assert!(!w.valid && !s.valid, "{}: {w:?}", w.start);
        }
    }
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains(
            "every transition's time lies on a 8.333e-8 s grid, to the nanosecond its times \
             are written to (a 12000000 Hz analyser's)"
        ),
        "{said}"
    );
    let fine = saleae_of_rising(&rising, 1e9, 2.0);
    let mut reader = text_reader(fine, "fine.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert_eq!(report.time_grid, None);
}

/// A steady shaft (true δ 0): what a window measures is the timer's quantization, within the
/// noise floor. Such a window is valid but its δ is not resolved, and the report says so
/// (`resolved` false) instead of printing it like a measured ripple.
#[test]
fn a_delta_within_its_noise_floor_is_not_reported_as_resolved() {
    let rising = wheel_teeth(36, 2, 40.0, 2.0);
    let cfg = configure(&wheel("36-2")).unwrap();
    let mut reader = text_reader(saleae_of_rising(&rising, 50e6, 2.0), "steady.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    assert!(valid.len() >= 5, "{}", valid.len());
    for w in &valid {
        let floor = w.floor_with_sampling.or(w.noise_floor).unwrap();
        assert!(w.delta.unwrap() <= floor, "{w:?}");
        assert_eq!(w.resolved, Some(false), "{w:?}");
    }
    let said = host_sim::app::analyze::text(&report);
    let rows: Vec<&str> = said.lines().filter(|l| l.contains("  valid")).collect();
    assert_eq!(rows.len(), valid.len(), "{said}");
    assert!(
        rows.iter()
            .all(|l| l.ends_with("δ within its floor: not resolved")),
        "{said}"
    );
}

/// A 16-bit counter at 1 MHz with the minimum speed near its limit (5.4 rad/s on a 36-1
/// wheel: a timeout of 64.6 ms against a 65.5 ms counter period) leaves 0.9 ms after the
/// timeout in which a poll sees the standstill before the counter wraps past the last edge.
/// Polled every 1 ms, a stop was missed at some phases (no timeout, "synced at the end");
/// the polls now come at least twice in that window, so every stop is seen.
#[test]
fn a_stop_is_seen_when_the_counter_barely_covers_the_timeout() {
    let cfg = configure(&AnalyzeOptions {
        counter_bits: Some(16),
        min_speed: Some(5.4),
        ..wheel("36-1")
    })
    .unwrap();
    let enc = drive_monitor::encoder::Encoder::new(cfg.encoder).unwrap();
    let window = f64::from(enc.poll_interval_ticks()) / cfg.encoder.timer_hz;
    assert!(window < 1e-3, "{window}");
    assert!(host_sim::app::analyze::poll_interval(&enc) <= 0.5 * window);
    for k in 0..12 {
        let stop = 2.5 + f64::from(k) * 0.83e-3;
        let rising = wheel_teeth(36, 1, 20.0, stop);
        let mut reader =
            text_reader(saleae_of_rising(&rising, 1e6, 4.0), "stop16.csv", None).unwrap();
        let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
        assert_eq!(report.timeouts, 1, "stop at {stop} s");
        assert_eq!(report.sync_state, "searching", "stop at {stop} s");
    }
}

/// Options outside a fixed range are refused with the range, in the options' own terms (not
/// the core's parameter names).
#[test]
fn options_out_of_range_name_their_range() {
    let err = |o: AnalyzeOptions| configure(&o).err().unwrap();
    let e = err(AnalyzeOptions {
        lines: Some(0),
        framing: Some(host_sim::app::analyze::FramingArg::Index),
        ..AnalyzeOptions::default()
    });
    assert!(
        e.contains("--lines 0 is out of range: a disc has 2 to 8192 lines"),
        "{e}"
    );
    // More lines than the analysis's monitor holds (the core's bound is wider): refused here,
    // with the range (was: "`edges per revolution` exceeds the fixed capacity").
    let e = err(AnalyzeOptions {
        lines: Some(9000),
        ..AnalyzeOptions::default()
    });
    assert_eq!(
        e,
        "--lines 9000 is out of range: a disc has 2 to 8192 lines"
    );
    let e = err(AnalyzeOptions {
        estimator_edges: Some(40),
        ..wheel("36-1")
    });
    assert!(
        e.contains("--estimator-edges 40 is out of range: a speed sample spans 1 to 32"),
        "{e}"
    );
    let e = err(AnalyzeOptions {
        estimator_edges: Some(8),
        ..wheel("8-1")
    });
    assert!(e.ends_with("(7 here: the wheel's teeth)"), "{e}");
    for (o, said) in [
        (
            AnalyzeOptions {
                counter_bits: Some(8),
                ..wheel("36-1")
            },
            "--counter-bits 8 is out of range: the counter is 16 to 32 bits wide",
        ),
        (
            AnalyzeOptions {
                window_revolutions: Some(0),
                ..wheel("36-1")
            },
            "--window-revolutions 0 is out of range: a window is 1 to 1024 revolutions",
        ),
        (
            AnalyzeOptions {
                window_revolutions: Some(5000),
                ..wheel("36-1")
            },
            "--window-revolutions 5000 is out of range: a window is 1 to 1024 revolutions",
        ),
        (
            AnalyzeOptions {
                prescaler: Some(3),
                ..wheel("36-1")
            },
            "--prescaler 3 is out of range: the input prescaler is 1, 2, 4 or 8",
        ),
        // (Was: "--timer-hz does not fit", the speed written out to 301 digits.)
        (
            AnalyzeOptions {
                min_speed: Some(1e300),
                ..wheel("36-1")
            },
            "--min-speed 1e300 is out of range: the slowest speed still running is 1e-6 to 1e5 \
             rad/s (as a scene's monitor.min_speed)",
        ),
        (
            AnalyzeOptions {
                min_speed: Some(1e-9),
                ..wheel("36-1")
            },
            "--min-speed 1e-9 is out of range: the slowest speed still running is 1e-6 to 1e5 \
             rad/s (as a scene's monitor.min_speed)",
        ),
    ] {
        assert_eq!(err(o), said);
    }
    // A sample longer than a revolution's captures says how many those are.
    let e = err(AnalyzeOptions {
        lines: Some(64),
        prescaler: Some(8),
        estimator_edges: Some(16),
        framing: Some(host_sim::app::analyze::FramingArg::Index),
        ..AnalyzeOptions::default()
    });
    assert!(e.ends_with("(8 here: 64 lines, one captured in 8)"), "{e}");
    // A prescaler the wheel cannot take names the wheel, not the timer.
    let e = err(AnalyzeOptions {
        prescaler: Some(2),
        ..wheel("36-2")
    });
    assert!(
        e.starts_with("--prescaler 2 does not fit a wheel with a pattern"),
        "{e}"
    );
    assert!(!e.contains("timer"), "{e}");
    let e = err(AnalyzeOptions {
        lines: Some(36),
        prescaler: Some(8),
        framing: Some(host_sim::app::analyze::FramingArg::Index),
        ..AnalyzeOptions::default()
    });
    assert!(
        e.starts_with("--prescaler 8 does not fit a disc of 36 lines: it must divide"),
        "{e}"
    );
    for w in ["36-36", "36-34", "100-2"] {
        let e = err(wheel(w));
        assert!(
            e.starts_with(&format!(
                "--wheel {w} is out of range: a wheel N-M has 3 to 128 positions"
            )),
            "{w}: {e}"
        );
        assert!(!e.contains("pattern."), "{w}: {e}");
    }
}

/// An index pulse a fraction of a tick after its frame edge (latched at the same tick by a
/// 1 MHz timer): windows begin and end at the frame edge's time, not the index pulse's (a
/// window was shown ending 0.3 µs late, at its index), and the sync list gives the time
/// `sync_acquired` does (listed at the edge the state changed after, two edges later).
#[test]
fn window_and_sync_times_are_the_edges_the_core_took() {
    // 24 lines at about 40 rad/s, each rising edge 0.2 µs into its tick, the index before
    // line 0: 65 µs (0.01 pitch) before it, and from the fifth revolution on in every other
    // revolution 0.3 µs after it, at its tick (a jittering index, taken as the count says once
    // in sync).
    let rising: Vec<f64> = (0..24 * 12u32)
        .map(|k| (1000.0 + f64::from(k) * 6545.0 + 0.2) * 1e-6)
        .collect();
    let mut rows = vec![(0.0, 0u8, 0u8)];
    for (k, &t) in rising.iter().enumerate() {
        let (index, odd) = (k % 24 == 0, k / 24 % 2 == 1 && k / 24 > 4);
        if index && !odd {
            rows.push((t - 65e-6, 0, 1));
        }
        rows.push((t, 1, u8::from(index && !odd)));
        if index && odd {
            rows.push((t + 0.3e-6, 1, 1));
        }
        rows.push((t + 3000e-6, 0, 0));
    }
    let mut text = String::from("Time [s],Channel 0,Channel 1\n");
    for (t, a, z) in rows {
        text.push_str(&format!("{t:.9},{a},{z}\n"));
    }
    let cfg = configure(&index_lines(24)).unwrap();
    let mut reader = text_reader(text, "index-at-edge.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert!(report.valid_windows >= 8, "{}", report.valid_windows);
    let on_edge = |t: f64| rising.iter().any(|&r| (r - t).abs() < 1e-12);
    for w in &report.windows {
        assert!(
            on_edge(w.start) && on_edge(w.end),
            "{} … {}",
            w.start,
            w.end
        );
    }
    let synced = report
        .sync
        .iter()
        .find(|s| s.state == "synced")
        .map(|s| s.time);
    assert_eq!(synced, report.sync_acquired);
}

/// The share of a ripple's δ that `analyze` says the windows read, against what the core
/// reads: edge times of a shaft running at ω̄(1 + a·sin(zφ + ψ)) integrated exactly enough
/// (Simpson's rule, 64 steps a pitch), fed to a monitor of one-revolution windows, every valid
/// window's δ over the true 2a. The reading is first order in a (0.001 here), the timer's
/// tick 1e-8 s: agreement to 0.005 of the true δ.
#[test]
fn the_ripple_reading_analyze_states_is_what_the_core_reads() {
    use drive_monitor::encoder::{Encoder, EncoderConfig, Estimator, Pattern};
    use drive_monitor::irregularity::{WindowConfig, WindowLength};
    use drive_monitor::monitor::DeltaMonitor;
    use drive_monitor::speed::Direction;
    use host_sim::app::analyze::ripple_reading;
    use std::f64::consts::TAU;
    let hz = 1e8;
    let wheels: Vec<(&str, EncoderConfig, Vec<f64>)> = {
        let pattern = |n: u8, m: u8, k: u16| {
            let p = Pattern::missing_teeth(n, m);
            let mut c = EncoderConfig::pattern(p, hz);
            c.estimator = Estimator::Edges(k);
            let angles = (0..u32::from(n))
                .filter(|&j| p.present() >> j & 1 == 1)
                .map(|j| TAU * f64::from(j) / f64::from(n))
                .collect();
            (c, angles)
        };
        let mut disc = EncoderConfig::unframed(16, hz);
        disc.estimator = Estimator::Edges(2);
        let disc_angles = (0..16).map(|j| TAU * f64::from(j) / 16.0).collect();
        let (c81, a81) = pattern(8, 1, 1);
        let (c121, a121) = pattern(12, 1, 1);
        let (c362, a362) = pattern(36, 2, 4);
        vec![
            ("8-1, K 1", c81, a81),
            ("12-1, K 1", c121, a121),
            ("36-2, K 4", c362, a362),
            ("16 lines, K 2", disc, disc_angles),
        ]
    };
    let a = 0.001;
    let mut checked = 0;
    for (name, cfg, angles) in &wheels {
        for z in 1..=6u32 {
            for psi in [0.0, 0.7, 1.9, 4.0] {
                let w = |phi: f64| 100.0 * (1.0 + a * (f64::from(z) * phi + psi).sin());
                // Edge times over 12 revolutions: t(φ) = ∫ dφ/ω.
                let mut times = Vec::new();
                let (mut t, mut from) = (0.0f64, 0.0f64);
                for rev in 0..12 {
                    for &theta in angles {
                        let to = TAU * f64::from(rev) + theta;
                        if to > from {
                            let h = (to - from) / 64.0;
                            let f = |k: u32| 1.0 / w(from + h * f64::from(k));
                            let mut sum = f(0) + f(64);
                            for k in 1..64 {
                                sum += if k % 2 == 1 { 4.0 } else { 2.0 } * f(k);
                            }
                            t += sum * h / 3.0;
                            from = to;
                        }
                        times.push(t);
                    }
                }
                let mut m: DeltaMonitor<1024> = DeltaMonitor::new(
                    Encoder::new(*cfg).unwrap(),
                    WindowConfig {
                        length: WindowLength::Revolutions(1),
                        steady_tolerance: 0.02,
                    },
                    None,
                )
                .unwrap();
                let expected = ripple_reading(cfg, z, psi);
                let mut valid = 0;
                for &t in &times {
                    let ticks = (0.001 + t) * hz;
                    if let Some(o) = m.on_edge(ticks as u64 as u32, Some(Direction::Forward)) {
                        if let Some(meas) = o.report.measurement() {
                            let read = f64::from(meas.delta) / (2.0 * a);
                            assert!(
                                (read - expected).abs() <= 0.005,
                                "{name}, order {z}, phase {psi}: the core reads {read:.4} of δ, \
                                 analyze says {expected:.4}"
                            );
                            valid += 1;
                        }
                    }
                }
                assert!(
                    valid >= 5,
                    "{name}, order {z}, phase {psi}: {valid} valid windows"
                );
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 4 * 6 * 4);
}

/// The lines `analyze` prints after `sync:` on why the core never synced.
fn hint_lines(report: &AnalyzeReport) -> Vec<String> {
    host_sim::app::analyze::text(report)
        .lines()
        .filter(|l| l.starts_with("no sync: "))
        .map(str::to_string)
        .collect()
}

/// A 36-1 wheel analyzed as 36-2 never syncs, and the report says why: the configured wheel's
/// 34 teeth and 3-pitch gap against the capture's gap of about twice its neighbours every 35
/// edges, and the wheel that fits. Analyzed as 36-1, it syncs and says nothing of the kind.
#[test]
fn a_wrong_wheel_is_named_with_the_gaps_the_capture_shows() {
    let (_scratch, file) = tmp("crank-36-1.csv");
    simulate(
        &cranking("36-1", "sample_rate = 50e6", 2.0, ""),
        CaptureFormat::Saleae,
        &file,
    );
    let (report, _) = run_analyze(&file, wheel("36-2"));
    assert!(report.sync_acquired.is_none());
    let hint = report.sync_hint.as_ref().expect("a hint");
    let gaps = hint.gaps.as_ref().expect("the gaps seen");
    assert_eq!(gaps.every, 35, "{hint:?}");
    assert!((gaps.ratio - 2.0).abs() < 0.2, "{hint:?}");
    assert!(gaps.times * 10 >= gaps.of * 9 && gaps.of >= 4, "{hint:?}");
    // A clean signal: no interval read as a noise pulse's.
    assert_eq!(hint.irregular_intervals, 0, "{hint:?}");
    let lines = hint_lines(&report);
    println!("{}", lines.join("\n"));
    assert!(
        lines.iter().any(|l| l.starts_with(
            "no sync: the configured 36-2 wheel has 34 teeth a revolution and a gap of 3 \
             pitches; in the capture an interval about 2.0 times its neighbours comes every 35 \
             edges"
        ) && l.ends_with("(a 36-1 wheel?)")),
        "{lines:?}"
    );
    // Printed right after the sync line.
    let said = host_sim::app::analyze::text(&report);
    let at = said.find("sync: never acquired").unwrap();
    assert!(said[at..]
        .lines()
        .nth(1)
        .unwrap()
        .starts_with("no sync: the configured 36-2"));
    let (right, _) = run_analyze(&file, wheel("36-1"));
    assert!(right.sync_acquired.is_some());
    assert!(right.sync_hint.is_none());
    assert!(hint_lines(&right).is_empty());
}

/// A capture of a wheel that syncs has no hint, in the text or the JSON.
#[test]
fn a_capture_that_syncs_has_no_hint() {
    let (_scratch, file) = tmp("crank-36-2.csv");
    simulate(
        &cranking("36-2", "sample_rate = 50e6", 2.0, ""),
        CaptureFormat::Saleae,
        &file,
    );
    let (report, _) = run_analyze(&file, wheel("36-2"));
    assert!(report.sync_acquired.is_some());
    assert!(report.sync_hint.is_none());
    assert!(hint_lines(&report).is_empty());
    let json = serde_json::to_value(&report).unwrap();
    assert!(json["sync_hint"].is_null(), "{}", json["sync_hint"]);
}

/// A capture of just over one revolution is too short to sync: the report says how many
/// revolutions of edges it holds, and claims no wrong wheel.
#[test]
fn a_capture_too_short_to_sync_says_so() {
    // 36-2 at 40 rad/s: a revolution is 0.157 s; 0.2 s is 1.3 revolutions, 43 teeth.
    let rising = wheel_teeth(36, 2, 40.0, 0.2);
    let mut reader = text_reader(saleae_of_rising(&rising, 50e6, 0.2), "short.csv", None).unwrap();
    let cfg = configure(&wheel("36-2")).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert!(report.sync_acquired.is_none());
    let lines = hint_lines(&report);
    println!("{}", lines.join("\n"));
    assert_eq!(
        lines,
        [format!(
            "no sync: the capture is too short: its {} captured edges are {:.1} revolutions of \
             the configured wheel (34 edges a revolution), and acquiring sync takes about 2–3",
            rising.len(),
            rising.len() as f64 / 34.0
        )],
    );
    let json = serde_json::to_value(&report).unwrap();
    let r = json["sync_hint"]["revolutions_of_edges"].as_f64().unwrap();
    assert!((r - rising.len() as f64 / 34.0).abs() < 1e-9, "{json}");
}

/// A shaft turning below --min-speed times out at every gap and never syncs: the report names
/// --min-speed and the slowest speed seen; with --min-speed below it, the same capture syncs.
#[test]
fn a_shaft_below_the_minimum_speed_says_so() {
    // 36-2 at 0.5 rad/s: a tooth every 0.35 s, the gap 1.05 s; --min-speed 1 rad/s times out
    // after 0.52 s.
    let rising = wheel_teeth(36, 2, 0.5, 50.0);
    let text = saleae_of_rising(&rising, 1e6, 50.0);
    for (min_speed, syncs) in [(1.0, false), (0.2, true)] {
        let cfg = configure(&AnalyzeOptions {
            min_speed: Some(min_speed),
            ..wheel("36-2")
        })
        .unwrap();
        let mut reader = text_reader(text.clone(), "slow.csv", None).unwrap();
        let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
        assert_eq!(report.sync_acquired.is_some(), syncs, "{min_speed}");
        if syncs {
            assert!(report.sync_hint.is_none());
            continue;
        }
        let hint = report.sync_hint.as_ref().unwrap();
        let slowest = hint.slowest_speed.unwrap();
        assert!((slowest - 0.5).abs() < 0.01, "{hint:?}");
        let lines = hint_lines(&report);
        println!("{}", lines.join("\n"));
        assert!(
            lines.iter().any(|l| l
                .starts_with("no sync: the shaft stopped or ran below --min-speed 1 rad/s:")
                && l.ends_with("the slowest speed seen is about 0.500 rad/s")),
            "{lines:?}"
        );
        // The gaps are the configured wheel's: no wrong wheel claimed.
        assert!(!lines.iter().any(|l| l.contains("configured")), "{lines:?}");
    }
}

/// A uniform disc analyzed as a 36-2 wheel shows no gap at all: the report says so and points
/// to --lines.
#[test]
fn a_uniform_disc_analyzed_as_a_wheel_with_a_gap_says_no_gap_was_seen() {
    let rising = wheel_teeth(36, 0, 40.0, 1.0);
    let mut reader =
        text_reader(saleae_of_rising(&rising, 50e6, 1.0), "uniform.csv", None).unwrap();
    let cfg = configure(&wheel("36-2")).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert!(report.sync_acquired.is_none());
    let lines = hint_lines(&report);
    println!("{}", lines.join("\n"));
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(
        lines[0].starts_with(
            "no sync: the configured 36-2 wheel has 34 teeth a revolution and a gap of 3 \
             pitches, but no gap recurs in the capture (0 interval(s)"
        ) && lines[0].contains("use --lines N --framing index|none"),
        "{lines:?}"
    );
}

/// Noise pulses on a fifth of the teeth keep the core from syncing: the report says the
/// signal is noisy, with the counts.
#[test]
fn a_noisy_signal_that_never_syncs_says_so() {
    let (_scratch, file) = tmp("very-noisy.csv");
    let text = cranking(
        "36-2",
        "sample_rate = 50e6\nnoise_width = 2e-6",
        2.0,
        "glitch_probability = 0.2\nglitch_window = [0.3, 0.7]",
    );
    simulate(&text, CaptureFormat::Saleae, &file);
    let (report, _) = run_analyze(&file, wheel("36-2"));
    let lines = hint_lines(&report);
    println!("{}", lines.join("\n"));
    assert!(report.sync_acquired.is_none(), "{lines:?}");
    let hint = report.sync_hint.as_ref().unwrap();
    // Every fifth tooth or so split by a pulse: far more than one interval in fifty.
    assert!(hint.irregular_intervals * 20 >= report.captured, "{hint:?}");
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(
        lines[0].starts_with(&format!(
            "no sync: the signal is noisy: of {} captured edges, {} interval(s) are short \
             against both neighbours and next to no gap (a noise pulse's)",
            report.captured, hint.irregular_intervals
        )),
        "{lines:?}"
    );
}

/// A clean 12-1 wheel at a steady 200 rpm on average but swinging ±45 % four times a
/// revolution (a V8 cranking) does not sync: its long intervals come every 3 edges, or after
/// 3 and 8 in turn, as the ripple's phase against the gap has it. The report says the speed
/// swings, from the long intervals coming at the same places every 11 edges (the wheel's
/// teeth), and names no other wheel and no noise; a wheel of the wrong count (a_wrong_wheel_*)
/// and a noisy signal (a_noisy_signal_*) are still named so.
#[test]
fn a_wheel_swinging_too_much_to_sync_is_not_called_another_wheel_or_noisy() {
    for phase in [0.0, std::f64::consts::PI] {
        let (_scratch, file) = tmp("swinging-12-1.csv");
        let text = format!(
            "[simulation]\nduration = 4.5\nseed = 3\n\
             [motor]\nmodel = \"profile\"\npoints = [[0.0, 20.944], [4.5, 20.944]]\n\
             [cranking]\nripple = 0.45\nstrokes = 4.0\nphase = {phase}\n\
             [encoder]\nwheel = \"12-1\"\ntimer_hz = 1e6\nestimator_edges = 1\n\
             [monitor]\nwindow_revolutions = 1\n\
             [capture]\nsample_rate = 50e6\n"
        );
        let run = simulate(&text, CaptureFormat::Saleae, &file);
        let (report, _) = run_analyze(&file, wheel("12-1"));
        let lines = hint_lines(&report);
        println!("phase {phase}:\n{}", lines.join("\n"));
        assert!(report.sync_acquired.is_none(), "phase {phase}: {lines:?}");
        // No edge lost or added: every edge the simulation recorded is a tooth.
        assert_eq!(
            report.captured,
            teeth(&run.edge_list).len() as u64,
            "phase {phase}"
        );
        assert_eq!(lines.len(), 1, "phase {phase}: {lines:?}");
        assert!(
            lines[0].starts_with(
                "no sync: the configured 12-1 wheel has 11 teeth a revolution and a gap of 2 \
                 pitches; in the capture "
            ) && lines[0].contains(
                "the long intervals come at the same places every 11 edges, as many as the \
                 wheel has teeth (none added or lost): unless its teeth are placed otherwise, \
                 the speed swings within a revolution"
            ) && !lines[0].contains("wheel?")
                && !lines[0].contains("positions with"),
            "phase {phase}: {lines:?}"
        );
    }
}

/// The rising edges of a wheel of `n` positions carrying a tooth where `present` says, turning
/// steadily at `omega` from t = 0 to `stop`.
fn pattern_teeth(n: u32, present: impl Fn(u32) -> bool, omega: f64, stop: f64) -> Vec<f64> {
    let pitch = std::f64::consts::TAU / f64::from(n);
    (0..)
        .map(|k: u32| (k, f64::from(k) * pitch / omega))
        .take_while(|&(_, t)| t < stop)
        .filter(|&(k, _)| present(k % n))
        .map(|(_, t)| t)
        .collect()
}

/// A scene that describes the wheel of `lines` positions with `gaps` ([first missing, count]),
/// for `analyze --scene`.
fn gaps_scene(lines: u32, gaps: &str) -> AnalyzeOptions {
    let text = format!(
        "[motor]\nmodel = \"speed\"\nspeed = 40.0\n[encoder]\ntimer_hz = 1e6\n\
         lines = {lines}\ngaps = {gaps}\n"
    );
    let path = PathBuf::from("gaps.toml");
    AnalyzeOptions {
        scene: Some((Scene::parse(&text, &path).unwrap(), path)),
        ..AnalyzeOptions::default()
    }
}

/// A 36-2-2-2 wheel (gaps of 3 pitches after runs of 10, 13 and 7 teeth) analyzed as 36-2:
/// the report names the three recurring gaps in the order they come and the wheel they make,
/// not a wheel of one gap. Described by a scene, the same capture syncs with no hint; and a
/// 36-2 capture analyzed with that scene is named a 36-2 wheel.
#[test]
fn a_wheel_with_several_gaps_is_named_by_its_gaps() {
    let missing = |k: u32| matches!(k, 0 | 1 | 12 | 13 | 27 | 28);
    let rising = pattern_teeth(36, |k| !missing(k), 40.0, 2.0);
    let text = saleae_of_rising(&rising, 50e6, 2.0);
    let read = |options: &AnalyzeOptions, text: &str| {
        let cfg = configure(options).unwrap();
        let mut reader = text_reader(text.to_string(), "gaps.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {}).unwrap()
    };
    let report = read(&wheel("36-2"), &text);
    assert!(report.sync_acquired.is_none());
    let hint = report.sync_hint.as_ref().expect("a hint");
    let gaps = hint.gaps.as_ref().expect("the gaps seen");
    // Teeth 2..=11 (10), 14..=26 (13), 29..=35 (7): listed round the wheel from the most
    // common (all as common: the fewest teeth).
    let every: Vec<u64> = gaps.spacings.iter().map(|s| s.every).collect();
    assert_eq!(every, [7, 10, 13], "{gaps:?}");
    assert!(
        gaps.spacings.iter().all(|s| (s.ratio - 3.0).abs() < 0.1),
        "{gaps:?}"
    );
    let lines = hint_lines(&report);
    println!("{}", lines.join("\n"));
    assert_eq!(lines.len(), 1, "{lines:?}");
    let times = gaps.spacings[0].times;
    assert!(times >= 10, "{gaps:?}");
    assert!(
        lines[0].starts_with(
            "no sync: the configured 36-2 wheel has 34 teeth a revolution and a gap of 3 \
             pitches; in the capture intervals about 3.0, 3.0 and 3.0 times their neighbours \
             come after 7, 10 and 13 edges in turn"
        ) && lines[0].contains("(a wheel of 36 positions with 3 gaps? describe it in a scene"),
        "{lines:?}"
    );
    let several = gaps_scene(36, "[[0, 2], [12, 2], [27, 2]]");
    let right = read(&several, &text);
    assert!(right.sync_acquired.is_some(), "{:?}", right.sync_hint);
    assert!(right.sync_hint.is_none());
    // One gap, analyzed as three: a 36-2 wheel, from the one gap that recurs.
    let one = saleae_of_rising(&wheel_teeth(36, 2, 40.0, 2.0), 50e6, 2.0);
    let report = read(&several, &one);
    assert!(report.sync_acquired.is_none());
    let lines = hint_lines(&report);
    println!("{}", lines.join("\n"));
    assert!(
        lines.len() == 1
            && lines[0].starts_with(
                "no sync: the configured wheel (pattern of 30 teeth on 36 positions) has 30 \
                 teeth a revolution and gaps of 3 pitches after 10 teeth, 3 pitches after 13 \
                 teeth, 3 pitches after 7 teeth; in the capture an interval about 3.0 times its \
                 neighbours comes every 34 edges"
            )
            && lines[0].ends_with("(a 36-2 wheel?)"),
        "{lines:?}"
    );
}

/// A capture that syncs, is lost to noise bursts again and again and ends in one, unsynced:
/// the report says why as for one that never synced, and names no wheel from the halves of
/// the teeth's intervals the pulses leave (they recur every other edge: once read as a 3-1
/// wheel). A single burst, synced again after it, leaves no hint.
#[test]
fn sync_lost_again_and_again_says_why() {
    let clean = wheel_teeth(36, 2, 40.0, 4.0);
    // Inside the bursts, a noise pulse in every interval, at 0.2 to 0.8 of it.
    let noisy = |bursts: &[(f64, f64)]| {
        let mut rising = Vec::new();
        for (i, w) in clean.windows(2).enumerate() {
            rising.push(w[0]);
            if bursts.iter().any(|&(a, b)| w[0] >= a && w[0] < b) {
                let at = 0.2 + 0.6 * ((i * 7) % 10) as f64 / 10.0;
                rising.push(w[0] + at * (w[1] - w[0]));
            }
        }
        rising.push(*clean.last().unwrap());
        saleae_of_rising(&rising, 50e6, 4.0)
    };
    let read = |text: String| {
        let cfg = configure(&wheel("36-2")).unwrap();
        let mut reader = text_reader(text, "bursts.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {}).unwrap()
    };
    let report = read(noisy(&[(1.0, 1.5), (2.5, 4.0)]));
    let lines = hint_lines(&report);
    println!("{}", lines.join("\n"));
    assert!(report.sync_acquired.is_some());
    assert!(report.sync_losses >= 2, "{}", report.sync_losses);
    assert_ne!(report.sync_state, "synced");
    assert_eq!(lines.len(), 1, "{lines:?}");
    assert!(
        lines[0].starts_with("no sync: the signal is noisy: of ")
            && lines[0].contains("no wheel's gaps can be told among them"),
        "{lines:?}"
    );
    let once = read(noisy(&[(1.0, 1.5)]));
    assert!(once.sync_losses >= 1 && once.sync_state == "synced");
    assert!(once.sync_hint.is_none() && hint_lines(&once).is_empty());
    // The edges the core did not judge while it searched again are counted and said: some,
    // at most the burst's (each tooth and its pulse) and three revolutions to sync again.
    let burst = 2 * clean.iter().filter(|&&t| (1.0..1.5).contains(&t)).count() as u64;
    assert!(
        once.edges_unsynced > 0 && once.edges_unsynced <= burst + 3 * 34,
        "{} of {}, the burst {burst}",
        once.edges_unsynced,
        once.captured
    );
    let said = host_sim::app::analyze::text(&once);
    assert!(
        said.contains(&format!(
            "sync lost: {} of the {} captured edges came while the count was searched for again",
            once.edges_unsynced, once.captured
        )),
        "{said}"
    );
    let clean = read(noisy(&[]));
    assert_eq!((clean.sync_losses, clean.edges_unsynced), (0, 0));
    assert!(!host_sim::app::analyze::text(&clean).contains("sync lost:"));
}

/// `t` as C's `%g` writes it: six significant digits, trailing zeros dropped.
fn six_digits(t: f64) -> String {
    if t == 0.0 {
        return "0".into();
    }
    let decimals = (5 - t.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{t:.decimals$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A plain capture of rising edges at `rising` (written by `time`), falling halfway.
fn plain_of_rising(rising: &[f64], time: impl Fn(f64) -> String) -> String {
    let mut s = String::from("time_s,level\n");
    for (i, &t) in rising.iter().enumerate() {
        let next = rising.get(i + 1).copied().unwrap_or(t + 1e-3);
        s.push_str(&format!("{},1\n{},0\n", time(t), time(0.5 * (t + next))));
    }
    s
}

/// Times written to six significant digits (C's `%g`): a steady 36-1 wheel at 100 rad/s (δ 0)
/// resolves its times to 10 µs from 1 s and to 100 µs from 10 s, where a pitch is 1745 µs. The
/// windows there read δ 0.057 (two steps of a pitch); their floor includes the resolution of
/// their own rows, so none is resolved, every δ lies within its floor, and a line says where
/// the times coarsen. (With the file's finest grid alone, 10 ns, they were resolved, δ 50
/// times the floor.)
#[test]
fn times_written_to_fixed_significant_digits_widen_the_floor() {
    let rising = wheel_teeth(36, 1, 100.0, 19.0);
    let text = plain_of_rising(&rising, six_digits);
    let cfg = configure(&wheel("36-1")).unwrap();
    let mut reader = text_reader(text, "g.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    assert!(valid.len() > 250, "{}", valid.len());
    let mut late = 0;
    for w in &valid {
        let (d, f) = (w.delta.unwrap(), w.floor_with_sampling.unwrap());
        assert!(d <= f, "{w:?}");
        assert_eq!(w.resolved, Some(false), "{w:?}");
        if w.start > 10.0 {
            assert_eq!(w.time_resolution, Some(1e-4), "{w:?}");
            late += 1;
        }
    }
    assert!(late > 100, "{late}");
    let (worst, from) = report.coarser_times.expect("said");
    assert_eq!(worst, 1e-4);
    assert!((9.9..=10.1).contains(&from), "{from}");
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("sampling: the times resolve less finely in places: to 1.000e-4 s"),
        "{said}"
    );
}

/// The kneader's own capture (Saleae, 50 MS/s), analyzed with its scene: where the speed
/// turns, 32 rows come 1166 samples apart, which is no coarser resolution of the times (it was
/// read as 23.32 µs, and every window of δ 0.031 as within a floor of 0.064, not resolved).
#[test]
fn a_steady_signal_on_a_fine_grid_is_not_taken_for_coarse_times() {
    let (_scratch, file) = tmp("kneader.csv");
    let text = host_sim::app::scene::BUNDLED
        .iter()
        .find(|(f, _)| *f == "kneader.toml")
        .unwrap()
        .1
        .replace("duration = 30.0", "duration = 3.0")
        .replace("settle = 10.0", "settle = 1.0");
    let run = simulate(&text, CaptureFormat::Saleae, &file);
    let scene = Scene::parse(&text, Path::new("kneader.toml")).unwrap();
    let (report, _) = run_analyze(
        &file,
        AnalyzeOptions {
            scene: Some((scene, PathBuf::from("kneader.toml"))),
            ..AnalyzeOptions::default()
        },
    );
    assert_eq!(report.time_grid, Some(2e-8));
    assert_eq!(report.coarser_times, None, "{:?}", report.coarser_times);
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    assert!(valid.len() >= 2, "{:?}", report.windows);
    for w in &valid {
        assert_eq!(w.resolved, Some(true), "{w:?}");
        // Steady, the run's own measurement of the same shaft.
        let d = w.delta.unwrap();
        if w.steady == Some(true) {
            assert!(
                (d / run.delta_measured.unwrap() - 1.0).abs() < 0.05,
                "{d} {w:?}"
            );
        }
    }
    assert!(valid.iter().any(|w| w.steady == Some(true)));
}

/// Exact decimal Unix times after a first row at 0 s: counted from 0 (the first row's whole
/// seconds), they are f64 numbers near 1.7e9 s, 0.24 µs apart (20 ticks of an 84 MHz timer),
/// and their products with the clock near 1.43e17 ticks, 16 ticks apart. Every valid window's
/// δ of a steady shaft (0) lies within its floor, which includes both spacings (it was up to
/// 19 times the timer's floor alone); a line says so.
#[test]
fn times_far_from_their_origin_widen_the_floor() {
    let rising = wheel_teeth(36, 1, 40.0, 3.0);
    let unix = |t: f64| {
        let ns = (t * 1e9).round() as u64;
        format!(
            "{}.{:09}",
            1_700_000_000 + ns / 1_000_000_000,
            ns % 1_000_000_000
        )
    };
    let text = format!(
        "time_s,level\n0.0,0\n{}",
        plain_of_rising(&rising, unix).trim_start_matches("time_s,level\n")
    );
    let cfg = configure(&AnalyzeOptions {
        timer_hz: Some(84e6),
        ..wheel("36-1")
    })
    .unwrap();
    let mut reader = text_reader(text, "unix.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert_eq!(report.time_origin, 0);
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    assert!(valid.len() >= 15, "{}", valid.len());
    for w in &valid {
        let (d, f) = (w.delta.unwrap(), w.floor_with_sampling.unwrap());
        assert!(d <= f, "{w:?}");
    }
    let (worst, _) = report.coarser_times.expect("said");
    assert_eq!(worst, 2f64.powi(-22) + 16.0 / 84e6, "{worst}");
}

/// A scene knows its load: `analyze --scene` says, as `run` and `predict` do, when the window
/// does not hold the load's cycle (the kneader's repeats every 8 revolutions), whether the
/// scene or `--window-revolutions` sets it; a whole number of cycles is not warned of.
#[test]
fn analyze_with_a_scene_warns_of_a_window_shorter_than_the_load_cycle() {
    let path = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/kneader.toml"));
    let scene = Scene::parse(&std::fs::read_to_string(&path).unwrap(), &path).unwrap();
    let with = |revolutions: Option<u16>| {
        configure(&AnalyzeOptions {
            scene: Some((scene.clone(), path.clone())),
            window_revolutions: revolutions,
            ..AnalyzeOptions::default()
        })
        .unwrap()
        .warnings
    };
    assert!(with(None).is_empty(), "{:?}", with(None));
    assert!(with(Some(16)).is_empty());
    let w = with(Some(3));
    assert_eq!(w.len(), 1);
    assert!(
        w[0].starts_with(
            "WARNING: `--window-revolutions 3` is not a whole number of the load's period (8 \
             revolutions)"
        ),
        "{w:?}"
    );
    // A load of no common period: the default window (one cycle of the lowest order) said;
    // a window set is the answer to that, as in `run`.
    let text = "[motor]\nmodel = \"speed\"\nspeed = 40.0\n[load]\nmean = 10.0\n\
                harmonics = [{ order = 1.0, amplitude = 5.0 }, { order = 1.4142135623730951, \
                amplitude = 5.0 }]\n[encoder]\ntimer_hz = 1e6\nlines = 36\nframing = \"none\"\n";
    let odd = Scene::parse(text, &path).unwrap();
    for n in [None, Some(40)] {
        let w = configure(&AnalyzeOptions {
            scene: Some((odd.clone(), path.clone())),
            window_revolutions: n,
            ..AnalyzeOptions::default()
        })
        .unwrap()
        .warnings;
        assert_eq!(
            w.len() == 1 && w[0].contains("have no common period"),
            n.is_none(),
            "{n:?}: {w:?}"
        );
    }
    // In the report's text, whatever the capture.
    let cfg = configure(&AnalyzeOptions {
        scene: Some((odd, path)),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let rising = wheel_teeth(36, 0, 40.0, 0.5);
    let mut reader = text_reader(saleae_of_rising(&rising, 50e6, 0.5), "k.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    assert!(host_sim::app::analyze::text(&report).contains(&cfg.warnings[0]));
}

/// The shares of a ripple's δ that README quotes (to two decimals), as analyze states them.
#[test]
fn the_ripple_readings_readme_quotes_are_analyzes() {
    use drive_monitor::encoder::{EncoderConfig, Estimator, Pattern};
    use host_sim::app::analyze::ripple_readings;
    // Wheel (positions, missing teeth), K, and the orders quoted with their shares.
    type Quoted = (u8, u8, u16, &'static [(u32, &'static str)]);
    let quoted: [Quoted; 3] = [
        (
            8,
            1,
            1,
            &[
                (1, "0.87–0.97"),
                (2, "0.64–0.90"),
                (3, "0.67–0.78"),
                (4, "0.00–0.64"),
                (8, "0.00–0.00"),
            ],
        ),
        (36, 2, 1, &[(6, "0.83–0.95")]),
        (60, 2, 4, &[(6, "0.72–0.76")]),
    ];
    for (n, m, k, orders) in quoted {
        let mut c = EncoderConfig::pattern(Pattern::missing_teeth(n, m), 1e6);
        c.estimator = Estimator::Edges(k);
        let r = ripple_readings(&c);
        for &(order, text) in orders {
            let q = r.iter().find(|q| q.order == order).unwrap();
            assert_eq!(
                format!("{:.2}–{:.2}", q.min, q.max),
                text,
                "{n}-{m}, K {k}, order {order}"
            );
        }
    }
}

/// A Saleae export's `X` (no data) on the channel read: its edges there were not seen, and the
/// report says so with the span, where it only counted missing edges and a sync loss, as if
/// the encoder had faulted.
#[test]
fn a_span_without_data_is_said_to_be_the_captures() {
    // A 12-line disc at 1 ms a line (rising every 1 ms), `X` from 0.1005 to 0.1205 s.
    let mut text = String::from("Time [s],Channel 0\n");
    for k in 0..400u32 {
        let t = f64::from(k) * 5e-4;
        let level = if (0.1005..0.1205).contains(&t) {
            "X".to_string()
        } else {
            (k % 2).to_string()
        };
        text.push_str(&format!("{t:.9},{level}\n"));
    }
    let cfg = configure(&AnalyzeOptions {
        lines: Some(12),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let mut reader = text_reader(text, "x.csv", None).unwrap();
    let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
    let n = report.no_data.as_ref().unwrap();
    assert_eq!(n.spans, 1);
    assert!(
        (n.first[0] - 0.1005).abs() < 1e-9 && (n.first[1] - 0.1205).abs() < 1e-9,
        "{n:?}"
    );
    assert!((n.seconds - 0.02).abs() < 1e-9, "{n:?}");
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("WARNING: `Channel 0` had no data (unknown level) over 1 span(s)"),
        "{said}"
    );
    // Without an `X`, nothing.
    let clean: String = (0..400u32)
        .map(|k| format!("{:.9},{}\n", f64::from(k) * 5e-4, k % 2))
        .collect();
    let mut reader = text_reader(format!("Time [s],Channel 0\n{clean}"), "c.csv", None).unwrap();
    assert!(analyze(&mut reader, &cfg, &mut |_| {})
        .unwrap()
        .no_data
        .is_none());
}

/// A fast timer on a narrow counter against the default minimum speed: the refusal is headed
/// by the options given, not by a `--min-speed` nobody gave; given, it is named.
#[test]
fn a_timer_that_does_not_fit_the_default_minimum_speed_names_the_options_given() {
    let o = AnalyzeOptions {
        lines: Some(1000),
        timer_hz: Some(84e6),
        counter_bits: Some(16),
        ..AnalyzeOptions::default()
    };
    let e = configure(&o).err().unwrap();
    assert!(
        e.starts_with("--timer-hz and --counter-bits do not fit the default --min-speed")
            && e.contains("`--min-speed` at least 8.06 rad/s"),
        "{e}"
    );
    let e = configure(&AnalyzeOptions {
        min_speed: Some(1.0),
        ..o
    })
    .err()
    .unwrap();
    assert!(e.starts_with("--min-speed does not fit"), "{e}");
}

/// `--channel 1 --framing index` without `--index-channel`: the default index channel (the
/// second column) is the encoder's, and the refusal says it was the default.
#[test]
fn the_default_index_channel_on_the_encoder_is_said_to_be_the_default() {
    use host_sim::app::analyze::{Channel, FramingArg};
    let text = "Time [s],Channel 0,Channel 1\n0.0,0,0\n0.001,1,1\n0.002,0,0\n".to_string();
    let o = AnalyzeOptions {
        lines: Some(12),
        framing: Some(FramingArg::Index),
        channel: Some(Channel::Column(1)),
        ..AnalyzeOptions::default()
    };
    let cfg = configure(&o).unwrap();
    let mut reader = text_reader(text.clone(), "two.csv", None).unwrap();
    let e = analyze(&mut reader, &cfg, &mut |_| {})
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("no --index-channel was given, so the default applies: `Channel 1`"),
        "{e}"
    );
    let cfg = configure(&AnalyzeOptions {
        index_channel: Some(Channel::Column(1)),
        ..o
    })
    .unwrap();
    let mut reader = text_reader(text, "two.csv", None).unwrap();
    let e = analyze(&mut reader, &cfg, &mut |_| {})
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("--index-channel is the encoder channel itself"),
        "{e}"
    );
}

/// A Saleae Logic 1.x digital export (`Time[s], Channel 0, Channel 1`: no space before `[s]`,
/// one after each comma, fifteen decimals) is read as Saleae's, told from its header or named
/// with --format saleae, and gives the analysis of the same capture exported by Logic 2, row
/// per change or row per sample alike; a tab-separated export and a header that is no Saleae
/// time column are refused, saying what to export.
#[test]
fn a_saleae_logic_1_export_is_read_as_logic_2s() {
    use host_sim::app::analyze::FramingArg;
    // A 16-line disc with an index, 5 ms a line, 10 revolutions; sampled at 1 MHz.
    let mut logic2 = String::from("Time [s],Channel 0,Channel 1\n");
    let mut logic1 = String::from("Time[s], Channel 0, Channel 1\n");
    let mut per_sample = String::from("Time[s], Channel 0, Channel 1\n");
    let level = |us: u64| {
        let line = (us / 2500) % 2;
        let index = u64::from(us % 80_000 < 2500);
        (line, index)
    };
    let end = 800_000u64;
    let mut last = None;
    for us in 0..=end {
        let l = level(us);
        if last != Some(l) || us == end {
            let t = us as f64 * 1e-6;
            logic2.push_str(&format!("{t:.9},{},{}\n", l.0, l.1));
            logic1.push_str(&format!("{t:.15}, {}, {}\n", l.0, l.1));
        }
        // A row every 10 µs (the levels hold between them).
        if us % 10 == 0 {
            per_sample.push_str(&format!("{:.15}, {}, {}\n", us as f64 * 1e-6, l.0, l.1));
        }
        last = Some(l);
    }
    let cfg = configure(&AnalyzeOptions {
        lines: Some(16),
        framing: Some(FramingArg::Index),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let read = |text: &str, format: Option<CaptureFormat>| {
        let mut r = CaptureReader::new(
            std::io::Cursor::new(text.to_string()),
            Path::new("l.csv"),
            format,
            None,
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(r.format(), CaptureFormat::Saleae);
        assert_eq!(r.channels(), ["Channel 0", "Channel 1"]);
        analyze(&mut r, &cfg, &mut |_| {}).unwrap()
    };
    let two = read(&logic2, None);
    assert!(two.valid_windows >= 7, "{}", two.valid_windows);
    for (text, format) in [
        (&logic1, None),
        (&logic1, Some(CaptureFormat::Saleae)),
        (&per_sample, None),
    ] {
        let one = read(text, format);
        assert_eq!(
            (
                one.captured,
                one.index_pulses,
                one.accepted,
                one.valid_windows
            ),
            (
                two.captured,
                two.index_pulses,
                two.accepted,
                two.valid_windows
            )
        );
        let deltas = |r: &AnalyzeReport| r.windows.iter().map(|w| w.delta).collect::<Vec<_>>();
        assert_eq!(deltas(&one), deltas(&two));
    }
    // Tab-separated: the delimiter named.
    let e = reader_error("Time[s]\tChannel 0\tChannel 1\n0.0\t0\t0\n");
    assert!(
        e.starts_with("cap.csv:1:") && e.contains("tab-separated") && e.contains("delimiter"),
        "{e}"
    );
    // Named saleae, a header that is not: refused with Saleae's headers.
    let e = CaptureReader::new(
        std::io::Cursor::new("Index, Channel 0\n0, 0\n".to_string()),
        Path::new("s.csv"),
        Some(CaptureFormat::Saleae),
        None,
    )
    .err()
    .unwrap()
    .to_string();
    assert!(
        e.contains("`Time [s],Channel 0,...` (Logic 2) or `Time[s], Channel 0, ...` (Logic 1.x)")
            && e.contains("`Sample Number, Channel 0, ...`")
            && e.contains("found `Index, Channel 0`"),
        "{e}"
    );
}

/// A Saleae Logic 1.x export with sample numbers for times is read at the rate --sample-rate
/// gives and analyzes as the same rows exported with time stamps, δ for δ (at a rate whose
/// period is a whole number of nanoseconds, and at 24 MHz, whose is not); without the rate it
/// is refused naming the column and the option, and a sample number that is not a whole
/// number, or a rate that is no rate, is named.
#[test]
fn a_saleae_logic_1_export_with_sample_numbers_reads_as_its_time_stamps() {
    for (rate, rate_key) in [(50e6, "sample_rate = 50e6"), (24e6, "sample_rate = 24e6")] {
        let (_scratch, file) = tmp("crank.csv");
        simulate(
            &cranking("36-2", rate_key, 2.0, ""),
            CaptureFormat::Saleae,
            &file,
        );
        let written = std::fs::read_to_string(&file).unwrap();
        // The same rows as Logic 1.x writes them: with time stamps (fifteen decimals), and
        // with sample numbers.
        let mut stamped = String::from("Time[s], Channel 0\n");
        let mut numbered = String::from("Sample Number, Channel 0\n");
        for row in written.lines().skip(1) {
            let (t, level) = row.split_once(',').unwrap();
            let n = (t.parse::<f64>().unwrap() * rate).round() as i64;
            stamped.push_str(&format!("{:.15}, {level}\n", n as f64 / rate));
            numbered.push_str(&format!("{n}, {level}\n"));
        }
        let cfg = configure(&wheel("36-2")).unwrap();
        let read = |text: &str, rate: Option<f64>| {
            let mut r =
                text_reader(text.to_string(), "l.csv", rate).unwrap_or_else(|e| panic!("{e}"));
            assert_eq!(r.format(), CaptureFormat::Saleae);
            assert_eq!(r.channels(), ["Channel 0"]);
            analyze(&mut r, &cfg, &mut |_| {}).unwrap()
        };
        let by_time = read(&stamped, Some(rate));
        let by_number = read(&numbered, Some(rate));
        assert!(by_time.valid_windows >= 2, "{}", by_time.valid_windows);
        assert_eq!(by_number.sample_numbers.as_deref(), Some("Sample Number"));
        assert_eq!(by_time.sample_numbers, None);
        assert_eq!(window_rows(&by_number), window_rows(&by_time), "{rate}");
        assert_eq!(
            (
                by_number.captured,
                by_number.accepted,
                by_number.glitches,
                by_number.missing
            ),
            (
                by_time.captured,
                by_time.accepted,
                by_time.glitches,
                by_time.missing
            )
        );
        // The time stamps without the rate: the same δ (the floor then takes the time grid).
        let unstated = read(&stamped, None);
        let deltas = |r: &AnalyzeReport| r.windows.iter().map(|w| w.delta).collect::<Vec<_>>();
        assert_eq!(deltas(&by_number), deltas(&unstated));
        let text = host_sim::app::analyze::text(&by_number);
        assert!(
            text.contains(&format!(
                "sample numbers of `Sample Number` over --sample-rate {rate} Hz"
            )),
            "{text}"
        );
        // A rate other than the capture's is another capture: every speed scaled by it.
        let doubled = read(&numbered, Some(2.0 * rate));
        let speed = |r: &AnalyzeReport| r.windows.iter().find_map(|w| w.omega_mean).unwrap();
        assert!((speed(&doubled) / speed(&by_number) - 2.0).abs() < 1e-3);
    }
    // Without the rate: refused, naming the column and the option.
    for head in ["Sample Number", "Sample", "Sample [#]", "sample number"] {
        let e = reader_error(&format!("{head}, Channel 0, Channel 1\n0, 0, 0\n5, 1, 0\n"));
        assert!(
            e.starts_with("cap.csv:1:")
                && e.contains(&format!("`{head}`"))
                && e.contains("--sample-rate"),
            "{e}"
        );
    }
    // A sample number with decimals, and rates that are none.
    let mut r = text_reader(
        "Sample Number, Channel 0\n0, 0\n12.5, 1\n".to_string(),
        "cap.csv",
        Some(1e6),
    )
    .unwrap();
    assert!(r.next_row().is_ok());
    let e = r.next_row().unwrap_err().to_string();
    assert!(
        e.starts_with("cap.csv:3:") && e.contains("`12.5`") && e.contains("`Sample Number`"),
        "{e}"
    );
    for bad in [0.0, -1e6, f64::NAN, f64::INFINITY] {
        let e = text_reader(
            "Sample Number, Channel 0\n0, 0\n".to_string(),
            "cap.csv",
            Some(bad),
        )
        .err()
        .unwrap()
        .to_string();
        assert!(
            e.contains("--sample-rate") && e.contains("above 0"),
            "{bad}: {e}"
        );
    }
    // libsigrok's `samples` unit is still sigrok's.
    let r = text_reader("samples,logic\n1,0\n".to_string(), "cap.csv", Some(1.0)).unwrap();
    assert_eq!(r.format(), CaptureFormat::Sigrok);
}

/// A file of edge times (one captured edge a row, in seconds: a capture timer's dump), with a
/// header naming the column or none, is read as the format `times` and gives the analysis of
/// a logic analyzer's record of the same edges; what it cannot hold is refused: an index, a
/// direction channel, an edge polarity, a unit other than seconds, whole numbers read as
/// seconds unless the header says so. `run` does not write it.
#[test]
fn a_file_of_edge_times_is_read_as_the_captured_edges() {
    use host_sim::app::analyze::{Channel, FramingArg, Polarity};
    // A 12-1 wheel near 52 rad/s with a first-order ripple, 12 revolutions.
    let pitch = 1e-3;
    let mut times = Vec::new();
    for k in 0..12 * 12 {
        if k % 12 == 11 {
            continue;
        }
        let a = f64::from(k) * std::f64::consts::TAU / 12.0;
        // The time at angle a: t = a/ω0 + ε sin(a)/ω0.
        let t = (f64::from(k) + 0.5 * (a.sin() / std::f64::consts::TAU * 12.0) * 0.05) * pitch;
        times.push((t * 1e6).round() * 1e-6);
    }
    let mut saleae = String::from("Time [s],Channel 0\n0.000000000,0\n");
    for &t in &times {
        saleae.push_str(&format!("{:.9},1\n{:.9},0\n", t + 1e-4, t + 4e-4));
    }
    let listed: String = times.iter().map(|t| format!("{:.6}\n", t + 1e-4)).collect();
    let analyze_text = |text: String, o: &AnalyzeOptions| {
        let cfg = configure(o).unwrap();
        let mut r = text_reader(text, "t.csv", None).unwrap_or_else(|e| panic!("{e}"));
        let format = r.format();
        (format, analyze(&mut r, &cfg, &mut |_| {}))
    };
    let o = wheel("12-1");
    let (_, from_levels) = analyze_text(saleae, &o);
    let from_levels = from_levels.unwrap();
    assert!(
        from_levels.valid_windows >= 8,
        "{}",
        from_levels.valid_windows
    );
    for text in [format!("time_s\n{listed}"), listed.clone()] {
        let (format, r) = analyze_text(text, &o);
        let r = r.unwrap();
        assert_eq!(format, CaptureFormat::Times);
        assert_eq!(
            (r.format, r.edge, r.channel.as_str()),
            ("times", "listed", "time_s")
        );
        assert_eq!(
            (
                r.captured,
                r.accepted,
                r.valid_windows,
                r.glitches,
                r.missing
            ),
            (
                from_levels.captured,
                from_levels.accepted,
                from_levels.valid_windows,
                0,
                0
            )
        );
        for (a, b) in r.windows.iter().zip(&from_levels.windows) {
            assert_eq!((a.start, a.delta), (b.start, b.delta));
        }
        let said = host_sim::app::analyze::text(&r);
        assert!(
            said.contains("channel: time_s (edge times: each row a captured edge)"),
            "{said}"
        );
    }
    // A uniform disc's times read as a wheel with a gap: the hint names no option the file
    // refuses.
    let uniform: String = (0..200)
        .map(|k| format!("{:.6}\n", f64::from(k) * 1e-3 + 1e-4))
        .collect();
    let (_, r) = analyze_text(uniform, &wheel("12-1"));
    let causes = r.unwrap().sync_hint.unwrap().causes;
    assert!(
        causes
            .iter()
            .any(|c| c.contains("no gap recurs") && c.contains("a uniform disc (use --lines N)"))
            && causes
                .iter()
                .all(|c| !c.contains("--edge") && !c.contains("--framing")),
        "{causes:?}"
    );
    // What the file cannot hold.
    let refused = |o: AnalyzeOptions| {
        analyze_text(listed.clone(), &o)
            .1
            .err()
            .unwrap()
            .to_string()
    };
    let e = refused(AnalyzeOptions {
        lines: Some(12),
        framing: Some(FramingArg::Index),
        ..AnalyzeOptions::default()
    });
    assert!(
        e.contains("no index channel") && e.contains("--framing none"),
        "{e}"
    );
    let e = refused(AnalyzeOptions {
        direction_channel: Some(Channel::Column(1)),
        ..wheel("12-1")
    });
    assert!(
        e.starts_with("--direction-channel: a file of edge times"),
        "{e}"
    );
    let e = refused(AnalyzeOptions {
        edge: Some(Polarity::Rising),
        ..wheel("12-1")
    });
    assert!(
        e.starts_with("--edge: a file of edge times") && e.contains("leave --edge out"),
        "{e}"
    );
    // Units: read in the one the header names (`time_us`), refused when it is none of s, ms,
    // us, ns; whole numbers only under a header (or --time-unit) stating the unit.
    let mut r = text_reader("time_us\n0.5\n2084\n".into(), "w.csv", None).unwrap();
    let mut read = Vec::new();
    while let Some((t, _)) = r.next_row().unwrap() {
        read.push(t);
    }
    assert_eq!(read, [0.5e-6, 2084e-6]);
    let e = reader_error("ticks\n5\n2084\n");
    assert!(
        e.starts_with("cap.csv:1:") && e.contains("in ticks") && e.contains("--time-unit"),
        "{e}"
    );
    let e = reader_error("0\n2084\n4146\n");
    assert!(
        e.starts_with("cap.csv:2:")
            && e.contains("`2084` is a whole number")
            && e.contains("give --time-unit ms, us or ns"),
        "{e}"
    );
    let mut r = text_reader("time_s\n0\n2\n4\n".into(), "w.csv", None).unwrap();
    let mut read = Vec::new();
    while let Some((t, _)) = r.next_row().unwrap() {
        read.push(t);
    }
    assert_eq!(read, [0.0, 2.0, 4.0]);
    let e = reader_error("time_s\n0.1\n0.2,1\n");
    assert!(
        e.starts_with("cap.csv:3:") && e.contains("one column"),
        "{e}"
    );
    // `run` writes levels, not edge times.
    let e = CaptureFormat::for_file(Path::new("x.csv"), Some(CaptureFormat::Times))
        .err()
        .unwrap();
    assert!(
        e.starts_with("--capture-format times:") && e.contains("saleae, sigrok"),
        "{e}"
    );
}

/// A transition that rings (the level crosses back and again within microseconds of each
/// rising edge) gives an edge just after every tooth: the core rejects each as a glitch and
/// every window is invalid. The report says what it is, how long the ringing lasts and what
/// cures it, where it had only counted the glitches; noise pulses between teeth are not called
/// ringing.
#[test]
fn ringing_at_each_edge_is_said_with_its_length() {
    // A 60-line disc at 2 ms a line, 8 revolutions, times to 0.1 µs; after a tooth's rise the
    // level falls after 1 µs to 3 µs and rises again 4 µs to 8 µs after it (by tooth).
    let capture = |ring_every: u32, noise_every: u32| {
        let mut rows: Vec<(f64, u8)> = Vec::new();
        for k in 0..480u32 {
            let t = f64::from(k) * 2e-3;
            rows.push((t, 1));
            // (From the ninth tooth: the core's sync is found on clean teeth.)
            if ring_every > 0 && k >= 8 && k % ring_every == 0 {
                let j = f64::from(k % 5);
                rows.push((t + (1.0 + 0.5 * j) * 1e-6, 0));
                rows.push((t + (4.0 + j) * 1e-6, 1));
            }
            rows.push((t + 1e-3, 0));
            if noise_every > 0 && k % noise_every == 3 {
                // A 2 µs noise pulse at 75 % of the tooth's interval.
                rows.push((t + 1.5e-3, 1));
                rows.push((t + 1.502e-3, 0));
            }
        }
        let mut text = String::from("Time [s],Channel 0\n0.0000000,0\n");
        for (t, l) in rows {
            text.push_str(&format!("{:.7},{l}\n", t + 1e-4));
        }
        let cfg = configure(&AnalyzeOptions {
            lines: Some(60),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut r = text_reader(text, "r.csv", None).unwrap();
        analyze(&mut r, &cfg, &mut |_| {}).unwrap()
    };
    let every = capture(1, 0);
    assert_eq!(every.valid_windows, 0);
    assert!(every.glitches >= 460, "{}", every.glitches);
    let g = every.ringing.clone().unwrap();
    assert!(g.edges >= 460 && g.of == every.captured, "{g:?}");
    // The longest: 8 µs, to the 0.1 µs of the times.
    assert!((g.longest - 8e-6).abs() < 2e-7, "{g:?}");
    let said = host_sim::app::analyze::text(&every);
    assert!(
        said.contains(&format!(
            "WARNING: `Channel 0` rings: {} of its {} captured edges came within 8.000e-6 s of \
             the edge before",
            g.edges, g.of
        )) && said.contains("input filter")
            && said.contains("here more than 8.000e-6 s"),
        "{said}"
    );
    // One tooth in ten rings: said as well.
    let some = capture(10, 0);
    assert!(
        some.ringing
            .as_ref()
            .is_some_and(|g| (46..=47).contains(&g.edges)),
        "{:?}",
        some.ringing
    );
    // Noise pulses between teeth, one tooth in ten: glitches, no ringing.
    let noise = capture(0, 10);
    assert!(noise.glitches >= 40, "{}", noise.glitches);
    assert_eq!(noise.ringing, None);
    // A clean disc: nothing.
    assert_eq!(capture(0, 0).ringing, None);
}

/// The other polarity of a ringing channel is no cure, and the ringing WARNING suggests none:
/// on one channel the levels alternate, so each extra crossing of the polarity read brings
/// one of the other, and the two polarities' edges differ by one at most. Where every tooth
/// rings the falling edges are a regular train at twice the lines, which reads clean (no
/// interval of a bounce's length, valid windows) at twice the true speed; where one tooth in
/// ten rings they hold noise pulses instead (glitches, no clean run of windows).
#[test]
fn the_other_polarity_of_a_ringing_channel_is_no_cure() {
    use host_sim::app::analyze::Polarity;
    // As in `ringing_at_each_edge_is_said_with_its_length`: a 60-line disc at 2 ms a line,
    // 8 revolutions; after a ringing tooth's rise the level falls 1 µs to 3 µs after it and
    // rises again 4 µs to 8 µs after it.
    let capture = |ring_every: u32, edge: Polarity| {
        let mut text = String::from("Time [s],Channel 0\n0.0000000,0\n");
        for k in 0..480u32 {
            let t = f64::from(k) * 2e-3 + 1e-4;
            text.push_str(&format!("{t:.7},1\n"));
            if k >= 8 && k % ring_every == 0 {
                let j = f64::from(k % 5);
                text.push_str(&format!("{:.7},0\n", t + (1.0 + 0.5 * j) * 1e-6));
                text.push_str(&format!("{:.7},1\n", t + (4.0 + j) * 1e-6));
            }
            text.push_str(&format!("{:.7},0\n", t + 1e-3));
        }
        let cfg = configure(&AnalyzeOptions {
            lines: Some(60),
            edge: Some(edge),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut r = text_reader(text, "r.csv", None).unwrap();
        analyze(&mut r, &cfg, &mut |_| {}).unwrap()
    };
    let truth = std::f64::consts::TAU / (60.0 * 2e-3);
    let mean_speed = |r: &AnalyzeReport| {
        let w: Vec<f64> = r
            .windows
            .iter()
            .filter(|w| w.valid)
            .filter_map(|w| w.omega_mean)
            .collect();
        w.iter().sum::<f64>() / w.len() as f64
    };
    for ring_every in [1u32, 10] {
        let rising = capture(ring_every, Polarity::Rising);
        let falling = capture(ring_every, Polarity::Falling);
        let ringing = rising.ringing.clone().unwrap();
        // One falling edge for each rising one, the bounces' included.
        assert!(
            rising.edges.abs_diff(falling.edges) <= 1,
            "{} {}",
            rising.edges,
            falling.edges
        );
        assert!(
            falling.edges >= 480 + ringing.edges - 1,
            "{}",
            falling.edges
        );
        let said = host_sim::app::analyze::text(&rising);
        assert!(
            said.contains("The edges of the other polarity are no cure")
                && !said.contains("--edge falling"),
            "{said}"
        );
        if ring_every == 1 {
            // Clean to every check on the intervals, and twice as fast as the shaft.
            assert_eq!(falling.ringing, None);
            assert!(falling.valid_windows >= 8, "{}", falling.valid_windows);
            let ratio = mean_speed(&falling) / truth;
            assert!((ratio - 2.0).abs() < 0.01, "{ratio}");
        } else {
            assert!(falling.glitches >= 20, "{}", falling.glitches);
            assert!(
                falling.invalid_windows > falling.valid_windows,
                "{falling:?}"
            );
        }
    }
}

/// The busier-channel hint under an input prescaler: both channels' edges are counted on the
/// lines, before the prescaler, and each count's revolutions are it over the lines a
/// revolution the hint states (the channel read's revolutions were its captured edges', a
/// prescaler-fold fewer, beside the busier channel's lines), and the prescaler is said.
#[test]
fn the_busier_channel_hint_counts_edges_in_one_unit_under_a_prescaler() {
    use host_sim::app::analyze::FramingArg;
    // A 1000-line index disc at 2 µs a line, 10 revolutions, its channels swapped; the
    // channel read pulses every 10 lines (a 100-line disc's signal on the wrong probe).
    let mut text = String::from("Time [s],Channel 0,Channel 1\n0.000000,0,0\n");
    for k in 0..10_000u32 {
        let t = f64::from(k) * 2e-6 + 1e-6;
        let read = u8::from(k % 10 == 7);
        text.push_str(&format!("{t:.7},{read},1\n{:.7},0,0\n", t + 1e-6));
    }
    // The number after `key` in `text`, up to the first character no number has.
    let number = |text: &str, key: &str| -> f64 {
        let at = text
            .find(key)
            .unwrap_or_else(|| panic!("no `{key}` in {text}"))
            + key.len();
        let digits: String = text[at..]
            .chars()
            .take_while(|c| c.is_ascii_digit() || *c == '.')
            .collect();
        digits
            .parse()
            .unwrap_or_else(|_| panic!("`{key}` in {text}"))
    };
    for prescaler in [1u8, 4] {
        let cfg = configure(&AnalyzeOptions {
            lines: Some(1000),
            framing: Some(FramingArg::Index),
            timer_hz: Some(100e6),
            prescaler: Some(prescaler),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut r = text_reader(text.clone(), "swap.csv", None).unwrap();
        let report = analyze(&mut r, &cfg, &mut |_| {}).unwrap();
        assert_eq!(report.sync_acquired, None);
        let said = report.sync_hint.unwrap().causes;
        let hint = said
            .iter()
            .find(|c| c.contains("the channel read, has"))
            .unwrap_or_else(|| panic!("{said:?}"));
        let read = number(hint, "the channel read, has ");
        let read_revs = number(hint, "edges (");
        let per_rev = number(hint, "revolutions of the configured wheel, ");
        let busier = number(hint, "`Channel 1` has ");
        let busier_revs = number(hint, &format!("`Channel 1` has {busier} ("));
        assert_eq!(
            (read, busier, per_rev),
            (1000.0, 10_000.0, 1000.0),
            "{hint}"
        );
        assert!((read / per_rev - read_revs).abs() <= 0.05, "{hint}");
        assert!((busier / per_rev - busier_revs).abs() <= 0.05, "{hint}");
        assert_eq!(
            hint.contains("before the input prescaler of 4, which captures 250 a revolution"),
            prescaler == 4,
            "{hint}"
        );
        assert!(
            hint.ends_with("read it with --channel 1 --index-channel 0"),
            "{hint}"
        );
    }
}

/// A channel that pulses once a revolution read as the encoder (a cam or index channel first
/// in the export, or the two swapped): the core does not sync, and the hint names the busier
/// channel as the encoder with the options that read it, where it said the capture was too
/// short (and, with a long revolution, that the shaft had stopped). A capture that is too
/// short is still said to be.
#[test]
fn a_channel_pulsing_once_a_revolution_read_as_the_encoder_names_the_encoder() {
    use host_sim::app::analyze::{Channel, FramingArg};
    // A 60-2 wheel on `Channel 1`, 1 ms a pitch, 30 revolutions; `Channel 0` pulses once a
    // revolution, at the fifth tooth.
    let mut text = String::from("Time [s],Channel 0,Channel 1\n0.000000,0,0\n");
    for rev in 0..30u32 {
        for pos in 0..58u32 {
            let t = f64::from(rev * 60 + pos) * 1e-3 + 1e-4;
            let cam = u8::from(pos == 4);
            text.push_str(&format!("{t:.6},{cam},1\n{:.6},0,0\n", t + 5e-4));
        }
    }
    let causes = |text: &str, o: AnalyzeOptions| {
        let cfg = configure(&o).unwrap();
        let mut r = text_reader(text.to_string(), "cam.csv", None).unwrap();
        let report = analyze(&mut r, &cfg, &mut |_| {}).unwrap();
        assert_eq!(report.sync_acquired, None);
        report.sync_hint.unwrap().causes
    };
    let said = causes(&text, wheel("60-2"));
    assert!(
        said[0].contains("`Channel 0`, the channel read, has 30 edges")
            && said[0].contains("where `Channel 1` has 1740 (30.0 revolutions)")
            && said[0].contains("pulses once every 58 edges of `Channel 1`")
            && said[0].ends_with("the encoder is likely `Channel 1`: read it with --channel 1"),
        "{said:?}"
    );
    assert!(
        said.iter()
            .all(|c| !c.contains("too short") && !c.contains("stopped")),
        "{said:?}"
    );
    // A 1000-line index disc at 2 µs a line with its channels swapped, framed by the index:
    // the index channel is the encoder.
    let mut text = String::from("Time [s],Channel 0,Channel 1\n0.000000,0,0\n");
    for k in 0..10_000u32 {
        let t = f64::from(k) * 2e-6 + 1e-6;
        let index = u8::from(k % 1000 == 7);
        text.push_str(&format!("{t:.7},{index},1\n{:.7},0,0\n", t + 1e-6));
    }
    let indexed = AnalyzeOptions {
        lines: Some(1000),
        framing: Some(FramingArg::Index),
        timer_hz: Some(100e6),
        ..AnalyzeOptions::default()
    };
    let said = causes(&text, indexed.clone());
    assert!(
        said[0].ends_with(
            "the encoder is likely `Channel 1`: read it with --channel 1 --index-channel 0"
        ) && said
            .iter()
            .all(|c| !c.contains("too short") && !c.contains("stopped")),
        "{said:?}"
    );
    // Read so, it syncs.
    let cfg = configure(&AnalyzeOptions {
        channel: Some(Channel::Column(1)),
        index_channel: Some(Channel::Column(0)),
        ..indexed
    })
    .unwrap();
    let mut r = text_reader(text, "swap.csv", None).unwrap();
    assert!(analyze(&mut r, &cfg, &mut |_| {}).unwrap().valid_windows >= 8);
    // One revolution of a 60-2 wheel and nothing else: too short.
    let mut text = String::from("Time [s],Channel 0\n0.000000,0\n");
    for pos in 0..58u32 {
        let t = f64::from(pos) * 1e-3 + 1e-4;
        text.push_str(&format!("{t:.6},1\n{:.6},0\n", t + 5e-4));
    }
    let said = causes(&text, wheel("60-2"));
    assert!(
        said.iter().any(|c| c.contains("the capture is too short")),
        "{said:?}"
    );
}

/// A 360-line disc whose index pulse rises at a line's rising edge, 0.05 pitch to either side
/// of it (a quadrature encoder's index gated with the lines' levels rises at one of their
/// edges): read on the rising edges, the index frames the count a line early or late, shown
/// as faults on clean lines, and the report says why and what cures it; read on the falling
/// edges the index lies mid-pitch, and every revolution is framed without a fault.
#[test]
fn an_index_at_a_line_edge_is_named_as_such() {
    use host_sim::app::analyze::Polarity;
    let (lines, omega, revolutions) = (360u32, 60.0, 24u32);
    let pitch = std::f64::consts::TAU / f64::from(lines) / omega;
    let mut changes: Vec<(f64, usize, u8)> = Vec::new();
    for k in 0..lines * revolutions {
        let t = 1e-3 + f64::from(k) * pitch;
        changes.push((t, 0, 1));
        changes.push((t + 0.5 * pitch, 0, 0));
        if k % lines == 0 {
            // To either side of the edge in turn, as jitter would have it at random.
            let r = k / lines;
            let side = if (r * 7 + r / 3) % 2 == 0 {
                0.05
            } else {
                -0.05
            };
            changes.push((t + side * pitch, 1, 1));
            changes.push((t + (side + 1.0) * pitch, 1, 0));
        }
    }
    changes.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut text = String::from("Time [s],Channel 0,Channel 1\n0.000000000,0,0\n");
    let mut levels = [0u8; 2];
    for (t, ch, level) in changes {
        levels[ch] = level;
        text.push_str(&format!(
            "{:.9},{},{}\n",
            sampled(t, 50e6),
            levels[0],
            levels[1]
        ));
    }
    let said_of = |edge: Option<Polarity>| {
        let cfg = configure(&AnalyzeOptions {
            edge,
            ..index_lines(360)
        })
        .unwrap();
        let mut reader = text_reader(text.clone(), "index-at-edge.csv", None).unwrap();
        let report = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
        (host_sim::app::analyze::text(&report), report)
    };
    let (said, report) = said_of(None);
    let p = report.index_period.unwrap();
    assert!(p.early_late.0 >= 2 && p.early_late.1 >= 2, "{p:?}");
    // Not told that the line count is wrong, where the count a capture short is the commonest.
    assert!(!said.contains("check the number of lines"), "{said}");
    assert!(
        said.lines().any(|l| l.starts_with("index: ")
            && l.contains("the index pulse comes at a line edge and falls to either side of it")
            && l.contains("capture the lines' other edge (--edge)")),
        "{said}"
    );
    let (said, report) = said_of(Some(Polarity::Falling));
    assert!(!said.contains("index pulse comes at a line edge"), "{said}");
    assert_eq!(report.index_period.unwrap().early_late, (0, 0));
    assert_eq!(
        (report.extra, report.missing, report.missing_frames),
        (0, 0, 0),
        "{said}"
    );
    assert_eq!(report.invalid_windows, 0, "{said}");
    assert!(report.valid_windows >= 20, "{said}");
}

/// How [`session_file`] writes a sigrok session file.
struct SessionLayout {
    /// The metadata's `[device 1]` keys before the probes (`capturefile`, `total probes`,
    /// `samplerate`, `unitsize`, ...), one `key=value` a line.
    keys: &'static str,
    /// The probe numbers (1-based) of the capture's channels, in order.
    probes: &'static [u32],
    /// Bytes a sample.
    unitsize: usize,
    /// A probe not read that toggles every 7 samples, when given.
    extra: Option<u32>,
    /// Bytes an entry.
    chunk: usize,
    deflated: bool,
    /// The entries written last first (the archive's order is not theirs).
    reversed: bool,
}

/// A window as [`window_rows`] gives it.
type WindowRow = (bool, Option<f64>, Option<f64>, u32, u32);

/// Each window as two analyses of one capture are compared: valid, δ, the floor with the
/// sampling, its first and last edge.
fn window_rows(r: &AnalyzeReport) -> Vec<WindowRow> {
    r.windows
        .iter()
        .map(|w| {
            (
                w.valid,
                w.delta,
                w.floor_with_sampling,
                w.start_edge,
                w.end_edge,
            )
        })
        .collect()
}

/// The error reading the capture file `path` (format told from it, `rate` as --sample-rate)
/// gives, opening it or at a row; empty when it reads to its end.
fn open_error(path: &Path, rate: Option<f64>) -> String {
    match CaptureReader::open(path, None, rate) {
        Err(e) => e.to_string(),
        Ok(mut r) => loop {
            match r.next_row() {
                Ok(Some(_)) => continue,
                Ok(None) => return String::new(),
                Err(e) => break e.to_string(),
            }
        },
    }
}

/// Writes `entries` as a zip archive at `path`, each stored or deflated.
fn zip_of(path: &Path, entries: &[(String, Vec<u8>)], deflated: bool) {
    use std::io::Write as _;
    let method = if deflated {
        zip::CompressionMethod::Deflated
    } else {
        zip::CompressionMethod::Stored
    };
    let options = zip::write::SimpleFileOptions::default().compression_method(method);
    let mut z = zip::ZipWriter::new(std::fs::File::create(path).unwrap());
    for (name, bytes) in entries {
        z.start_file(name.as_str(), options).unwrap();
        z.write_all(bytes).unwrap();
    }
    z.finish().unwrap();
}

/// The sigrok session file of the sigrok CSV capture `csv` (rows at changes, a 1 MHz time
/// column in microseconds, `(i+1)` for sample `i`), every sample of it, as `layout` says:
/// written independently of the reader, following libsigrok's srzip output module.
fn session_file(csv: &str, path: &Path, layout: &SessionLayout) {
    let mut words: Vec<u64> = Vec::new();
    let mut rows = csv.lines().filter(|l| !l.starts_with(';')).skip(1);
    let mut word = 0u64;
    for row in rows.by_ref() {
        let mut fields = row.split(',');
        let i = fields.next().unwrap().parse::<usize>().unwrap() - 1;
        while words.len() < i {
            words.push(word);
        }
        word = 0;
        for (&p, level) in layout.probes.iter().zip(fields) {
            if level == "1" {
                word |= 1 << (p - 1);
            }
        }
        words.truncate(i);
        words.push(word);
    }
    let mut bytes = Vec::new();
    for (i, w) in words.iter().enumerate() {
        let w = match layout.extra {
            Some(p) if (i / 7) % 2 == 1 => w | 1 << (p - 1),
            _ => *w,
        };
        bytes.extend_from_slice(&w.to_le_bytes()[..layout.unitsize]);
    }
    let mut probes: Vec<(u32, String)> = layout
        .probes
        .iter()
        .enumerate()
        .map(|(k, &p)| (p, format!("D{k}")))
        .collect();
    if let Some(p) = layout.extra {
        probes.push((p, "spare".into()));
    }
    let mut metadata = format!(
        "[global]\nsigrok version=0.5.2\n\n[device 1]\n{}",
        layout.keys
    );
    for (p, name) in probes {
        metadata.push_str(&format!("probe{p}={name}\n"));
    }
    let mut entries = vec![
        ("version".to_string(), b"2".to_vec()),
        ("metadata".to_string(), metadata.into_bytes()),
    ];
    let mut chunks: Vec<(String, Vec<u8>)> = bytes
        .chunks(layout.chunk)
        .enumerate()
        .map(|(k, c)| (format!("logic-1-{}", k + 1), c.to_vec()))
        .collect();
    if layout.reversed {
        chunks.reverse();
    }
    entries.extend(chunks);
    zip_of(path, &entries, layout.deflated);
}

/// A sigrok session file (PulseView's .sr) reads as libsigrok's CSV export of the same samples:
/// the same windows, δ, floors and counts, whether its entries are deflated or stored, with
/// samples of one or two bytes, straddling two entries or not, entries in the archive out of
/// their order, and a channel not read toggling among them.
#[test]
fn a_sigrok_session_file_reads_as_its_csv_export() {
    let (_scratch, csv) = tmp("disc.csv");
    simulate(
        &index_disc(1.0).replace("sample_rate = 10e6", "sample_rate = 1e6\ndedup = true"),
        CaptureFormat::Sigrok,
        &csv,
    );
    let text = std::fs::read_to_string(&csv).unwrap();
    let cfg = configure(&index_lines(24)).unwrap();
    let read = |file: &Path| {
        let mut r = CaptureReader::open(file, None, None).unwrap_or_else(|e| panic!("{e}"));
        let channels = r.channels().to_vec();
        let format = r.format();
        let report = analyze(&mut r, &cfg, &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
        (format, channels, report)
    };
    let (format, channels, by_csv) = read(&csv);
    assert_eq!(format, CaptureFormat::Sigrok);
    assert_eq!(channels, ["D0", "D1"]);
    assert!(by_csv.valid_windows >= 2, "{}", by_csv.valid_windows);
    let summary = |r: &AnalyzeReport| {
        (
            window_rows(r),
            (r.rows, r.captured, r.accepted, r.glitches, r.missing),
            (r.index_pulses, r.sample_rate, r.span),
        )
    };
    let one = "capturefile=logic-1\ntotal probes=8\nsamplerate=1 MHz\ntotal analog=0\nunitsize=1\n";
    let two = "capturefile=logic-1\ntotal probes=16\nsamplerate=1 MHz\nunitsize=2\n";
    let layouts = [
        SessionLayout {
            keys: one,
            probes: &[1, 2],
            unitsize: 1,
            extra: None,
            chunk: 1 << 20,
            deflated: true,
            reversed: false,
        },
        SessionLayout {
            keys: one,
            probes: &[1, 2],
            unitsize: 1,
            extra: None,
            chunk: 40_000,
            deflated: false,
            reversed: true,
        },
        SessionLayout {
            keys: two,
            probes: &[3, 12],
            unitsize: 2,
            extra: Some(16),
            chunk: 65_537,
            deflated: true,
            reversed: true,
        },
    ];
    for (k, layout) in layouts.iter().enumerate() {
        let sr = csv.with_file_name(format!("disc{k}.sr"));
        session_file(&text, &sr, layout);
        let (format, channels, by_sr) = read(&sr);
        assert_eq!(format, CaptureFormat::Sr);
        assert_eq!(by_sr.format, "sr");
        let mut expected = vec!["D0".to_string(), "D1".to_string()];
        if layout.extra.is_some() {
            expected.push("spare".into());
        }
        assert_eq!(channels, expected, "layout {k}");
        let (sr_windows, sr_counts, sr_rest) = summary(&by_sr);
        let (csv_windows, csv_counts, csv_rest) = summary(&by_csv);
        assert_eq!(sr_windows, csv_windows, "layout {k}");
        assert_eq!(sr_rest, csv_rest, "layout {k}");
        if layout.extra.is_none() {
            // (A toggling channel not read adds rows, not edges.)
            assert_eq!(sr_counts, csv_counts, "layout {k}");
        } else {
            assert_eq!(
                (sr_counts.1, sr_counts.2, sr_counts.3, sr_counts.4),
                (csv_counts.1, csv_counts.2, csv_counts.3, csv_counts.4)
            );
            assert!(sr_counts.0 > csv_counts.0);
        }
    }
}

/// What is wrong with a session file is said, naming the entry or the key: never a guess.
#[test]
fn a_sigrok_session_file_is_refused_naming_what_is_wrong() {
    let (_scratch, path) = tmp("bad.sr");
    let samples: Vec<u8> = (0..4000u32).map(|i| u8::from(i % 100 < 50)).collect();
    let meta = |keys: &str| format!("[global]\nsigrok version=0.5.2\n[device 1]\n{keys}");
    let good = "capturefile=logic-1\ntotal probes=8\nsamplerate=1 MHz\nunitsize=1\nprobe1=D0\n";
    let error = |version: &str, metadata: Option<String>, chunks: &[(&str, &[u8])], rate| {
        let mut entries = vec![("version".to_string(), version.as_bytes().to_vec())];
        if let Some(m) = metadata {
            entries.push(("metadata".to_string(), m.into_bytes()));
        }
        entries.extend(chunks.iter().map(|(n, b)| (n.to_string(), b.to_vec())));
        zip_of(&path, &entries, true);
        open_error(&path, rate)
    };
    let data: &[(&str, &[u8])] = &[("logic-1-1", &samples)];
    // The good file reads, also as version 1 with one entry `logic-1`.
    assert_eq!(error("2", Some(meta(good)), data, None), "");
    assert_eq!(
        error("1", Some(meta(good)), &[("logic-1", &samples)], None),
        ""
    );
    // (version, metadata, entries of samples, --sample-rate, what the error says)
    type Case<'a> = (
        &'a str,
        Option<String>,
        &'a [(&'a str, &'a [u8])],
        Option<f64>,
    );
    let cases: [(Case, &[&str]); 10] = [
        (
            ("2", None, data, None),
            &["without the `version` and `metadata`"],
        ),
        (
            ("3", Some(meta(good)), data, None),
            &["version `3`", "1 and 2"],
        ),
        (
            (
                "2",
                Some(meta(&good.replace("samplerate=1 MHz\n", ""))),
                data,
                None,
            ),
            &["states no samplerate", "--sample-rate"],
        ),
        (
            ("2", Some(meta(&good.replace("1 MHz", "0 Hz"))), data, None),
            &["states no samplerate"],
        ),
        (
            ("2", Some(meta(good)), data, Some(2e6)),
            &["samplerate = 1 MHz", "--sample-rate is 2000000 Hz"],
        ),
        (
            (
                "2",
                Some(meta(&good.replace("unitsize=1\n", ""))),
                data,
                None,
            ),
            &["no `unitsize`"],
        ),
        (
            (
                "2",
                Some(meta("total analog=1\nsamplerate=1 MHz\nanalog2=A0\n")),
                &[],
                None,
            ),
            &["no `capturefile`", "analog"],
        ),
        (
            (
                "2",
                Some(meta(&good.replace("probe1=D0", "probe9=D8"))),
                data,
                None,
            ),
            &["`probe9 = D8`", "probes 1 to 8"],
        ),
        (
            (
                "2",
                Some(meta(&good.replace("unitsize=1", "unitsize=2"))),
                &[("logic-1-1", &samples[..3999])],
                None,
            ),
            &["1 byte(s) into a sample of 2", "cut off"],
        ),
        (
            ("2", Some(meta(good)), &[], None),
            &["no `logic-1-1`", "no samples"],
        ),
    ];
    for ((version, metadata, chunks, rate), says) in cases {
        let e = error(version, metadata.clone(), chunks, rate);
        assert!(
            says.iter().all(|s| e.contains(s)) && e.starts_with(&path.display().to_string()),
            "{metadata:?}: {e}"
        );
    }
    // A session file given another format, and a text file given `sr`.
    let wrong = CaptureReader::open(&path, Some(CaptureFormat::Vcd), None)
        .err()
        .unwrap();
    assert!(
        wrong
            .to_string()
            .contains("--format vcd: the file is a zip archive"),
        "{wrong}"
    );
    let (_s, csv) = tmp("x.csv");
    std::fs::write(&csv, "time_s,level\n0,0\n").unwrap();
    let wrong = CaptureReader::open(&csv, Some(CaptureFormat::Sr), None)
        .err()
        .unwrap();
    assert!(
        wrong
            .to_string()
            .contains("--format sr: the file is not a zip archive"),
        "{wrong}"
    );
    // Written by `run`: refused, naming what it writes instead.
    for (file, given) in [("x.sr", None), ("x.csv", Some(CaptureFormat::Sr))] {
        let e = CaptureFormat::for_file(Path::new(file), given).unwrap_err();
        assert!(
            e.contains("not a sigrok session file") && e.contains(".vcd"),
            "{e}"
        );
    }
}

/// A session file written by libsigrok itself (`sigrok-cli -i … -I vcd -o … .sr`, see
/// `tests/data/README.md`) reads as the value change dump it was converted from: the same
/// rows, windows, δ and counts; its last sample, the end of the recording, one sample period
/// before the dump's closing time.
#[test]
fn a_session_file_written_by_libsigrok_reads_as_the_dump_it_came_from() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let cfg = configure(&index_lines(24)).unwrap();
    let read = |name: &str| {
        let mut r = CaptureReader::open(&data.join(name), None, None).unwrap();
        assert_eq!(r.channels(), ["encoder", "index"], "{name}");
        assert_eq!(r.sample_rate(), Some(1e6), "{name}");
        analyze(&mut r, &cfg, &mut |_| {}).unwrap()
    };
    let (sr, vcd) = (read("disc-100rads.sr"), read("disc-100rads.vcd"));
    assert_eq!((sr.format, vcd.format), ("sr", "vcd"));
    assert_eq!(sr.valid_windows, 4);
    let windows = |r: &AnalyzeReport| {
        r.windows
            .iter()
            .map(|w| {
                (
                    w.valid,
                    w.delta,
                    w.omega_mean,
                    w.floor_with_sampling,
                    w.start_edge,
                )
            })
            .collect::<Vec<_>>()
    };
    assert_eq!(windows(&sr), windows(&vcd));
    assert_eq!(
        (sr.rows, sr.edges, sr.accepted, sr.index_pulses, sr.span[0]),
        (
            vcd.rows,
            vcd.edges,
            vcd.accepted,
            vcd.index_pulses,
            vcd.span[0]
        )
    );
    assert_eq!((sr.span[1], vcd.span[1]), (0.399999, 0.4));
}

/// Writes Saleae Logic 2's binary export of the Saleae CSV capture `csv` (rows at changes,
/// `Time [s],Channel 0,Channel 1`) into the folder `dir`, a file `digital_N.bin` a channel, as
/// Saleae documents the format: version 0, or version 1 at `rate` Hz with the channel
/// `gap_channel` without data over `gap` s (two chunks). Written independently of the reader.
fn saleae_binary(csv: &str, dir: &Path, version: i32, rate: f64, gap: Option<(usize, [f64; 2])>) {
    let rows: Vec<(f64, Vec<bool>)> = csv
        .lines()
        .skip(1)
        .map(|l| {
            let mut f = l.split(',');
            let t = f.next().unwrap().parse::<f64>().unwrap();
            (t, f.map(|v| v == "1").collect())
        })
        .collect();
    let (begin, end) = (rows[0].0, rows[rows.len() - 1].0);
    std::fs::create_dir_all(dir).unwrap();
    for ch in 0..rows[0].1.len() {
        let level_at = |k: usize| rows[k].1[ch];
        let changes: Vec<f64> = (1..rows.len())
            .filter(|&k| level_at(k) != level_at(k - 1))
            .map(|k| rows[k].0)
            .collect();
        // Chunks: (initial level, begin, end, transitions).
        let mut chunks = vec![(level_at(0), begin, end, changes.clone())];
        if let Some((c, [from, to])) = gap.filter(|&(c, _)| c == ch) {
            let level_after = |t: f64| rows.iter().rev().find(|r| r.0 <= t).unwrap().1[ch];
            chunks = vec![
                (
                    level_at(0),
                    begin,
                    from,
                    changes.iter().copied().filter(|&t| t <= from).collect(),
                ),
                (
                    level_after(to),
                    to,
                    end,
                    changes.iter().copied().filter(|&t| t > to).collect(),
                ),
            ];
            assert_eq!(c, ch);
        }
        let mut b: Vec<u8> = b"<SALEAE>".to_vec();
        b.extend(version.to_le_bytes());
        b.extend(0i32.to_le_bytes());
        if version == 1 {
            b.extend((chunks.len() as u64).to_le_bytes());
        }
        for (initial, from, to, times) in &chunks {
            b.extend(u32::from(*initial).to_le_bytes());
            if version == 1 {
                b.extend(rate.to_le_bytes());
            }
            b.extend(from.to_le_bytes());
            b.extend(to.to_le_bytes());
            b.extend((times.len() as u64).to_le_bytes());
            for t in times {
                b.extend(t.to_le_bytes());
            }
        }
        std::fs::write(dir.join(format!("digital_{ch}.bin")), b).unwrap();
    }
}

/// Saleae Logic 2's binary export (a file a channel) reads as its CSV export of the same
/// capture: the same windows, δ (to the rounding of the times, which the CSV writes in decimals
/// and the export as doubles) and counts, from the folder; one channel's file alone is that
/// channel; a chunk gap of version 1 is a span without data, as Logic 2's CSV `X` is.
#[test]
fn a_saleae_binary_export_reads_as_its_csv_export() {
    let (_scratch, csv) = tmp("disc.csv");
    simulate(&index_disc(1.0), CaptureFormat::Saleae, &csv);
    let text = std::fs::read_to_string(&csv).unwrap();
    let cfg = configure(&index_lines(24)).unwrap();
    let read = |path: &Path, cfg: &host_sim::app::analyze::AnalyzeConfig| {
        let mut r = CaptureReader::open(path, None, None).unwrap_or_else(|e| panic!("{e}"));
        let channels = r.channels().to_vec();
        let report = analyze(&mut r, cfg, &mut |_| {}).unwrap_or_else(|e| panic!("{e}"));
        (channels, report)
    };
    let (_, by_csv) = read(&csv, &cfg);
    assert!(by_csv.valid_windows >= 4, "{}", by_csv.valid_windows);
    let close = |a: &AnalyzeReport, b: &AnalyzeReport| {
        assert_eq!(a.windows.len(), b.windows.len());
        for (x, y) in a.windows.iter().zip(&b.windows) {
            assert_eq!(
                (x.valid, x.start_edge, x.end_edge),
                (y.valid, y.start_edge, y.end_edge)
            );
            match (x.delta, y.delta) {
                (Some(p), Some(q)) => assert!((p - q).abs() <= 1e-9 * q, "{p} {q}"),
                (p, q) => assert_eq!(p, q),
            }
        }
        assert_eq!(
            (a.rows, a.edges, a.accepted, a.glitches, a.index_pulses),
            (b.rows, b.edges, b.accepted, b.glitches, b.index_pulses)
        );
    };
    for version in [0, 1] {
        let dir = csv.with_file_name(format!("v{version}"));
        saleae_binary(&text, &dir, version, 10e6, None);
        let (channels, by_bin) = read(&dir, &cfg);
        assert_eq!(channels, ["Channel 0", "Channel 1"]);
        assert_eq!(by_bin.format, "saleae-binary");
        assert_eq!(by_bin.sample_rate, (version == 1).then_some(10e6));
        close(&by_bin, &by_csv);
    }
    // One channel's file: that channel alone (framed by nothing).
    let lines = AnalyzeOptions {
        lines: Some(24),
        ..AnalyzeOptions::default()
    };
    let one = configure(&lines).unwrap();
    let (channels, alone) = read(&csv.with_file_name("v0").join("digital_0.bin"), &one);
    assert_eq!(channels, ["Channel 0"]);
    let (_, from_csv) = read(&csv, &one);
    assert_eq!(alone.edges, from_csv.edges);
    // A gap of version 1 on the encoder channel: a span without data, where the CSV says `X`.
    let dir = csv.with_file_name("gap");
    saleae_binary(&text, &dir, 1, 10e6, Some((0, [0.4, 0.5])));
    let (_, gapped) = read(&dir, &cfg);
    let no_data = gapped.no_data.as_ref().expect("a span without data");
    assert_eq!((no_data.spans, no_data.first), (1, [0.4, 0.5]));
    assert!(gapped.edges < by_csv.edges);
}

/// What is wrong with a binary export is said, naming the file.
#[test]
fn a_saleae_binary_export_is_refused_naming_what_is_wrong() {
    let (_scratch, dir) = tmp("export");
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("digital_0.bin");
    let header = |version: i32, kind: i32| {
        let mut b = b"<SALEAE>".to_vec();
        b.extend(version.to_le_bytes());
        b.extend(kind.to_le_bytes());
        b
    };
    let v0 = |times: &[f64], n: u64, end: f64| {
        let mut b = header(0, 0);
        b.extend(1u32.to_le_bytes());
        b.extend(0.0f64.to_le_bytes());
        b.extend(end.to_le_bytes());
        b.extend(n.to_le_bytes());
        for t in times {
            b.extend(t.to_le_bytes());
        }
        b
    };
    let error = |bytes: Vec<u8>| {
        std::fs::write(&file, bytes).unwrap();
        open_error(&file, None)
    };
    assert_eq!(error(v0(&[0.1, 0.2], 2, 1.0)), "");
    for (bytes, says) in [
        (header(0, 1), "type 1 (analog)"),
        (header(2, 0), "version 2"),
        (v0(&[0.1, 0.2], 3, 1.0), "ends before a transition's time"),
        (v0(&[0.2, 0.1], 2, 1.0), "before the one before it"),
        (v0(&[0.1, 2.0], 2, 1.0), "after its chunk's end"),
        (v0(&[0.1, f64::NAN], 2, 1.0), "a transition's time is NaN"),
        (
            v0(&[0.1, 0.2, 0.3], 2, 1.0),
            "bytes after its last transition",
        ),
        (header(0, 0)[..12].to_vec(), "shorter than the header"),
    ] {
        let e = error(bytes);
        assert!(
            e.contains(says) && e.contains("digital_0.bin"),
            "{says}: {e}"
        );
    }
    // A folder without a digital channel's export, and a CSV given the format.
    std::fs::remove_file(&file).unwrap();
    std::fs::write(dir.join("notes.txt"), "x").unwrap();
    let e = CaptureReader::open(&dir, None, None)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("without a digital channel's binary export"),
        "{e}"
    );
    let (_s, csv) = tmp("x.csv");
    std::fs::write(&csv, "time_s,level\n0,0\n").unwrap();
    let e = CaptureReader::open(&csv, Some(CaptureFormat::SaleaeBinary), None)
        .err()
        .unwrap()
        .to_string();
    assert!(e.contains("does not start with `<SALEAE>`"), "{e}");
    let e = CaptureFormat::for_file(Path::new("x.bin"), None).unwrap_err();
    assert!(e.contains("not Saleae's binary export"), "{e}");
}

/// An analog record (an oscilloscope's CSV of a variable-reluctance sensor before its
/// comparator: a sine a tooth, its amplitude growing with the speed, with noise) read through
/// `--threshold` and `--hysteresis`: every valid window's δ matches the truth (the teeth's
/// crossing times solved from the rotor's angle) within the floor analyze states; without the
/// hysteresis the noise at each crossing is a glitch; and without the threshold the values are
/// refused, naming the options.
#[test]
fn an_analog_record_is_read_through_a_threshold() {
    use rand::{Rng, SeedableRng};
    // φ(t) = ω̄t + b·sin(2ω̄t): ω = ω̄(1 + 2b·cos(2ω̄t)), δ = 4b.
    let (omega, b, lines, rate) = (40.0f64, 0.025f64, 24u32, 200e3);
    let phi = |t: f64| omega * t + b * (2.0 * omega * t).sin();
    // Noise of σ `noise` (a sum of 12 uniforms): 0.0005 moves a crossing by 0.5 µs (σ), a
    // tenth of a sample; 0.02 by 20 µs, which the floor (the timing's alone) does not hold.
    let (_scratch, dir) = tmp("vr");
    std::fs::create_dir_all(&dir).unwrap();
    let record = |noise: f64| {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut text = String::from("time_s,level\n");
        for i in 0..(rate as usize) {
            let t = i as f64 / rate;
            let speed = 1.0 + 2.0 * b * (2.0 * omega * t).cos();
            let n: f64 = (0..12).map(|_| rng.gen::<f64>()).sum::<f64>() - 6.0;
            let v = speed * (f64::from(lines) * phi(t)).sin() + noise * n;
            text.push_str(&format!("{t:.6},{v:.4}\n"));
        }
        let file = dir.join(format!("vr-{noise}.csv"));
        std::fs::write(&file, &text).unwrap();
        file
    };
    let (quiet, noisy) = (record(0.0005), record(0.02));
    let cfg = configure(&AnalyzeOptions {
        lines: Some(lines as u16),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let read = |file: &Path, hysteresis: f64| {
        let mut r = CaptureReader::open(file, None, None).unwrap();
        r.set_threshold(host_sim::app::logic::Threshold::new(0.0, hysteresis).unwrap())
            .unwrap();
        analyze(&mut r, &cfg, &mut |_| {}).unwrap()
    };
    let report = read(&quiet, 0.4);
    assert_eq!(report.glitches, 0);
    assert!(report.valid_windows >= 4, "{}", report.valid_windows);
    // A rising crossing is where the sine reaches +0.2 (half the hysteresis) on its way up:
    // tooth k at lines·φ = 2πk + asin(0.2/speed), solved by Newton's method.
    let crossing = |k: u32, guess: f64| {
        let mut t = guess;
        for _ in 0..50 {
            let speed = 1.0 + 2.0 * b * (2.0 * omega * t).cos();
            let target = std::f64::consts::TAU * f64::from(k) + (0.2 / speed).asin();
            let f = f64::from(lines) * phi(t) - target;
            let df = f64::from(lines) * omega * speed;
            t -= f / df;
        }
        t
    };
    let pitch = std::f64::consts::TAU / f64::from(lines);
    let teeth: Vec<f64> = (0..200)
        .map(|k| crossing(k, f64::from(k) * pitch / omega))
        .collect();
    for w in report.windows.iter().filter(|w| w.valid) {
        let speeds: Vec<f64> = teeth
            .windows(2)
            .filter(|p| p[1] > w.start + 3e-6 && p[1] <= w.end + 3e-6)
            .map(|p| pitch / (p[1] - p[0]))
            .collect();
        let (lo, hi) = speeds
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(l, h), &s| (l.min(s), h.max(s)));
        let truth = 2.0 * (hi - lo) / (hi + lo);
        let (delta, floor) = (w.delta.unwrap(), w.floor_with_sampling.unwrap());
        assert_eq!(speeds.len(), lines as usize);
        assert!(
            (delta - truth).abs() <= floor,
            "δ {delta} against {truth}, floor {floor}"
        );
        assert!((truth - 4.0 * b).abs() < 0.01, "{truth}");
    }
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("--threshold 0 with --hysteresis 0.4"),
        "{said}"
    );
    // Noise at a crossing crosses again without the hysteresis, not with it.
    assert!(read(&noisy, 0.0).glitches > 0);
    assert_eq!(read(&noisy, 0.4).glitches, 0);
    // No threshold: the values are refused, naming the options.
    let mut r = CaptureReader::open(&quiet, None, None).unwrap();
    let e = r.next_row().err().unwrap().to_string();
    assert!(
        e.contains("not a logic level")
            && e.contains("--threshold V")
            && e.contains("--hysteresis"),
        "{e}"
    );
    // A format that records levels takes no threshold.
    let (_s, vcd) = tmp("x.vcd");
    simulate(&index_disc(0.2), CaptureFormat::Vcd, &vcd);
    let mut r = CaptureReader::open(&vcd, None, None).unwrap();
    let e = r
        .set_threshold(host_sim::app::logic::Threshold::new(0.0, 0.1).unwrap())
        .unwrap_err()
        .to_string();
    assert!(e.contains("a vcd file records levels"), "{e}");
}

/// A channel that rings at the transitions of the polarity NOT read: each falling transition
/// crosses back and again within microseconds, and the crossing back is a rising edge, half a
/// pitch after the tooth's. The rising edges read then come twice a tooth, evenly enough for
/// the core to take them as teeth: valid windows at twice the shaft's speed, which nothing
/// said. Now a WARNING names the ringing polarity; noise pulses between teeth and a clean disc
/// give none, and read on the ringing polarity the capture gets the ringing WARNING instead.
#[test]
fn ringing_on_the_polarity_not_read_is_said() {
    // A 60-line disc at 2 ms a line (52.36 rad/s), 8 revolutions, times to 0.1 µs; after a
    // tooth's fall the level rises after 3 µs and falls again at 4 µs.
    let capture =
        |bounce: bool, noise_every: u32, edge: Option<host_sim::app::analyze::Polarity>| {
            let mut rows: Vec<(f64, u8)> = Vec::new();
            for k in 0..480u32 {
                let t = f64::from(k) * 2e-3;
                rows.push((t, 1));
                rows.push((t + 1e-3, 0));
                if bounce {
                    rows.push((t + 1.003e-3, 1));
                    rows.push((t + 1.004e-3, 0));
                }
                if noise_every > 0 && k % noise_every == 3 {
                    // A 2 µs noise pulse at 75 % of the tooth's interval.
                    rows.push((t + 1.5e-3, 1));
                    rows.push((t + 1.502e-3, 0));
                }
            }
            let mut text = String::from("Time [s],Channel 0\n0.0000000,0\n");
            for (t, l) in rows {
                text.push_str(&format!("{:.7},{l}\n", t + 1e-4));
            }
            let cfg = configure(&AnalyzeOptions {
                lines: Some(60),
                edge,
                ..AnalyzeOptions::default()
            })
            .unwrap();
            let mut r = text_reader(text, "r.csv", None).unwrap();
            analyze(&mut r, &cfg, &mut |_| {}).unwrap()
        };
    let omega = std::f64::consts::TAU / 60.0 / 2e-3;
    let bounced = capture(true, 0, None);
    // What the WARNING is for: valid windows at twice the shaft's speed.
    let doubled = bounced
        .windows
        .iter()
        .filter(|w| w.valid)
        .filter_map(|w| w.omega_mean)
        .collect::<Vec<_>>();
    assert!(
        !doubled.is_empty() && doubled.iter().all(|w| (w / omega - 2.0).abs() < 0.01),
        "{doubled:?}"
    );
    assert_eq!(bounced.ringing, None);
    let g = bounced.ringing_other_polarity.clone().unwrap();
    assert!(g.edges >= 470 && g.of >= 958, "{g:?}");
    // The longest: 4 µs, to the 0.1 µs of the times.
    assert!((g.longest - 4e-6).abs() < 2e-7, "{g:?}");
    let said = host_sim::app::analyze::text(&bounced);
    assert!(
        said.contains(&format!(
            "WARNING: `Channel 0` rings at its falling transitions: {} of its {} falling edges \
             came within 4.000e-6 s",
            g.edges, g.of
        )) && said.contains("twice the teeth's")
            && said.contains("`--edge falling`"),
        "{said}"
    );
    // Read on the falling edges: the ringing of the polarity read, said as such.
    let falling = capture(true, 0, Some(host_sim::app::analyze::Polarity::Falling));
    assert!(falling.ringing.is_some() && falling.ringing_other_polarity.is_none());
    // Noise pulses between teeth (one tooth in ten), and a clean disc: nothing.
    let noise = capture(false, 10, None);
    assert!(noise.glitches >= 40, "{}", noise.glitches);
    assert_eq!(noise.ringing_other_polarity, None);
    assert_eq!(capture(false, 0, None).ringing_other_polarity, None);
}

/// One tooth's edge moved 30 % of a pitch early (a noise pulse that merged with the tooth) on
/// a 1024-line disc at a constant 150 rad/s: the core takes it (its intervals are within the
/// accept band), and the window holding it read δ 0.60 valid and resolved where the shaft's
/// is 0, with no word. The window is now marked with the edge and how far off it lies, and a
/// WARNING says so; with 16-edge samples (δ 0.037 from it) as well. A shaft whose speed swings
/// smoothly (3 % at order 2, and 40 % at order 2 on a 36-2 wheel) has no edge marked.
#[test]
fn a_window_whose_delta_one_displaced_edge_makes_is_marked() {
    // Rising edges of `lines` lines at angle θ_k, the shaft at ω(φ) = ω̄·(1 + a·sin 2φ): the
    // time of angle φ by Simpson's rule on a fine grid (exact enough: 1e-12 s).
    let edges = |lines: u32, missing: u32, a: f64, moved: Option<(usize, f64)>| {
        let omega = |phi: f64| 150.0 * (1.0 + a * (2.0 * phi).sin());
        let pitch = std::f64::consts::TAU / f64::from(lines);
        let mut times = Vec::new();
        let (mut t, mut phi) = (1e-3, 0.0);
        for k in 0..lines * 8 {
            if k % lines < lines - missing {
                times.push(t);
            }
            let n = 64;
            let h = pitch / f64::from(n);
            let mut sum = 0.0;
            for j in 0..=n {
                let w = if j == 0 || j == n {
                    1.0
                } else if j % 2 == 1 {
                    4.0
                } else {
                    2.0
                };
                sum += w / omega(phi + f64::from(j) * h);
            }
            t += sum * h / 3.0;
            phi += pitch;
        }
        if let Some((i, f)) = moved {
            let d = times[i] - times[i - 1];
            times[i] -= f * d;
        }
        times
    };
    let analyzed = |times: &[f64], options: AnalyzeOptions| {
        let text = saleae_of_rising(times, 1e9, times.last().unwrap() + 1e-3);
        let cfg = configure(&options).unwrap();
        let mut r = text_reader(text, "d.csv", Some(1e9)).unwrap();
        analyze(&mut r, &cfg, &mut |_| {}).unwrap()
    };
    let disc = |k: u16| AnalyzeOptions {
        lines: Some(1024),
        estimator_edges: Some(k),
        ..AnalyzeOptions::default()
    };
    let moved = edges(1024, 0, 0.0, Some((5130, 0.3)));
    let at = moved[5130];
    for (k, delta) in [(1u16, 0.6), (16, 0.6 / 16.0)] {
        let r = analyzed(&moved, disc(k));
        let marked: Vec<_> = r
            .windows
            .iter()
            .filter(|w| w.displaced_edge.is_some())
            .collect();
        assert_eq!(marked.len(), 1, "K {k}: {:?}", r.windows);
        let (w, e) = (marked[0], marked[0].displaced_edge.unwrap());
        assert!(
            (e.pitches - 0.3).abs() < 0.01 && (e.time - at).abs() < 2e-9,
            "{e:?}"
        );
        // What it marks: δ made by that edge, 2·f/K.
        assert!(
            (w.delta.unwrap() / delta - 1.0).abs() < 0.05,
            "K {k}: {:?}",
            w.delta
        );
        let e = r.displaced_edges.unwrap();
        // (The capture's times are on a 1 ns grid.)
        assert!(e.windows == 1 && (e.first - at).abs() < 2e-9, "{e:?}");
        let said = host_sim::app::analyze::text(&r);
        assert!(
            said.contains("WARNING: in 1 valid window(s) one edge lies off the line")
                && said.contains(&format!(
                    ", δ from one edge 30.0 % of a pitch off at {at:.6} s"
                )),
            "{said}"
        );
    }
    // Smooth swings of the speed: nothing marked.
    let r = analyzed(&edges(1024, 0, 0.03, None), disc(1));
    assert!(
        r.valid_windows >= 6 && r.displaced_edges.is_none(),
        "{} {:?}",
        r.valid_windows,
        r.displaced_edges
    );
    let wheel = AnalyzeOptions {
        wheel: Some("36-2".into()),
        ..AnalyzeOptions::default()
    };
    let r = analyzed(&edges(36, 2, 0.4, None), wheel);
    assert!(
        r.valid_windows >= 4 && r.displaced_edges.is_none(),
        "{} {:?}",
        r.valid_windows,
        r.displaced_edges
    );
}

/// A direction channel that hardly changes (the index channel named by mistake, or B not
/// connected): every edge of A came with no step forward of the quadrature count and was fed
/// as reverse, and the only hint on a wheel said no gap recurs. A WARNING now names the
/// channel and its changes against the captures; the real B gets none.
#[test]
fn a_direction_channel_that_does_not_change_is_named() {
    use host_sim::app::analyze::Channel;
    let rev = std::f64::consts::TAU;
    let (text, _, _) = quadrature(50, 40.0, &[8.0 * rev]);
    let run = |direction: &str| {
        let cfg = configure(&AnalyzeOptions {
            channel: Some(Channel::Name("A".into())),
            direction_channel: Some(Channel::Name(direction.into())),
            lines: Some(50),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut reader = text_reader(text.clone(), "q.csv", None).unwrap();
        analyze(&mut reader, &cfg, &mut |_| {}).unwrap()
    };
    let wrong = run("Z");
    let z = wrong
        .channel_changes
        .iter()
        .find(|c| c.name == "Z")
        .unwrap()
        .changes;
    assert!(z <= 18 && wrong.captured >= 390, "{z} {}", wrong.captured);
    let said = host_sim::app::analyze::text(&wrong);
    assert!(
        said.contains(&format!(
            "WARNING: the direction channel `Z` changed {z} time(s) over the {} captured edges \
             of `A`",
            wrong.captured
        )),
        "{said}"
    );
    let right = run("B");
    assert!(right.valid_windows >= 6, "{}", right.valid_windows);
    assert!(
        !host_sim::app::analyze::text(&right).contains("WARNING: the direction channel"),
        "{right:?}"
    );
}

/// Edge-timing jitter (a sensor's or comparator's) reads as δ beyond the floor, which holds
/// only the timer's and the sampling's resolution; the windows were called resolved with no
/// word. The report now gives the jitter the edges' scatter about their neighbours' cubic
/// implies, and what it can read as δ: on a 60-line disc at 150 rad/s with 2 µs of jitter
/// (0.00286 pitch), 40 revolutions, it finds that to 10 %; the same disc without jitter gets
/// no note.
#[test]
fn edge_jitter_is_estimated_and_noted() {
    let interval = std::f64::consts::TAU / 60.0 / 150.0;
    let times = |sigma: f64| {
        // Gaussian jitter from a fixed linear congruential sequence (Box–Muller).
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut uniform = || {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            ((state >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..2400)
            .map(|k| {
                let g = (-2.0 * uniform().ln()).sqrt() * (std::f64::consts::TAU * uniform()).cos();
                1e-3 + f64::from(k) * interval + sigma * g
            })
            .collect::<Vec<f64>>()
    };
    let analyzed = |t: &[f64]| {
        let text = saleae_of_rising(t, 1e9, t.last().unwrap() + 1e-3);
        let cfg = configure(&AnalyzeOptions {
            lines: Some(60),
            timer_hz: Some(1e9),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut r = text_reader(text, "j.csv", Some(1e9)).unwrap();
        analyze(&mut r, &cfg, &mut |_| {}).unwrap()
    };
    let r = analyzed(&times(2e-6));
    let e = r.edge_scatter.unwrap();
    let truth = 2e-6 / interval;
    assert!(
        (e.pitches / truth - 1.0).abs() < 0.1,
        "{} against {truth}",
        e.pitches
    );
    // What it is for: the windows' δ (the shaft's is 0) is what it says jitter reads, about
    // (their median within 25 %), far beyond the floor.
    let mut deltas: Vec<f64> = r.windows.iter().filter_map(|w| w.delta).collect();
    deltas.sort_by(f64::total_cmp);
    let median = deltas[deltas.len() / 2];
    assert!(
        (median / e.delta - 1.0).abs() < 0.25 && deltas[0] > 2.0 * e.floor,
        "{deltas:?} {e:?}"
    );
    assert!(host_sim::app::analyze::text(&r).contains("NOTE: the edges scatter"));
    assert_eq!(analyzed(&times(0.0)).edge_scatter, None);
}

/// The core counts the teeth a long interval lost by how many of the interval it judged
/// before fit in it (a run of teeth lost, e.g. a sensor's dropout): more missing edges than
/// captures are said to be the core's judgement; a count within the captures is printed as it
/// was. (Ringing read on the polarity that rings once counted 78 400 missing edges among 5 762
/// captures that way; the core now counts extra edges there: `monitor::tests::ringing_after_every_tooth_counts_extra_edges_not_lost_teeth`.)
#[test]
fn more_missing_edges_than_captures_are_said_to_be_a_judgement() {
    let said = |missing: u32, captured: u64| {
        host_sim::app::analyze::text(&AnalyzeReport {
            missing,
            captured,
            ..AnalyzeReport::default()
        })
    };
    let many = said(78_400, 5_762);
    assert!(
        many.contains("78400 missing edges")
            && many.contains("(more missing edges than the 5762 captured: the core counts"),
        "{many}"
    );
    assert!(!said(12, 5_762).contains("more missing edges than"));
}

/// The rising edges of a `lines`-line disc turning at a constant `omega` rad/s from `start` to
/// `stop` s, drawn from the angle (the true δ of every window is 0).
fn steady_disc(lines: u32, omega: f64, start: f64, stop: f64) -> Vec<f64> {
    let pitch = std::f64::consts::TAU / f64::from(lines) / omega;
    (0..)
        .map(|k: u32| start + f64::from(k) * pitch)
        .take_while(|&t| t < stop)
        .collect()
}

/// The transitions of a capture sampled at `rate` Hz on the grid `origin + j/rate` (each
/// edge at the first sample at or after it) of a disc rising at `rising` and falling halfway
/// to the next rise: (time, level).
fn on_grid(rising: &[f64], rate: f64, origin: f64) -> Vec<(f64, u8)> {
    let at = |t: f64| origin + ((t - origin) * rate).ceil() / rate;
    let mut rows = Vec::new();
    for (i, &t) in rising.iter().enumerate() {
        let next = rising.get(i + 1).copied().unwrap_or(t + 1e-3);
        rows.push((at(t), 1));
        rows.push((at(0.5 * (t + next)), 0));
    }
    rows
}

/// A one-channel CSV (`header`, then `first` and `rows`) with each time as `time` writes it.
fn csv_of(
    header: &str,
    first: Option<f64>,
    rows: &[(f64, u8)],
    sep: &str,
    time: impl Fn(f64) -> String,
) -> String {
    let mut s = format!("{header}\n");
    for (t, v) in first.map(|t| (t, 0)).iter().chain(rows) {
        s.push_str(&format!("{}{sep}{v}\n", time(*t)));
    }
    s
}

/// Analyzes `text` (read as the file `name`) with a `lines`-line disc, an 84 MHz timer and
/// `k` edges a speed sample.
fn analyze_text(text: String, name: &str, lines: u16, k: u16) -> AnalyzeReport {
    let cfg = configure(&AnalyzeOptions {
        lines: Some(lines),
        timer_hz: Some(84e6),
        estimator_edges: Some(k),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let mut reader = text_reader(text, name, None).unwrap();
    analyze(&mut reader, &cfg, &mut |_| {}).unwrap()
}

/// The windows of a steady shaft: at least 3 valid, and the δ of each (the times' quantization
/// alone) within the floor given, not resolved.
fn none_resolved(report: &AnalyzeReport, what: &str) {
    let valid: Vec<_> = report.windows.iter().filter(|w| w.valid).collect();
    assert!(valid.len() >= 3, "{what}: {} valid windows", valid.len());
    for w in valid {
        assert_eq!(
            w.resolved,
            Some(false),
            "{what}: window at {} s, δ {:?} (truth 0), floor {:?}, grid {:?}",
            w.start,
            w.delta,
            w.floor_with_sampling.or(w.noise_floor),
            report.time_grid
        );
    }
}

fn grid_is(report: &AnalyzeReport, period: f64, what: &str) {
    assert!(
        report
            .time_grid
            .is_some_and(|g| (g / period - 1.0).abs() < 1e-9),
        "{what}: grid {:?}, truth {period:e}",
        report.time_grid
    );
}

/// A row that carries no transition need lie on no sample grid: a Saleae export's first row
/// (the initial level, at 0 s, the transitions at 0.1234567 s + k·0.5 µs), a last row at the
/// end of the recording off the grid, a value change dump's `#0` dump, a Saleae binary
/// export's begin time. The grid is the transitions' (2 MS/s), and a steady shaft's δ (the
/// sampling's) is within the floor; one such row had made the grid 100 ns, the floor 4.6
/// times too small, and δ 0.0086 of a constant shaft read as resolved.
#[test]
fn a_row_without_a_transition_does_not_set_the_grid() {
    let rising = steady_disc(360, 300.0, 0.13, 0.25);
    let nine = |t: f64| format!("{t:.9}");
    let header = "Time [s],Channel 0";
    let offset = on_grid(&rising, 2e6, 0.1234567);
    let first_off = csv_of(header, Some(0.0), &offset, ",", nine);
    let report = analyze_text(first_off.clone(), "first.csv", 360, 1);
    grid_is(&report, 5e-7, "first row at 0 s");
    none_resolved(&report, "first row at 0 s");
    let text = host_sim::app::analyze::text(&report);
    assert!(
        text.contains("every transition's time lies on a 5.000e-7 s grid"),
        "{text}"
    );
    // Transitions on the grid from 0, a last row 12.3 µs after the last transition.
    let from0 = on_grid(&rising, 2e6, 0.0);
    let mut last_off = csv_of(header, Some(0.0), &from0, ",", nine);
    let end = from0.last().unwrap().0 + 12.3e-6;
    last_off.push_str(&format!("{end:.9},0\n"));
    let report = analyze_text(last_off, "last.csv", 360, 1);
    grid_is(&report, 5e-7, "last row off the grid");
    none_resolved(&report, "last row off the grid");
    // A value change dump in nanoseconds: `#0` with the initial level, then the transitions.
    let mut vcd = String::from(
        "$timescale 1 ns $end\n$scope module top $end\n$var wire 1 ! ch0 $end\n$upscope $end\n\
         $enddefinitions $end\n#0\n$dumpvars\n0!\n$end\n",
    );
    for (t, v) in &offset {
        vcd.push_str(&format!("#{}\n{v}!\n", (t * 1e9).round() as u64));
    }
    let report = analyze_text(vcd, "dump.vcd", 360, 1);
    grid_is(&report, 5e-7, "value change dump");
    none_resolved(&report, "value change dump");
    // Saleae's binary export, begin time 0 s.
    let (_scratch, dir) = tmp("bin");
    saleae_binary(&first_off, &dir, 0, 0.0, None);
    let (report, _) = run_analyze(
        &dir.join("digital_0.bin"),
        AnalyzeOptions {
            lines: Some(360),
            timer_hz: Some(84e6),
            ..AnalyzeOptions::default()
        },
    );
    grid_is(&report, 5e-7, "binary export");
    none_resolved(&report, "binary export");
}

/// Rates whose period is not whole nanoseconds are found at whatever precision the times are
/// written to: Saleae Logic 1.x's fifteen decimals (`Time[s], Channel 0`), a value change
/// dump in picoseconds, a Saleae binary export's doubles. Each grid is the rate's period, and
/// a steady shaft's δ is within the floor (at 24 MS/s it read 2.5 times the timer's floor,
/// resolved, with no grid found).
#[test]
fn a_grid_of_a_rate_not_whole_nanoseconds_is_found_at_any_precision() {
    let rising = steady_disc(1024, 300.0, 0.0012, 0.2);
    for rate in [24e6, 12e6, 3e6] {
        let rows = on_grid(&rising, rate, 0.0);
        let text = csv_of("Time[s], Channel 0", Some(0.0), &rows, ", ", |t| {
            format!("{t:.15}")
        });
        let report = analyze_text(text.clone(), "logic1.csv", 1024, 16);
        let what = format!("{rate} Hz at fifteen decimals");
        grid_is(&report, 1.0 / rate, &what);
        none_resolved(&report, &what);
        if rate == 24e6 {
            let mut vcd = String::from(
                "$timescale 1 ps $end\n$var wire 1 ! ch0 $end\n$enddefinitions $end\n#0\n0!\n",
            );
            for (t, v) in &rows {
                vcd.push_str(&format!("#{}\n{v}!\n", (t * 1e12).round() as u64));
            }
            let report = analyze_text(vcd, "dump.vcd", 1024, 16);
            grid_is(&report, 1.0 / rate, "24 MHz in picoseconds");
            none_resolved(&report, "24 MHz in picoseconds");
            let csv = csv_of("Time [s],Channel 0", Some(0.0), &rows, ",", |t| {
                format!("{t:e}")
            });
            let (_scratch, dir) = tmp("bin");
            saleae_binary(&csv, &dir, 0, 0.0, None);
            let (report, _) = run_analyze(
                &dir.join("digital_0.bin"),
                AnalyzeOptions {
                    lines: Some(1024),
                    timer_hz: Some(84e6),
                    estimator_edges: Some(16),
                    ..AnalyzeOptions::default()
                },
            );
            grid_is(&report, 1.0 / rate, "24 MHz in doubles");
            none_resolved(&report, "24 MHz in doubles");
        }
    }
    // Times at 1 GS/s written to fifteen decimals lie on no such grid, nor do exact times.
    let exact: Vec<(f64, u8)> = rising
        .iter()
        .flat_map(|&t| [(t, 1), (t + 1e-6, 0)])
        .collect();
    let text = csv_of("Time[s], Channel 0", Some(0.0), &exact, ", ", |t| {
        format!("{t:.15}")
    });
    let report = analyze_text(text, "exact.csv", 1024, 16);
    assert_eq!(
        (report.time_grid, report.float_grid.is_some()),
        (None, false)
    );
}

/// A rate that is a sub-multiple of one whose period is not whole nanoseconds (750 kHz, 3 MHz
/// over 4; 2.4 MHz, 12 MHz over 5; 1.5 MHz) lies on that rate's grid too, every so many
/// points: the grid found is the longest step every transition lies on, the true period (it
/// had been the listed rate's, the floor a quarter of the sampling's and a steady shaft's δ
/// resolved).
#[test]
fn a_sub_multiple_of_a_listed_rate_gets_its_own_period() {
    let rising = steady_disc(360, 300.0, 0.001, 0.2);
    for rate in [750e3, 2.4e6, 1.5e6] {
        let rows = on_grid(&rising, rate, 0.0);
        let text = csv_of("Time [s],Channel 0", Some(0.0), &rows, ",", |t| {
            format!("{t:.9}")
        });
        let report = analyze_text(text, "sub.csv", 360, 1);
        let what = format!("{rate} Hz");
        grid_is(&report, 1.0 / rate, &what);
        none_resolved(&report, &what);
    }
    let rows = on_grid(&rising, 750e3, 0.0);
    let text = csv_of("Time [s],Channel 0", Some(0.0), &rows, ",", |t| {
        format!("{t:.9}")
    });
    let said = host_sim::app::analyze::text(&analyze_text(text, "sub.csv", 360, 1));
    assert!(
        said.contains("4 periods of a 3000000 Hz analyser's"),
        "{said}"
    );
}

/// Rates of 3 MHz and faster written to seven decimals (Logic 2 at a coarser precision, a
/// period of 333.33 ns written as steps of 0.0000003 and 0.0000004 s) lie on the digits' own
/// 100 ns. 3 MHz is still told from its rows (each within 100 ns of its grid has odds 0.6 by
/// chance, so it takes 87 rows, not 64): its period and the digits' rounding are the
/// resolution. 6 MHz fits every such time (within 83 ns of its grid), so the rows cannot tell
/// it, nor anything faster: the floor takes the digits' step and 6 MHz's period. A steady
/// shaft's δ had read 1.8 times the floor (3 MHz) and 1.3 times it (6 MHz), resolved.
#[test]
fn rates_the_digits_cannot_show_are_kept_under_the_floor() {
    let rising = steady_disc(360, 300.0, 0.001, 0.25);
    let seven = |t: f64| format!("{t:.7}");
    for rate in [3e6, 6e6, 12e6, 24e6] {
        let rows = on_grid(&rising, rate, 0.0);
        let text = csv_of("Time [s],Channel 0", Some(0.0), &rows, ",", seven);
        let report = analyze_text(text, "seven.csv", 360, 1);
        let what = format!("{rate} Hz at seven decimals");
        none_resolved(&report, &what);
        if rate == 3e6 {
            grid_is(&report, 1.0 / 3e6, &what);
            assert!(report.digits_grid.is_none(), "{what}");
            let w = report.windows.iter().find(|w| w.valid).unwrap();
            assert_eq!(w.time_resolution, Some(1.0 / 3e6 + 1e-7), "{what}");
        } else {
            grid_is(&report, 1e-7, &what);
            let d = report.digits_grid.expect("the digits' grid");
            assert_eq!(d.hidden_rate, Some(6e6), "{what}");
            assert!(
                (d.resolution - (1e-7 + 1.0 / 6e6)).abs() < 1e-15,
                "{what}: {d:?}"
            );
            let said = host_sim::app::analyze::text(&report);
            assert!(
                said.contains("the precision the times are written to: the digits' own step")
                    && said.contains("a 6000000 Hz analyser's 1.667e-7 s fits every row"),
                "{said}"
            );
        }
    }
    // A 1 MHz capture at seven decimals shows its own 1 µs: no digits' grid.
    let rows = on_grid(&rising, 1e6, 0.0);
    let text = csv_of("Time [s],Channel 0", Some(0.0), &rows, ",", seven);
    let report = analyze_text(text, "1mhz.csv", 360, 1);
    grid_is(&report, 1e-6, "1 MHz at seven decimals");
    assert!(report.digits_grid.is_none());
}

/// Times held as floats before they were written lie on the float's power-of-two grid: Unix
/// times in an f64 printed to nine decimals, 2^-22 s (0.24 µs) apart near 1.76e9 s, or an
/// f32's at 5 s, 2^-21 s. That grid is their resolution (a steady shaft's δ 0.0043 had read
/// 10 times the timer's floor, resolved). The same instants written exactly lie on none.
#[test]
fn times_held_as_floats_are_resolved_to_the_float_grid() {
    let rising = steady_disc(360, 300.0, 0.001, 0.2);
    let exact: Vec<(f64, u8)> = rising
        .iter()
        .flat_map(|&t| [(t, 1), (t + 1e-5, 0)])
        .collect();
    let header = "Time [s],Channel 0";
    let f64_epoch = csv_of(header, None, &exact, ",", |t| {
        format!("{:.9}", 1_764_306_000.0 + t)
    });
    let report = analyze_text(f64_epoch, "epoch.csv", 360, 1);
    let f = report.float_grid.expect("a float grid");
    assert_eq!((f.exponent, f.float), (22, Some("f64")), "{f:?}");
    assert_eq!(report.time_grid, None);
    none_resolved(&report, "f64 Unix times");
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("lies on a 2^-22 s grid") && said.contains("64-bit float"),
        "{said}"
    );
    // Printed in full (shortest round trip, Python's `repr`): seven decimals, on 100 ns, which
    // is no sample period.
    let repr = csv_of(header, None, &exact, ",", |t| {
        format!("{:?}", 1_764_306_000.0 + t)
    });
    let report = analyze_text(repr, "repr.csv", 360, 1);
    let f = report.float_grid.expect("a float grid");
    assert_eq!((f.exponent, report.time_grid), (22, None), "{f:?}");
    none_resolved(&report, "f64 Unix times in full");
    let f32_at5 = csv_of(header, None, &exact, ",", |t| {
        format!("{:.9}", (5.0 + t) as f32)
    });
    let report = analyze_text(f32_at5, "f32.csv", 360, 1);
    let f = report.float_grid.expect("a float grid");
    assert_eq!((f.exponent, f.float), (21, Some("f32")), "{f:?}");
    none_resolved(&report, "f32 times at 5 s");
    // The same instants as exact decimals, at the Unix time and from 0: no grid of any kind.
    for (name, text) in [
        (
            "exact epoch",
            csv_of(header, None, &exact, ",", |t| {
                format!("1764306000.{:09}", (t * 1e9).round() as u64)
            }),
        ),
        (
            "exact",
            csv_of(header, None, &exact, ",", |t| format!("{t:.9}")),
        ),
    ] {
        let report = analyze_text(text, name, 360, 1);
        assert!(
            report.time_grid.is_none() && report.float_grid.is_none(),
            "{name}: {:?} {:?}",
            report.time_grid,
            report.float_grid
        );
    }
}

/// Saleae Logic 2 can export absolute times as ISO-8601 date-times
/// (`2026-11-28T05:00:00.000623599+00:00`): read exactly, counted from the first time's whole
/// seconds (Unix seconds), they give the windows the same rows written as decimal Unix times
/// give, whatever the zone offset written; they had been refused as "not a time in seconds".
#[test]
fn iso_8601_times_read_as_the_unix_times_they_are() {
    let rising = steady_disc(360, 300.0, 0.001, 0.2);
    let rows: Vec<(f64, u8)> = rising
        .iter()
        .flat_map(|&t| [(t, 1), (t + 1e-5, 0)])
        .collect();
    let ns = |t: f64| (t * 1e9).round() as u64;
    let header = "Time [s],Channel 0";
    let unix = csv_of(header, Some(0.0), &rows, ",", |t| {
        format!("1795842000.{:09}", ns(t))
    });
    let utc = csv_of(header, Some(0.0), &rows, ",", |t| {
        format!("2026-11-28T05:00:00.{:09}+00:00", ns(t))
    });
    let paris = csv_of(header, Some(0.0), &rows, ",", |t| {
        format!("2026-11-28T06:00:00.{:09}+01:00", ns(t))
    });
    let want = analyze_text(unix, "unix.csv", 360, 1);
    assert_eq!(want.time_origin, 1_795_842_000);
    let windows = |r: &AnalyzeReport| {
        r.windows
            .iter()
            .map(|w| (w.start, w.valid, w.delta, w.floor_with_sampling))
            .collect::<Vec<_>>()
    };
    assert!(want.valid_windows >= 3);
    for (name, text) in [("utc.csv", utc), ("paris.csv", paris)] {
        let got = analyze_text(text, name, 360, 1);
        assert_eq!(got.time_origin, want.time_origin, "{name}");
        assert_eq!(windows(&got), windows(&want), "{name}");
    }
}

/// Times held as f32 from near 0 s lie on no one grid: the float's spacing grows with the
/// time (1.2e-10 s at 0.001 s, 1.2e-7 s past 1 s). Each window's floor takes the spacing at its
/// own times, and a steady shaft's δ (the f32 rounding's alone) is within it; with the timer's
/// floor alone 84 of 93 windows (every one past 0.1 s) had read as resolved, at up to 5.5 times
/// it. The same instants written exactly are no float's values.
#[test]
fn f32_times_from_zero_take_the_spacing_at_each_window() {
    let rising = steady_disc(60, 300.0, 0.001, 2.0);
    let rows: Vec<(f64, u8)> = rising
        .iter()
        .flat_map(|&t| [(t, 1), (t + 0.5 * std::f64::consts::TAU / 60.0 / 300.0, 0)])
        .collect();
    let header = "Time [s],Channel 0";
    let f32s = csv_of(header, None, &rows, ",", |t| format!("{:.9}", t as f32));
    let report = analyze_text(f32s, "f32.csv", 60, 1);
    let f = report.float_times.expect("f32 times");
    assert_eq!((f.float, f.spacing_to), ("f32", 2f64.powi(-23)), "{f:?}");
    assert!(report.float_grid.is_none() && report.time_grid.is_none());
    none_resolved(&report, "f32 times from 0 s");
    // The floor follows the spacing: a window past 1 s takes 2^-23 s and the digits' 1 ns.
    let late = report.windows.iter().rev().find(|w| w.valid).unwrap();
    assert_eq!(late.time_resolution, Some(2f64.powi(-23) + 1e-9));
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("is a 32-bit float (f32) value") && said.contains("float spacing (below)"),
        "{said}"
    );
    let exact = csv_of(header, None, &rows, ",", |t| format!("{t:.9}"));
    let report = analyze_text(exact, "exact.csv", 60, 1);
    assert!(report.float_times.is_none(), "{:?}", report.float_times);
}

/// libsigrok writes the time column in the unit its sample rate calls for: a `; Samplerate:
/// 10 MHz` over whole microseconds (a 1 MHz capture's) contradicts itself, and read at the rate
/// every speed was 10 times off. Refused, naming both; so is --sample-rate against the column.
#[test]
fn a_sigrok_rate_against_its_time_column_is_refused() {
    let rows = "microseconds,logic\n1,0\n1001,1\n1574,0\n";
    let commented = format!("; CSV generated by libsigrok 0.5.2\n; Samplerate: 10 MHz\n{rows}");
    let e = sigrok_times(&commented, None).unwrap_err();
    assert!(
        e.contains("`microseconds`")
            && e.contains("Samplerate: 10 MHz")
            && e.contains("nanoseconds"),
        "{e}"
    );
    let e = sigrok_times(rows, Some(10e6)).unwrap_err();
    assert!(
        e.contains("`microseconds`") && e.contains("--sample-rate"),
        "{e}"
    );
    assert_eq!(
        sigrok_times(rows, Some(1e6)).unwrap(),
        vec![0.0, 1000e-6, 1573e-6]
    );
}

/// A mixed capture as libsigrok writes it: a logic column (`logic`) beside an analog one (by
/// its unit, `V`), named in the comment. It was refused as a whole for the analog column's
/// values, and its channels were named by the labels (`--channel D0`: no such channel). Now
/// the comment names the columns, the logic channel is analysed, and reading the analog one
/// as the encoder is refused with the threshold hint.
#[test]
fn a_mixed_capture_is_read_on_its_logic_channel() {
    // A 60-line disc at 2 ms a line (8 revolutions), sampled at 100 kHz, microseconds.
    let mut text = String::from(
        "; CSV generated by libsigrok 0.5.2\n; Channels (2/9): D0, A0\n; Samplerate: 100 kHz\n\
         microseconds,logic,V\n",
    );
    for j in 0..96_000u32 {
        let level = u8::from(j % 200 < 100);
        let volts = 0.5 + 0.25 * f64::from(j % 7);
        text.push_str(&format!("{},{level},{volts:.3}\n", j * 10));
    }
    let analyzed = |channel: Option<&str>| {
        let cfg = configure(&AnalyzeOptions {
            lines: Some(60),
            channel: channel.map(|c| host_sim::app::analyze::Channel::Name(c.into())),
            ..AnalyzeOptions::default()
        })
        .unwrap();
        let mut r = text_reader(text.clone(), "m.csv", None).unwrap();
        assert_eq!(r.channels(), ["D0", "A0"]);
        analyze(&mut r, &cfg, &mut |_| {}).map_err(|e| e.to_string())
    };
    for channel in [None, Some("D0")] {
        let r = analyzed(channel).unwrap();
        assert!(r.valid_windows >= 6, "{}", r.valid_windows);
        let omega = std::f64::consts::TAU / 60.0 / 2e-3;
        assert!(r
            .windows
            .iter()
            .filter_map(|w| w.omega_mean)
            .all(|w| (w / omega - 1.0).abs() < 1e-6));
    }
    let e = analyzed(Some("A0")).unwrap_err();
    assert!(
        e.contains("channel `A0`") && e.contains("--threshold"),
        "{e}"
    );
}

/// A 36-2 wheel at 150 rad/s under `--min-speed 200`: the no-sync hint gave the slowest speed
/// seen as 50 rad/s when the capture started in the gap, its first interval (three pitches,
/// no neighbour before it) read as one pitch. Judged against the interval after it, the
/// slowest speed is the shaft's.
#[test]
fn a_capture_starting_in_a_gap_gives_the_shafts_slowest_speed() {
    // The teeth from the one before the first gap: the first interval spans the gap.
    let teeth: Vec<f64> = wheel_teeth(36, 2, 150.0, 0.3)
        .into_iter()
        .skip(33)
        .collect();
    assert!((teeth[1] - teeth[0]) / (teeth[2] - teeth[1]) > 2.9);
    let text = saleae_of_rising(&teeth, 1e9, 0.301);
    let cfg = configure(&AnalyzeOptions {
        wheel: Some("36-2".into()),
        min_speed: Some(200.0),
        ..AnalyzeOptions::default()
    })
    .unwrap();
    let mut r = text_reader(text, "g.csv", Some(1e9)).unwrap();
    let report = analyze(&mut r, &cfg, &mut |_| {}).unwrap();
    let said = host_sim::app::analyze::text(&report);
    assert!(
        said.contains("the slowest speed seen is about 150.000 rad/s"),
        "{said}"
    );
}

/// Analyzes the capture `text` (read as the file `name`, its times in `unit` when given, as
/// `--time-unit` gives it) with `options`: the report and its text, or the error.
fn analyze_unit(
    text: &str,
    name: &str,
    unit: Option<TimeUnit>,
    options: AnalyzeOptions,
) -> Result<(AnalyzeReport, String), String> {
    let cfg = configure(&options)?;
    let mut reader = CaptureReader::new_with(
        std::io::Cursor::new(text.to_string()),
        Path::new(name),
        None,
        None,
        unit,
    )
    .map_err(|e| e.to_string())?;
    let report = analyze(&mut reader, &cfg, &mut |_| {}).map_err(|e| e.to_string())?;
    let said = host_sim::app::analyze::text(&report);
    Ok((report, said))
}

/// The valid windows' mean speeds.
fn mean_speeds(r: &AnalyzeReport) -> Vec<f64> {
    r.windows
        .iter()
        .filter(|w| w.valid)
        .filter_map(|w| w.omega_mean)
        .collect()
}

/// Edge times written in milliseconds or microseconds with decimals and no header are read as
/// seconds (nothing in the file says otherwise), which makes a 150 rad/s shaft 0.15 or 1.5e-4
/// rad/s: the no-sync hint's slowest speed and the valid windows' slow speeds say what such
/// times give and name --time-unit; with it (or a header naming the unit) the speeds are the
/// shaft's. Before, the slowest speed read "0.000 rad/s" for µs and nothing named the unit.
#[test]
fn edge_times_in_ms_or_us_name_the_time_unit_and_read_with_it() {
    let rising = wheel_teeth(36, 2, 150.0, 0.34);
    let ms: String = rising
        .iter()
        .map(|t| format!("{:.6}\n", 1.0 + t * 1e3))
        .collect();
    let us: String = rising
        .iter()
        .map(|t| format!("{:.3}\n", 1000.0 + t * 1e6))
        .collect();
    let (r, said) = analyze_unit(&ms, "t.txt", None, wheel("36-2")).unwrap();
    assert!(r.sync_acquired.is_none(), "{said}");
    assert!(
        said.contains("slowest speed seen is about 0.1")
            && said.contains("read as seconds")
            && said.contains("--time-unit ms"),
        "{said}"
    );
    let (_, said) = analyze_unit(&us, "t.txt", None, wheel("36-2")).unwrap();
    assert!(
        said.contains("slowest speed seen is about 1.") && said.contains("e-4 rad/s; the file"),
        "{said}"
    );
    let slow = AnalyzeOptions {
        min_speed: Some(0.01),
        ..wheel("36-2")
    };
    let (r, said) = analyze_unit(&ms, "t.txt", None, slow).unwrap();
    assert!(r.valid_windows >= 3, "{said}");
    assert!(
        said.contains("NOTE: the valid windows' mean speeds are as slow as 0.150 rad/s")
            && said.contains("--time-unit ms"),
        "{said}"
    );
    for (text, unit) in [(&ms, TimeUnit::Ms), (&us, TimeUnit::Us)] {
        let (r, said) = analyze_unit(text, "t.txt", Some(unit), wheel("36-2")).unwrap();
        let speeds = mean_speeds(&r);
        assert!(speeds.len() >= 3, "{said}");
        assert!(speeds.iter().all(|w| (w - 150.0).abs() < 0.5), "{speeds:?}");
        assert!(!said.contains("NOTE: the valid windows'"), "{said}");
        assert!(
            said.contains(&format!("times: in {}", unit.name())),
            "{said}"
        );
    }
    // A header naming the unit reads so; --time-unit against it is refused, and so is it for
    // a format that states its unit.
    let (r, _) = analyze_unit(&format!("t_ms\n{ms}"), "t.txt", None, wheel("36-2")).unwrap();
    assert!(mean_speeds(&r).iter().all(|w| (w - 150.0).abs() < 0.5));
    let e = analyze_unit(
        &format!("t_ms\n{ms}"),
        "t.txt",
        Some(TimeUnit::Us),
        wheel("36-2"),
    )
    .unwrap_err();
    assert!(
        e.contains("--time-unit us: the header says the times are in ms"),
        "{e}"
    );
    let vcd = "$timescale 1 us $end\n$var wire 1 ! D0 $end\n$enddefinitions $end\n#0 0!\n#5 1!\n";
    let e = analyze_unit(vcd, "t.vcd", Some(TimeUnit::Ms), wheel("36-2")).unwrap_err();
    assert!(
        e.contains("--time-unit ms: a vcd file states") && e.contains("$timescale"),
        "{e}"
    );
    // A plain CSV in µs, whole numbers, with --time-unit us.
    let plain: String = std::iter::once("time_s,level\n".to_string())
        .chain(rising.iter().flat_map(|t| {
            let up = (1000.0 + t * 1e6).round();
            [format!("{up},1\n"), format!("{},0\n", up + 100.0)]
        }))
        .collect();
    let (r, said) = analyze_unit(&plain, "p.csv", Some(TimeUnit::Us), wheel("36-2")).unwrap();
    assert!(mean_speeds(&r).len() >= 3, "{said}");
    assert!(mean_speeds(&r).iter().all(|w| (w - 150.0).abs() < 0.5));
}

/// An option's value far out of range is echoed as it reads (`1e300`), not as its 301 digits.
#[test]
fn a_huge_option_value_is_echoed_in_exponent_form() {
    let e = configure(&AnalyzeOptions {
        timer_hz: Some(1e300),
        ..wheel("36-2")
    })
    .unwrap_err();
    assert!(e.starts_with("--timer-hz 1e300 is out of range"), "{e}");
    assert!(e.len() < 200, "{e}");
    let e = host_sim::app::logic::Threshold::new(0.0, -1e300).unwrap_err();
    assert!(e.starts_with("--hysteresis -1e300:"), "{e}");
}

/// A threshold outside the values' range reads no edge; the report said "no channel of the
/// capture changes level" and "no sync: the capture is too short". It now gives the values'
/// range against the band the threshold reads them through.
#[test]
fn a_threshold_outside_the_values_is_named_with_their_range() {
    // A 24-tooth sensor's sine, ±1.05 V, 20 kS/s over 0.5 s.
    let omega = 100.0;
    let mut csv = String::from("Time [s],Channel 0\n");
    for i in 0..10_000 {
        let t = i as f64 / 20e3;
        csv.push_str(&format!("{t:.9},{:.5}\n", 1.05 * (24.0 * omega * t).sin()));
    }
    let lines = AnalyzeOptions {
        lines: Some(24),
        ..AnalyzeOptions::default()
    };
    for (volts, hysteresis, never) in [
        (5.0, 0.0, "never above 5, so never high"),
        (0.0, 3.0, "never above 1.5 nor below -1.5"),
    ] {
        let cfg = configure(&lines).unwrap();
        let mut reader = text_reader(csv.clone(), "a.csv", None).unwrap();
        reader
            .set_threshold(host_sim::app::logic::Threshold::new(volts, hysteresis).unwrap())
            .unwrap();
        let r = analyze(&mut reader, &cfg, &mut |_| {}).unwrap();
        let said = host_sim::app::analyze::text(&r);
        assert_eq!(r.edges, 0);
        assert!(
            said.contains("the values of `Channel 0` range from -1.05 to 1.05")
                && said.contains(never)
                && said.contains("give a --threshold within their range"),
            "{said}"
        );
        assert!(!said.contains("too short"), "{said}");
    }
}

/// A value change dump whose time unit (1 ms) is coarser than the pulses (a 36-2 wheel at
/// 150 rad/s, a tooth every 1.16 ms): a tooth's fall and the next one's rise often fall on
/// one time stamp and cancel. It was said to be "too short" (1.4 revolutions of edges in 8);
/// now the stamps with a change and its undoing are counted and said.
#[test]
fn changes_merged_by_a_coarse_timescale_are_said() {
    let rising = wheel_teeth(36, 2, 150.0, 0.34);
    let half = std::f64::consts::TAU / 36.0 / 150.0 / 2.0;
    let mut vcd = String::from(
        "$timescale 1 ms $end\n$scope module logic $end\n$var wire 1 ! D0 $end\n$upscope $end\n\
         $enddefinitions $end\n#0\n0!\n",
    );
    let mut stamp = 0u64;
    for &t in &rising {
        for (at, v) in [(t, 1), (t + half, 0)] {
            let k = (at * 1e3).ceil() as u64;
            if k != stamp {
                vcd.push_str(&format!("#{k}\n"));
                stamp = k;
            }
            vcd.push_str(&format!("{v}!\n"));
        }
    }
    let (r, said) = analyze_unit(&vcd, "c.vcd", None, wheel("36-2")).unwrap();
    let m = r.same_stamp.expect("merged changes counted");
    assert!(m.times > 100 && m.timescale == Some(1e-3), "{m:?}");
    assert!(
        said.contains("WARNING: `D0` changes level and back at one time stamp")
            && said.contains("lost to the time unit, not to a short capture"),
        "{said}"
    );
    assert!(!said.contains("too short"), "{said}");
}

/// Two rows at one time with opposite levels (a pulse of no width as written) were counted as
/// a glitch with no word that the file has two changes at one time stamp.
#[test]
fn two_rows_at_one_time_with_opposite_levels_are_named() {
    let rising = wheel_teeth(36, 2, 150.0, 0.34);
    let mut csv = saleae_of_rising(&rising, 1e9, 0.35);
    let at = 0.5 * (rising[100] + rising[101]) + 0.2e-3;
    let row = format!("{at:.9},0\n");
    let k = csv
        .find(&format!("{:.9},1\n", sampled(rising[101], 1e9)))
        .unwrap();
    csv.insert_str(k, &format!("{at:.9},1\n{row}"));
    let (r, said) = analyze_unit(&csv, "z.csv", None, wheel("36-2")).unwrap();
    let m = r.same_stamp.expect("the pulse of no width is counted");
    assert_eq!((m.times, m.timescale), (1, None));
    assert!((m.first - at).abs() < 1e-9, "{m:?}");
    assert!(
        said.contains("WARNING: `Channel 0` changes level twice at one time 1 time(s)"),
        "{said}"
    );
}

/// The G16 file quirks, each read as the clean Saleae export of the same edges (the same
/// windows, δ for δ), where each was refused or misread: CR-only line ends ("line longer than
/// 4096 bytes"), a comma after every row's last field ("`` in the column of channel ``"), a
/// header in double quotes and `Time [us]` / `Time [ms]` headers ("cannot tell the capture
/// format"), levels written `0.0`/`1.0` (refused as analog values), a sigrok export whose
/// time column is `seconds` (taken as a channel).
#[test]
fn file_quirks_read_as_the_clean_export() {
    let rising = wheel_teeth(36, 2, 150.0, 0.34);
    let clean = saleae_of_rising(&rising, 1e9, 0.35);
    let deltas = |text: &str, name: &str| -> Vec<(f64, f64)> {
        let (r, said) = analyze_unit(text, name, None, wheel("36-2")).unwrap();
        assert!(r.valid_windows >= 3, "{name}: {said}");
        r.windows
            .iter()
            .filter(|w| w.valid)
            .map(|w| (w.start, w.delta.unwrap()))
            .collect()
    };
    let want = deltas(&clean, "clean.csv");
    let rows: Vec<(f64, &str)> = clean
        .lines()
        .skip(1)
        .map(|l| {
            let (t, v) = l.split_once(',').unwrap();
            (t.parse().unwrap(), v)
        })
        .collect();
    let with = |header: &str, row: &dyn Fn(f64, &str) -> String, end: &str| {
        let mut s = format!("{header}{end}");
        for &(t, v) in &rows {
            s.push_str(&row(t, v));
            s.push_str(end);
        }
        s
    };
    let quirks = [
        ("cr", with("Time [s],Channel 0", &|t, v| format!("{t:.9},{v}"), "\r")),
        (
            "trailing comma",
            with("Time [s],Channel 0,", &|t, v| format!("{t:.9},{v},"), "\n"),
        ),
        (
            "quoted",
            with(
                "\"Time [s]\",\"Channel 0\"",
                &|t, v| format!("{t:.9},{v}"),
                "\n",
            ),
        ),
        (
            "us",
            with("Time [us],Channel 0", &|t, v| format!("{:.3},{v}", t * 1e6), "\n"),
        ),
        (
            "ms",
            with("Time [ms],Channel 0", &|t, v| format!("{:.6},{v}", t * 1e3), "\n"),
        ),
        (
            "float levels",
            with("Time [s],Channel 0", &|t, v| format!("{t:.9},{v}.0"), "\n"),
        ),
        (
            "sigrok seconds",
            with(
                "; CSV generated by libsigrok\n; Channels (1/8): D0\n; Samplerate: 1 GHz\nseconds,logic",
                &|t, v| format!("{t:.9},{v}"),
                "\n",
            ),
        ),
    ];
    for (what, text) in &quirks {
        let got = deltas(text, "q.csv");
        assert_eq!(got.len(), want.len(), "{what}");
        for ((s1, d1), (s0, d0)) in got.iter().zip(&want) {
            assert!(
                (s1 - s0).abs() < 1e-9 && (d1 - d0).abs() < 1e-9,
                "{what}: {got:?} against {want:?}"
            );
        }
    }
    let (r, _) = analyze_unit(&quirks[6].1, "s.csv", None, wheel("36-2")).unwrap();
    assert_eq!(r.channel, "D0");
    // A level other than exactly 0 or 1 among them is still refused, as an analog value.
    let half = with("Time [s],Channel 0", &|t, v| format!("{t:.9},{v}.5"), "\n");
    let e = analyze_unit(&half, "h.csv", None, wheel("36-2")).unwrap_err();
    assert!(
        e.contains("`0.5` in the column of channel `Channel 0` is not a logic level"),
        "{e}"
    );
}

/// Two columns of one name: the report names the one read with its number (it said `Channel
/// 0` whichever was read), and the name alone is refused as ambiguous.
#[test]
fn a_name_two_columns_share_is_told_by_number() {
    let rising = wheel_teeth(36, 2, 150.0, 0.34);
    let clean = saleae_of_rising(&rising, 1e9, 0.35);
    let mut text = String::from("Time [s],Channel 0,Channel 0\n");
    for l in clean.lines().skip(1) {
        text.push_str(&format!("{l},0\n"));
    }
    let read = |c: host_sim::app::analyze::Channel| {
        analyze_unit(
            &text,
            "d.csv",
            None,
            AnalyzeOptions {
                channel: Some(c),
                ..wheel("36-2")
            },
        )
    };
    let (r, said) = read(host_sim::app::analyze::Channel::Column(1)).unwrap();
    assert_eq!(r.channel, "Channel 0 (channel 1)");
    assert!(
        said.contains("channel: Channel 0 (channel 1) (rising edges)"),
        "{said}"
    );
    let (r, _) = read(host_sim::app::analyze::Channel::Column(0)).unwrap();
    assert_eq!(r.channel, "Channel 0 (channel 0)");
    assert!(r.valid_windows >= 3);
    let e = read(host_sim::app::analyze::Channel::Name("Channel 0".into())).unwrap_err();
    assert!(e.contains("2 channels have that name (numbers 0, 1"), "{e}");
}

/// A value change dump declaring `D0` in two scopes names both by their scope path, as the
/// README's SCOPE.NAME says (the first was `D0`, and `--channel logic.D0` was refused).
#[test]
fn channels_sharing_a_name_in_a_dump_are_named_by_their_scopes() {
    let vcd = "$timescale 1 us $end\n$scope module logic $end\n$var wire 1 ! D0 $end\n\
               $var wire 1 \" D1 $end\n$scope module sub $end\n$var wire 1 % D0 $end\n\
               $upscope $end\n$upscope $end\n$enddefinitions $end\n#0 0! 0\" 0%\n#5 1!\n#9\n";
    let r = text_reader(vcd.to_string(), "s.vcd", None).unwrap();
    assert_eq!(r.channels(), ["logic.D0", "D1", "logic.sub.D0"]);
    let e = analyze_unit(
        vcd,
        "s.vcd",
        None,
        AnalyzeOptions {
            channel: Some(host_sim::app::analyze::Channel::Name("D0".into())),
            ..wheel("36-2")
        },
    )
    .unwrap_err();
    assert!(
        e.contains("named by their scopes: logic.D0, logic.sub.D0"),
        "{e}"
    );
}

/// A grid found from the rows alone is the longest step they show, which the floor takes as
/// their resolution; the report said it was "taken as the sample period", a fact the rows do
/// not show (the analyser's period may be a whole fraction of it).
#[test]
fn the_grid_found_is_not_stated_as_the_sample_period() {
    let rising = steady_disc(360, 300.0, 0.001, 0.2);
    for (rate, text_of) in [
        (750e3, "a 750 kS/s capture written to the nanosecond"),
        (2e6, "a 2 MS/s capture"),
    ] {
        let rows = on_grid(&rising, rate, 0.0);
        let text = csv_of("Time [s],Channel 0", Some(0.0), &rows, ",", |t| {
            format!("{t:.9}")
        });
        let said = host_sim::app::analyze::text(&analyze_text(text, "g.csv", 360, 1));
        let line = said
            .lines()
            .find(|l| l.starts_with("sampling: rate not stated; every transition"))
            .unwrap_or_else(|| panic!("{text_of}: {said}"));
        assert!(
            !line.contains("taken as the sample period"),
            "{text_of}: {line}"
        );
        assert!(
            line.contains("the longest step the rows show")
                && line.contains("no sample period is stated")
                && line.contains("this step or a whole fraction of it"),
            "{text_of}: {line}"
        );
    }
}

/// A cranking stall read clean in `run` (0 faults, 0 invalid windows) while `analyze` of the
/// run's own capture found 2 missing edges, a timeout and an invalid window: `run` fed the core
/// its edges only, without the firmware's periodic standstill check that `analyze` makes
/// between events and at the end of the recording, so the window in progress at the stall was
/// never judged. `run` polls the core alike now: the same windows, faults and timeout.
#[test]
fn a_stall_reads_alike_in_run_and_in_analyze_of_its_capture() {
    let scene = "[motor]\nmodel = \"profile\"\n\
        points = [[0.0, 0.0], [1.0, 25.0], [3.0, 25.0], [3.5, 0.0]]\n\
        [cranking]\nripple = 0.4\nstrokes = 2\nphase = 0.0\n[encoder]\nwheel = \"36-2\"\n\
        timer_hz = 1e6\nestimator_edges = 4\n[simulation]\nduration = 4.0\n";
    let (_scratch, file) = tmp("stall.csv");
    let run = simulate(scene, CaptureFormat::Saleae, &file);
    let (a, _) = run_analyze(
        &file,
        AnalyzeOptions {
            estimator_edges: Some(4),
            ..wheel("36-2")
        },
    );
    assert_eq!(
        (run.windows, run.invalid_windows),
        (a.valid_windows + a.invalid_windows, a.invalid_windows)
    );
    assert_eq!(run.rejected_edges, [a.glitches, a.missing, a.extra]);
    assert_eq!(run.timeouts, a.timeouts);
    // The stall is seen: a timeout once the shaft has stopped, and the window it cut short.
    assert!(run.timeouts >= 1 && run.invalid_windows >= 1, "{run:?}");
}
