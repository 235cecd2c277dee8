//! Value change dumps (VCD, IEEE 1364 §18): what sigrok-cli and PulseView (`-O vcd`), Saleae
//! Logic 2 and HDL simulators export.
//!
//! A header of `$keyword ... $end` sections: `$timescale` (`1 ns`, `10us`: the unit of every
//! time, required: it is never guessed), `$scope`/`$upscope`, `$var TYPE SIZE ID NAME [BITS]
//! $end` (each 1-bit variable is a channel, named NAME, or SCOPE.NAME when another channel
//! already has that name; wider vectors are not channels and their changes are skipped), and
//! `$date`, `$version`, `$comment` (sigrok's `Acquisition with 2/8 channels at 1 MHz` gives the
//! sample rate). Then `$enddefinitions $end` and the changes: `#T` (the time in units, never
//! decreasing), scalar changes `0ID`, `1ID`, `xID`, `zID` (x and z read as no data: no edge
//! is taken across them), vector changes `bVALUE ID` (`b0`/`b1` on a 1-bit channel) and real
//! ones `rVALUE ID` and strings `sTEXT ID` (skipped; variables of type real, realtime,
//! string or event are no channels whatever their size), the `$dumpvars`, `$dumpall`, `$dumpon`, `$dumpoff` blocks, any
//! number of them on a line. A row is the levels once every change at a time is applied, at
//! that time; a `#T` without changes (the end of a recording) is a row too. Times are read
//! exactly in attoseconds and counted from the first time's whole seconds when they are
//! 10 000 s or more, as decimal times are.

use std::collections::{HashMap, HashSet, VecDeque};
use std::io::BufRead;

use super::{clip, parse_rate, CaptureError, CaptureReader, Level, ATTO};

/// The state of a VCD being read.
#[derive(Debug, Default)]
pub(super) struct Vcd {
    /// The channels each identifier code drives (a code may name several variables).
    ids: HashMap<String, Vec<usize>>,
    /// The identifier codes of variables wider than a bit (and reals): no channels.
    vectors: HashSet<String>,
    /// Attoseconds per time unit (`$timescale`).
    unit_atto: i128,
    /// The tokens of the current line not read yet.
    tokens: VecDeque<String>,
    /// The time, in units, whose changes are being gathered (none before the first `#T`).
    time: Option<u128>,
    /// Whether a change or a `#T` has been read since the last row was given.
    pending: bool,
    /// Each channel's last change of level: the time, units.
    changed_at: Vec<Option<u128>>,
    /// Each channel's changes at a time stamp at which it had changed already, and the first
    /// such time, units.
    merged: Vec<(u64, Option<u128>)>,
}

impl Vcd {
    /// Channel `k`'s changes merged into one time stamp, and the first such time, units.
    pub(super) fn merged(&self, k: usize) -> (u64, Option<u128>) {
        self.merged.get(k).copied().unwrap_or((0, None))
    }

    /// Attoseconds per time unit.
    pub(super) fn unit_atto(&self) -> i128 {
        self.unit_atto
    }
}

/// Attoseconds in one unit of a `$timescale`.
fn unit_atto(unit: &str) -> Option<i128> {
    Some(match unit {
        "s" => ATTO,
        "ms" => ATTO / 1_000,
        "us" => ATTO / 1_000_000,
        "ns" => ATTO / 1_000_000_000,
        "ps" => 1_000_000,
        "fs" => 1_000,
        _ => return None,
    })
}

impl<R: BufRead> CaptureReader<R> {
    /// The next whitespace-separated token of the file, or `None` at its end.
    fn vcd_token(&mut self) -> Result<Option<String>, CaptureError> {
        loop {
            if let Some(t) = self.vcd.tokens.pop_front() {
                return Ok(Some(t));
            }
            let Some(line) = self.read_line()? else {
                return Ok(None);
            };
            self.vcd
                .tokens
                .extend(line.split_whitespace().map(str::to_string));
        }
    }

    /// The tokens up to the next `$end` (which is read), joined by spaces.
    fn vcd_section(&mut self, keyword: &str) -> Result<String, CaptureError> {
        let mut words: Vec<String> = Vec::new();
        loop {
            match self.vcd_token()? {
                Some(t) if t == "$end" => return Ok(words.join(" ")),
                Some(t) => words.push(t),
                None => {
                    return Err(self.err_here(&format!(
                        "the file ends inside `{keyword}`: no `$end` closes it"
                    )))
                }
            }
        }
    }

