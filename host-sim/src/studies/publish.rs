//! `drive-sim accuracy`: regenerates the published cost/accuracy tables and plots.

use crate::app::plot::{write_svg, Chart, Series};
use crate::studies::accuracy::{accuracy_table, markdown, measure_case, AccuracySweep};
use crate::studies::cost::{
    balancer_pareto, crate_comparison, kneader_pareto, scaling, ParetoRow, ScalingRow,
};
use std::fmt::Write;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A line describing the machine the numbers were measured on.
pub fn machine_description() -> String {
    let cpu = std::fs::read_to_string("/proc/cpuinfo")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|m| m.trim().to_string())
        })
        .unwrap_or_else(|| "unknown CPU".into());
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    format!(
        "{cpu}, {cores} cores, {} {}, release build",
        std::env::consts::OS,
        std::env::consts::ARCH
    )
}

fn pareto_table(s: &mut String, rows: &[ParetoRow]) {
    let _ = writeln!(
        s,
        "| setting | RHS evaluations | wall, ms | error | Pareto |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|:-:|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {:.1} | {:.2e} | {} |",
            r.setting,
            r.rhs_evals,
            r.wall_ms,
            r.error,
            if r.pareto { "●" } else { "" }
        );
    }
}

fn scaling_table(s: &mut String, rows: &[ScalingRow]) {
    let _ = writeln!(
        s,
        "| varied | value | edges | RHS evaluations | wall, ms | ns per edge |"
    );
    let _ = writeln!(s, "|---|---|---:|---:|---:|---:|");
    for r in rows {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.1} | {:.0} |",
            r.series, r.value, r.edges, r.rhs_evals, r.wall_ms, r.ns_per_edge
        );
    }
}

fn pareto_plot(path: &Path, title: &str, rows: &[ParetoRow]) -> Result<(), String> {
    let mut series = Vec::new();
    for family in ["rk4", "dp5", "dop853"] {
        let points: Vec<(f64, f64)> = rows
            .iter()
            .filter(|r| r.setting.starts_with(family) && r.error > 0.0 && r.error.is_finite())
            .map(|r| (r.wall_ms.log10(), r.error.log10()))
            .collect();
        series.push(Series {
            label: family.into(),
            points,
            markers: true,
        });
    }
    write_svg(
        path,
        &Chart {
            title,
            x_label: "log10 wall time, ms",
            y_label: "log10 error",
            series,
            marks: Vec::new(),
        },
    )
}

/// What the firmware reported: `bench` lines as (name, instructions), its footprint line, its
/// `memory:` and `stack: construct` lines, and its `accuracy` and `delta:` lines (errors
/// against f64 or exact references, on the target).
struct TargetReport {
    benches: Vec<(String, String)>,
    compiler: String,
    footprint: String,
    memory: Vec<String>,
    accuracy: Vec<String>,
}

/// `bench <name, may contain spaces> <instructions>` as (name, instructions).
fn bench_line(line: &str) -> Option<(String, String)> {
    let rest = line.strip_prefix("bench ")?;
    let (name, n) = rest.trim_end().rsplit_once(char::is_whitespace)?;
    Some((name.trim().to_string(), n.to_string()))
}

/// The monitor's instructions per edge, edge by edge and in DMA batches of 64, from the bench
/// lines (printed with two decimals, `44.33`; an integer reads too).
fn per_edge_figures(benches: &[(String, String)]) -> Option<(f64, f64)> {
    let find = |name: &str| {
        benches
            .iter()
            .find(|(n, _)| n == name)
            .and_then(|(_, v)| v.parse::<f64>().ok())
    };
    find("monitor::on_edge").zip(find("monitor::on_captures/64"))
}

/// Runs the firmware under QEMU and collects what it reports.
fn target_benches() -> Result<TargetReport, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new("bash")
        .arg(root.join("examples/qemu/run.sh"))
        .output()
        .map_err(|e| format!("examples/qemu/run.sh: {e}"))?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    if !out.status.success() {
        return Err(format!(
            "examples/qemu/run.sh failed:\n{text}{}",
            String::from_utf8_lossy(&out.stderr)
        ));
    }
    let benches = text.lines().filter_map(bench_line).collect();
    let footprint = text
        .lines()
        .find(|l| l.starts_with("footprint:"))
        .unwrap_or("")
        .to_string();
    let compiler = text
        .lines()
        .find_map(|l| l.strip_prefix("compiler: "))
        .ok_or("examples/qemu/run.sh printed no `compiler:` line")?
        .trim()
        .to_string();
    let accuracy = text
        .lines()
        .filter(|l| l.starts_with("accuracy ") || l.starts_with("delta: "))
        .map(|l| l.split_whitespace().collect::<Vec<_>>().join(" "))
        .collect();
    let memory = text
        .lines()
        .filter(|l| l.starts_with("memory: ") || l.starts_with("stack: construct "))
        .map(|l| l.trim_end().to_string())
        .collect();
    Ok(TargetReport {
        benches,
        compiler,
        footprint,
        memory,
        accuracy,
    })
}