    /// Reads the header up to `$enddefinitions $end`; `first` is the file's first line.
    pub(super) fn header_vcd(&mut self, first: String) -> Result<(), CaptureError> {
        self.vcd
            .tokens
            .extend(first.split_whitespace().map(str::to_string));
        let mut scopes: Vec<String> = Vec::new();
        // Each channel's full name, its scopes' and its own (`logic.sub.D0`).
        let mut paths: Vec<String> = Vec::new();
        let mut unit: Option<i128> = None;
        loop {
            let Some(keyword) = self.vcd_token()? else {
                return Err(self.err_here(
                    "the file ends in its header: no `$enddefinitions $end` (not a complete value \
                     change dump)",
                ));
            };
            match keyword.as_str() {
                "$enddefinitions" => {
                    self.vcd_section(&keyword)?;
                    break;
                }
                "$timescale" => {
                    let text = self.vcd_section(&keyword)?;
                    let compact: String = text.split_whitespace().collect();
                    let digits = compact.len() - compact.trim_start_matches(['0', '1']).len();
                    let (number, name) = compact.split_at(digits);
                    let atto = match (number, unit_atto(name)) {
                        ("1", Some(u)) => Some(u),
                        ("10", Some(u)) => Some(u * 10),
                        ("100", Some(u)) => Some(u * 100),
                        _ => None,
                    };
                    unit = Some(atto.ok_or_else(|| {
                        self.err_here(&format!(
                            "`$timescale {}`: expected 1, 10 or 100 of s, ms, us, ns, ps or fs",
                            clip(&text)
                        ))
                    })?);
                }
                "$scope" => {
                    let text = self.vcd_section(&keyword)?;
                    scopes.push(text.split_whitespace().nth(1).unwrap_or("").to_string());
                }
                "$upscope" => {
                    self.vcd_section(&keyword)?;
                    scopes.pop();
                }
                "$var" => {
                    let text = self.vcd_section(&keyword)?;
                    let f: Vec<&str> = text.split_whitespace().collect();
                    let [kind, size, id, name, bits @ ..] = f.as_slice() else {
                        return Err(self.err_here(&format!(
                            "`$var {}`: expected `$var TYPE SIZE ID NAME $end`",
                            clip(&text)
                        )));
                    };
                    // Reals, strings and events carry no level whatever size a writer gives
                    // them (GTKWave's lxt2vcd declares a real `$var real 1`).
                    let levelless = ["real", "realtime", "string", "event"]
                        .iter()
                        .any(|k| kind.eq_ignore_ascii_case(k));
                    if *size != "1" || levelless {
                        // A vector (a bus), a real, a string or an event, not a channel: its
                        // changes are skipped.
                        self.vcd.vectors.insert((*id).to_string());
                        continue;
                    }
                    // The reference and its bit select, if any (`data [3]`), or a name a
                    // writer gave with spaces in it (`Channel 0`).
                    let mut channel = [*name]
                        .iter()
                        .chain(bits)
                        .copied()
                        .collect::<Vec<_>>()
                        .join(" ");
                    let path = scopes
                        .iter()
                        .filter(|s| !s.is_empty())
                        .map(String::as_str)
                        .chain([channel.as_str()])
                        .collect::<Vec<_>>()
                        .join(".");
                    // A name another channel has: both are named by their full path
                    // (`logic.D0`, `logic.sub.D0`), so that each is given as named.
                    let repeated: Vec<usize> = (0..self.channels.len())
                        .filter(|&k| self.channels[k] == channel)
                        .collect();
                    if !repeated.is_empty() {
                        for k in repeated {
                            self.channels[k].clone_from(&paths[k]);
                        }
                        channel.clone_from(&path);
                    }
                    paths.push(path);
                    self.vcd
                        .ids
                        .entry((*id).to_string())
                        .or_default()
                        .push(self.channels.len());
                    self.channels.push(channel);
                }
                "$comment" => {
                    let text = self.vcd_section(&keyword)?;
                    // sigrok: `Acquisition with 2/8 channels at 1 MHz`.
                    if let Some((_, rate)) = text.split_once(" channels at ") {
                        if let Some(rate) = parse_rate(rate) {
                            self.stated_rate(rate, &text)?;
                        }
                    }
                }
                k if k.starts_with('$') => {
                    self.vcd_section(k)?;
                }
                other => {
                    return Err(self.err_here(&format!(
                        "`{}` in the header: expected a `$keyword ... $end` section",
                        clip(other)
                    )))
                }
            }
        }
        self.vcd.unit_atto = unit.ok_or_else(|| {
            self.err_here(
                "no `$timescale` in the header: the unit of the file's times is not stated (it \
                 is never guessed)",
            )
        })?;
        Ok(())
    }

    /// The next row of a VCD: the time at which changes were read, s, and the levels after
    /// them; `None` at the end.
    pub(super) fn next_vcd_row(&mut self) -> Result<Option<(f64, &[Level])>, CaptureError> {
        loop {
            let Some(token) = self.vcd_token()? else {
                // The end: the last time's row, if not given yet.
                return match self.vcd.time.filter(|_| self.vcd.pending) {
                    Some(t) => {
                        self.vcd.pending = false;
                        self.vcd_row(t)
                    }
                    None => Ok(None),
                };
            };
            if let Some(digits) = token.strip_prefix('#') {
                // (Past 2^64 units: 5 hours in fs, 213 days in ps.)
                let t: u128 = digits.parse().map_err(|_| {
                    self.err_here(&format!("`{}` is not a time `#UNITS`", clip(&token)))
                })?;
                match self.vcd.time {
                    Some(before) if t < before => {
                        return Err(self.err_here(&format!(
                            "time #{t} is before the previous #{before}: times must not decrease"
                        )))
                    }
                    Some(before) if t == before => {}
                    Some(before) if self.vcd.pending => {
                        // The levels now are those at `before`: its row, then `t`'s changes.
                        self.vcd.time = Some(t);
                        return self.vcd_row(before);
                    }
                    _ => {
                        self.vcd.time = Some(t);
                        self.vcd.pending = true;
                    }
                }
                continue;
            }
            let first = token.chars().next().unwrap_or(' ');
            match first {
                '$' => {
                    if token == "$comment" {
                        self.vcd_section(&token)?;
                    }
                    // `$dumpvars`, `$dumpall`, `$dumpon`, `$dumpoff` and their `$end`: the
                    // changes inside are ordinary changes.
                }
                '0' | '1' | 'x' | 'X' | 'z' | 'Z' => {
                    let id = token[1..].to_string();
                    if id.is_empty() {
                        return Err(self.err_here(&format!(
                            "`{token}`: a scalar change names its identifier right after the value"
                        )));
                    }
                    self.vcd_change(&id, first)?;
                }
                'b' | 'B' | 'r' | 'R' | 's' | 'S' => {
                    let Some(id) = self.vcd_token()? else {
                        return Err(self.err_here(&format!(
                            "`{}`: the file ends before the identifier of this change",
                            clip(&token)
                        )));
                    };
                    // On a channel a vector change is its one bit (the last, should a writer pad
                    // it); a real or a string (`sTEXT ID`) on a channel is no level.
                    let bit = match first {
                        'b' | 'B' => token.chars().last().filter(|_| token.len() > 1),
                        _ => None,
                    };
                    if self.vcd.ids.contains_key(&id) {
                        let Some(bit) = bit else {
                            return Err(self.err_here(&format!(
                                "`{} {}`: not a one-bit value for a one-bit channel",
                                clip(&token),
                                clip(&id)
                            )));
                        };
                        self.vcd_change(&id, bit)?;
                    } else if !self.vcd.vectors.contains(&id) {
                        return Err(self.err_here(&format!(
                            "a change of `{}`, an identifier no `$var` declares",
                            clip(&id)
                        )));
                    }
                }
                _ => {
                    return Err(self.err_here(&format!(
                        "`{}` is not a value change (`0ID`, `1ID`, `xID`, `bVALUE ID`) or a time \
                         `#UNITS`",
                        clip(&token)
                    )))
                }
            }
        }
    }

    /// Sets the channels of identifier `id` to `value`.
    fn vcd_change(&mut self, id: &str, value: char) -> Result<(), CaptureError> {
        let level = match value {
            '0' => Level::Low,
            '1' => Level::High,
            _ => Level::Unknown,
        };
        if self.vcd.time.is_none() {
            // Changes before any `#T` (an initial dump written first): at time 0.
            self.vcd.time = Some(0);
        }
        self.vcd.pending = true;
        match self.vcd.ids.get(id) {
            Some(columns) => {
                let n = self.levels.len();
                if self.vcd.changed_at.len() != n {
                    self.vcd.changed_at = vec![None; n];
                    self.vcd.merged = vec![(0, None); n];
                }
                let now = self.vcd.time;
                for &c in columns {
                    if let Some(l) = self.levels.get_mut(c) {
                        // A change of a known level to the other: a second one at the same
                        // stamp undoes the first (a pulse shorter than the time unit).
                        if *l != level && *l != Level::Unknown && level != Level::Unknown {
                            if self.vcd.changed_at[c] == now {
                                let m = &mut self.vcd.merged[c];
                                m.0 += 1;
                                m.1 = m.1.or(now);
                            }
                            self.vcd.changed_at[c] = now;
                        }
                        *l = level;
                    }
                }
                Ok(())
            }
            // A scalar change of a vector's identifier: no channel.
            None if self.vcd.vectors.contains(id) => Ok(()),
            None => Err(self.err_here(&format!(
                "a change of `{}`, an identifier no `$var` declares",
                clip(id)
            ))),
        }
    }