/// The heading of the page's on-target section.
const TARGET_HEADING: &str = "## On the Cortex-M4F (QEMU mps2-an386, `-icount shift=0`)";

/// Measures everything and writes `accuracy.md` and the SVG plots into `out`; refuses,
/// without `target`, to replace a page that has the on-target section.
pub fn accuracy(out: &Path, target: bool) -> Result<Vec<PathBuf>, String> {
    // A page measured with --target is not replaced by one without its on-target section
    // (the README quotes the figures from it).
    let page = out.join("accuracy.md");
    if !target {
        if let Ok(old) = std::fs::read_to_string(&page) {
            if old.contains(TARGET_HEADING) {
                return Err(format!(
                    "{} holds the on-target figures of a run with --target, which this page \
                     without --target would drop: give --target (it runs the firmware under \
                     QEMU) or another --out",
                    page.display()
                ));
            }
        }
    }
    std::fs::create_dir_all(out).map_err(|e| format!("{}: {e}", out.display()))?;
    let mut files = Vec::new();
    let mut md = String::new();
    let _ = writeln!(md, "# What accuracy costs\n");
    let _ = writeln!(
        md,
        "Regenerated by `cargo run --release -p host-sim -- accuracy --out {}{}`. \
         Host numbers measured on: {}.\n",
        out.display(),
        if target { " --target" } else { "" },
        machine_description()
    );
    // Headline: a 1024-line encoder on a 170 MHz Cortex-M4 at 3000 rpm, the kneader's ripple.
    let rpm = 3000.0;
    let omega = rpm * std::f64::consts::TAU / 60.0;
    let edges_per_s = rpm / 60.0 * 1024.0;
    let mut per_edge: Option<(f64, f64)> = None;
    let mut target_section = String::new();
    if target {
        let TargetReport {
            benches,
            compiler,
            footprint,
            memory,
            accuracy,
        } = target_benches()?;
        per_edge = per_edge_figures(&benches);
        let md = &mut target_section;
        let _ = writeln!(md, "{TARGET_HEADING}\n");
        let _ = writeln!(
            md,
            "Instructions per call, counted with SysTick, firmware built by {compiler} (the \
             counts depend on its code generation); {footprint}.\n"
        );
        let _ = writeln!(md, "| path | instructions per call |\n|---|---:|");
        for (name, n) in &benches {
            let _ = writeln!(md, "| `{name}` | {n} |");
        }
        let _ = writeln!(
            md,
            "\n`monitor::*` are per edge, amortised over the whole stream (acquisition, index \
             pulses and windows included); `on_captures/N` feeds it in batches of N captures, \
             as a DMA half-buffer does. RAM of the monitor and the stack its configuration in \
             place takes:\n"
        );
        for line in memory {
            let _ = writeln!(md, "- `{line}`");
        }
        let _ = writeln!(
            md,
            "\nThe error each variant buys, measured on the target against an f64 (or exact) \
             reference on the same inputs:\n"
        );
        for line in accuracy {
            let _ = writeln!(md, "- `{line}`");
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(
        md,
        "## Recommended configuration
"
    );
    let _ = writeln!(
        md,
        "A 1024-line encoder with an index pulse on a 170 MHz 32-bit capture timer, speed \
         samples over K = 16 edges, δ windows of one load cycle. At {rpm} rpm ({omega:.1} rad/s, \
         {edges_per_s:.0} edges/s) on the kneader's ripple (δ = {:.4}):\n",
        2.0 * AccuracySweep::default().epsilon
    );
    let _ = writeln!(
        md,
        "| K | δ error | quantization floor | averaging bias |\n|---:|---:|---:|---:|"
    );
    for k in [1u16, 4, 16] {
        let r = measure_case(omega, AccuracySweep::default().epsilon, 1024, 170e6, k, 3)
            .map_err(|e| e.to_string())?;
        let _ = writeln!(
            md,
            "| {k} | {:.3} % | {:.3} % | {:.4} % |",
            100.0 * r.error,
            100.0 * r.quantization_floor,
            100.0 * r.averaging_bias
        );
    }
    match per_edge {
        Some((n, batch)) => {
            let _ = writeln!(
                md,
                "\nCPU load of the monitor: {n} instructions per edge × {edges_per_s:.0} edges/s = \
                 {:.1} M instructions/s, **{:.1} %** of a 170 MHz Cortex-M4 at one instruction per \
                 cycle edge by edge, {:.1} % fed in DMA batches of 64 ({batch} per edge); loads, \
                 taken branches and divisions take more cycles on the real core, so treat these \
                 as the floor of the load.\n",
                n * edges_per_s / 1e6,
                100.0 * n * edges_per_s / 170e6,
                100.0 * batch * edges_per_s / 170e6
            );
        }
        None => {
            let _ = writeln!(
                md,
                "\nThe CPU load needs the on-target instruction count: run with `--target`.\n"
            );
        }
    }
    md.push_str(&target_section);
    let _ = writeln!(
        md,
        "## δ accuracy against encoder lines, timer clock and K\n"
    );
    let _ = writeln!(
        md,
        "Measured by `DeltaMonitor` (the target's code, run on the host) from an exact pulse train \
         of ω(φ) = ω̄(1 + ε·sin(φ/8)) with ω̄ = {} rad/s, δ = 2ε exactly; errors and floors in \
         percent of δ. The quantization floor 2/(ticks per sample) is the physical limit; the \
         K-edge average adds the bias (K·p/8)²/24.\n",
        AccuracySweep::default().omega_mean
    );
    md.push_str(&markdown(&accuracy_table(&AccuracySweep::default())));
    let _ = writeln!(md);
    let kneader = kneader_pareto()?;
    let balancer = balancer_pareto()?;
    let _ = writeln!(md, "## Simulator: error against wall time\n");
    let _ = writeln!(
        md,
        "Kneader (30 s, 1024 lines, edges generated): error = max |ω²/u(φ) − 1| against the \
         exact steady state (seed 000 eq. 11) after 10 s, at step ends and mid-steps.\n"
    );
    pareto_table(&mut md, &kneader);
    let _ = writeln!(
        md,
        "\nTwo-mass auto-balancer at 100 rad/s (10 s): error = largest deviation of any state \
         from a DOP853 rtol 1e-13 run at 200 instants, relative to that state's largest value.\n"
    );
    pareto_table(&mut md, &balancer);
    for (name, rows, title) in [
        (
            "pareto-kneader.svg",
            &kneader,
            "Kneader: error against wall time",
        ),
        (
            "pareto-two-mass.svg",
            &balancer,
            "Two-mass auto-balancer: error against wall time",
        ),
    ] {
        let path = out.join(name);
        pareto_plot(&path, title, rows)?;
        let _ = writeln!(md, "\n![{title}]({name})");
        files.push(path);
    }
    let _ = writeln!(md, "\n## The own stepper against a well-kept crate\n");
    let _ = writeln!(
        md,
        "The simulator has its own steppers because edge location needs each step's dense \
         output as a polynomial it can evaluate with its derivative many times per step. Here \
         its DOPRI5 and `ode_solvers::Dopri5` (0.6) integrate the same kneader ODE for 30 s with \
         output every 1 ms; error = max |ω²/u(φ) − 1| at those instants after 10 s.\n"
    );
    let _ = writeln!(
        md,
        "| stepper | rtol | wall, ms | error |\n|---|---:|---:|---:|"
    );
    for r in crate_comparison()? {
        let _ = writeln!(
            md,
            "| {} | {:.0e} | {:.2} | {:.2e} |",
            r.stepper, r.rtol, r.wall_ms, r.error
        );
    }
    let rows = scaling()?;
    let _ = writeln!(
        md,
        "\n## Simulator: cost against duration, lines and effects\n"
    );
    let _ = writeln!(
        md,
        "The kneader scene run whole (simulation, edges, the core's monitor). The cost per edge \
         stays flat as duration and lines grow: the run is linear in edges.\n"
    );
    scaling_table(&mut md, &rows);
    let path = out.join("accuracy.md");
    std::fs::write(&path, md).map_err(|e| format!("{}: {e}", path.display()))?;
    files.push(path);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A page with the on-target section is not replaced by one without it (the README
    /// quotes its figures): refused before anything is measured, the page left as it was.
    #[test]
    fn a_page_without_target_figures_does_not_replace_one_with_them() {
        let dir = tempfile::tempdir().unwrap();
        let page = dir.path().join("accuracy.md");
        std::fs::write(
            &page,
            format!("# What accuracy costs\n\n{TARGET_HEADING}\n"),
        )
        .unwrap();
        let e = accuracy(dir.path(), false).unwrap_err();
        assert!(e.contains("accuracy.md holds the on-target figures") && e.contains("--target"));
        assert!(std::fs::read_to_string(&page)
            .unwrap()
            .contains(TARGET_HEADING));
    }

    #[test]
    fn bench_lines_keep_names_with_spaces() {
        assert_eq!(
            bench_line("bench supports::set_unbalance micromath      71"),
            Some(("supports::set_unbalance micromath".into(), "71".into()))
        );
        assert_eq!(
            bench_line("bench monitor::on_captures/64           24"),
            Some(("monitor::on_captures/64".into(), "24".into()))
        );
        // The per-edge figures come with two decimals.
        assert_eq!(
            bench_line("bench monitor::on_captures/64        19.71"),
            Some(("monitor::on_captures/64".into(), "19.71".into()))
        );
        assert_eq!(bench_line("accuracy libm::sqrt 5e-8"), None);
    }

    #[test]
    fn per_edge_figures_read_two_decimals() {
        let benches: Vec<_> = [
            "bench monitor::on_edge               44.33",
            "bench monitor::on_edge+learner       54.85",
            "bench monitor::on_captures/64        19.71",
            "bench monitor::on_captures/1024      15.76",
        ]
        .into_iter()
        .filter_map(bench_line)
        .collect();
        assert_eq!(per_edge_figures(&benches), Some((44.33, 19.71)));
        assert_eq!(per_edge_figures(&benches[..2]), None);
    }
}