    /// The row at time `t` (units), s.
    fn vcd_row(&mut self, t: u128) -> Result<Option<(f64, &[Level])>, CaptureError> {
        let atto = i128::try_from(t)
            .ok()
            .and_then(|t| t.checked_mul(self.vcd.unit_atto))
            .ok_or_else(|| {
                self.err_here(&format!(
                    "time #{t} is beyond 1.7e20 s: not a recording's time"
                ))
            })?;
        let time = self.seconds_from_atto(atto);
        self.precision = self.vcd.unit_atto as f64 * 1e-18;
        self.last_time = time;
        self.rows += 1;
        Ok(Some((time, &self.levels)))
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::super::{CaptureFormat, CaptureReader, Level};
    use std::path::Path;

    fn open(
        text: &str,
        rate: Option<f64>,
    ) -> Result<CaptureReader<std::io::Cursor<String>>, String> {
        CaptureReader::new(
            std::io::Cursor::new(text.to_string()),
            Path::new("cap.vcd"),
            None,
            rate,
        )
        .map_err(|e| e.to_string())
    }

    fn reader(text: &str, rate: Option<f64>) -> Result<Vec<(f64, Vec<Level>)>, String> {
        let mut r = open(text, rate)?;
        assert_eq!(r.format(), CaptureFormat::Vcd);
        let mut rows = Vec::new();
        while let Some((t, l)) = r.next_row().map_err(|e| e.to_string())? {
            rows.push((t, l.to_vec()));
        }
        Ok(rows)
    }

    /// A dump as sigrok-cli writes it (`-O vcd`): the rate in a comment, a time and its
    /// changes on one line, an end time alone.
    const SIGROK: &str = "$date Thu Nov 26 2026 $end\n$version libsigrok 0.5.2 $end\n\
        $comment\n  Acquisition with 2/8 channels at 1 MHz\n$end\n$timescale 1 us $end\n\
        $scope module libsigrok $end\n$var wire 1 ! D0 $end\n$var wire 1 \" D1 $end\n\
        $upscope $end\n$enddefinitions $end\n#0 1! 0\"\n#3 0!\n#5 1! 1\"\n#10\n";

    #[test]
    fn a_sigrok_dump_reads_its_rows_and_rate() {
        use Level::{High, Low};
        let rows = reader(SIGROK, None).unwrap();
        let want = [
            (0.0, vec![High, Low]),
            (3e-6, vec![Low, Low]),
            (5e-6, vec![High, High]),
            (10e-6, vec![High, High]),
        ];
        assert_eq!(rows.len(), want.len(), "{rows:?}");
        for ((t, l), (wt, wl)) in rows.iter().zip(&want) {
            assert!((t - wt).abs() < 1e-18, "{t} against {wt}");
            assert_eq!(l, wl);
        }
        let r = open(SIGROK, None).unwrap();
        assert_eq!(r.channels(), ["D0", "D1"]);
        assert_eq!(r.sample_rate(), Some(1e6));
        // A --sample-rate that disagrees with the comment is an error.
        let e = reader(SIGROK, Some(2e6)).unwrap_err();
        assert!(e.contains("1 MHz") && e.contains("--sample-rate"), "{e}");
    }

    /// Simulator-style dumps: scopes, a vector (no channel, its changes skipped), the initial
    /// values in `$dumpvars` before any time, x and z as no data, `b1` on a one-bit channel,
    /// one identifier for two names, a 10 ns unit, several times on one line.
    #[test]
    fn vectors_are_skipped_and_x_is_no_data() {
        use Level::{High, Low, Unknown};
        let text = "$timescale 10ns $end\n$scope module top $end\n$var wire 8 # bus $end\n\
            $var wire 1 ! a $end\n$scope module sub $end\n$var wire 1 ! a $end\n\
            $var reg 1 % z [0] $end\n$upscope $end\n$upscope $end\n$enddefinitions $end\n\
            $dumpvars 0! x% b00000000 # $end\n#2 1! #4 b1 % b11110000 # #7 z! 0%\n";
        let rows = reader(text, None).unwrap();
        let want = [
            (0.0, vec![Low, Low, Unknown]),
            (20e-9, vec![High, High, Unknown]),
            (40e-9, vec![High, High, High]),
            (70e-9, vec![Unknown, Unknown, Low]),
        ];
        assert_eq!(rows.len(), want.len(), "{rows:?}");
        for ((t, l), (wt, wl)) in rows.iter().zip(&want) {
            assert!((t - wt).abs() < 1e-20, "{t} against {wt}");
            assert_eq!(l, wl);
        }
        let r = open(text, None).unwrap();
        assert_eq!(r.channels(), ["top.a", "top.sub.a", "z [0]"]);
    }

    /// Reals, strings and events are no channels whatever size they are declared with (GTKWave's
    /// lxt2vcd writes `$var real 1`): their changes, `rVALUE ID` and `sTEXT ID`, are skipped.
    /// A real declared with size 1 had been read as a one-bit channel and its first change
    /// refused as "not a one-bit value"; a string change as "not a value change".
    #[test]
    fn reals_strings_and_events_are_no_channels() {
        use Level::{High, Low};
        let text = "$timescale 1 ns $end\n$var wire 1 ! a $end\n$var real 1 \" volts $end\n\
            $var string 1 # note $end\n$var event 1 $ tick $end\n$enddefinitions $end\n\
            #0 0! r0.0 \" shello # 1$\n#5 1! r1.5e-3 \" sworld #\n#9 0!\n";
        let rows = reader(text, None).unwrap();
        let r = open(text, None).unwrap();
        assert_eq!(r.channels(), ["a"]);
        let levels: Vec<_> = rows.iter().map(|(t, l)| (*t, l.clone())).collect();
        assert_eq!(
            levels,
            [(0.0, vec![Low]), (5e-9, vec![High]), (9e-9, vec![Low])]
        );
    }

    /// Times read exactly: a large time in picoseconds (20 000 s into a recording) keeps its
    /// resolution, counted from its whole seconds; so does one past 2^64 units (a Unix time in
    /// femtoseconds).
    #[test]
    fn large_times_keep_their_resolution() {
        let text = "$timescale 1 ps $end\n$var wire 1 ! a $end\n$enddefinitions $end\n\
            #20000000000000001 1!\n#20000000000000002 0!\n";
        let mut r = open(text, None).unwrap();
        assert_eq!(r.next_row().unwrap().unwrap().0, 1e-12);
        assert_eq!(r.next_row().unwrap().unwrap().0, 2e-12);
        assert_eq!(r.time_origin(), 20_000);
        let text = "$timescale 1 fs $end\n$var wire 1 ! a $end\n$enddefinitions $end\n\
            #1764130000000000000000001 1!\n";
        let rows = reader(text, None).unwrap();
        assert_eq!(rows[0].0, 1e-15);
    }

    #[test]
    fn bad_dumps_are_named() {
        let body = "$var wire 1 ! a $end\n$enddefinitions $end\n#0 1!\n";
        let cases = [
            (body.to_string(), "no `$timescale`"),
            (format!("$timescale 3 ns $end\n{body}"), "`$timescale 3 ns`"),
            (
                "$timescale 1 ns $end\n$var wire 1 ! a $end\n$enddefinitions $end\n#0 1?\n"
                    .to_string(),
                "`?`, an identifier no `$var` declares",
            ),
            (
                "$timescale 1 ns $end\n$var wire 1 ! a $end\n$enddefinitions $end\n#5 1!\n#4 0!\n"
                    .to_string(),
                "time #4 is before the previous #5",
            ),
            (
                "$timescale 1 ns $end\n$var wire 1 ! a $end\n$enddefinitions $end\n#0 1!\nq!\n"
                    .to_string(),
                "`q!` is not a value change",
            ),
            (
                "$timescale 1 ns $end\n$var wire 1 ! a $end\n".to_string(),
                "no `$enddefinitions $end`",
            ),
            (
                "$timescale 1 ns $end\n$var wire 1 ! a $end\n$enddefinitions $end\n#0 r1.5 !\n"
                    .to_string(),
                "not a one-bit value",
            ),
        ];
        for (text, want) in cases {
            let e = reader(&text, None).unwrap_err();
            assert!(e.contains(want) && e.starts_with("cap.vcd:"), "{want}: {e}");
        }
    }
}
