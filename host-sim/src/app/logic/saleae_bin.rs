//! Saleae Logic 2's binary export of digital channels: one file a channel (`digital_0.bin`,
//! `digital_1.bin`, ... in the folder the export writes), each the times at which its level
//! changes.
//!
//! Every file starts with `<SALEAE>`, an `int32` version and an `int32` type (0: digital; 1,
//! analog, is not read); all values little-endian. Version 0 (Logic 8, Logic Pro 8 and 16):
//! `uint32 initial_state`, `double begin_time`, `double end_time`, `uint64 num_transitions`,
//! then as many `double` transition times, s. Version 1 (the MSO devices): `uint64
//! chunk_count`, then for each chunk (a continuous stretch of data; between two chunks the
//! channel has none) `uint32 initial_state`, `double sample_rate`, `double begin_time`,
//! `double end_time`, `uint64 num_transitions` and the transition times. The level alternates
//! at each transition from the initial state.
//!
//! The channels are merged in time order as they are read (memory does not grow with the
//! capture): a row at the earliest begin time with each channel's initial level (no data for a
//! channel not begun), a row at every time at which a channel changes, a channel without data
//! between two of its chunks, and a last row at the latest end time (the end of the
//! recording). A channel `digital_N.bin` is named `Channel N`, as in Logic 2's CSV export.

use std::fs::File;
use std::io::{BufReader, Read};
use std::path::{Path, PathBuf};

use super::Level;

/// The eight bytes every Saleae binary export starts with.
pub(super) const MAGIC: [u8; 8] = *b"<SALEAE>";

/// One channel's file being read.
#[derive(Debug)]
struct Channel {
    file: PathBuf,
    input: BufReader<File>,
    version: i32,
    /// Chunks not yet begun (version 1; version 0 has one).
    chunks_left: u64,
    /// Transitions left in the current chunk.
    left: u64,
    /// The level after the last event.
    level: Level,
    /// The next event: its time and the level from it on (`None` after the last).
    next: Option<(f64, Level)>,
    /// The current chunk's end, s, and whether it ends without data (another chunk follows).
    chunk_end: f64,
    /// The sample rates of the chunks read (version 1).
    rate: Option<f64>,
    /// The latest end time of a chunk, s.
    end: f64,
    /// The time of the last transition read, s.
    last: f64,
}

fn read_exact<const N: usize>(c: &mut BufReader<File>) -> std::io::Result<[u8; N]> {
    let mut b = [0u8; N];
    c.read_exact(&mut b)?;
    Ok(b)
}

impl Channel {
    fn open(file: &Path) -> Result<Self, String> {
        let name = file.display();
        let f = File::open(file).map_err(|e| format!("{name}: cannot open: {e}"))?;
        let mut input = BufReader::new(f);
        let head: [u8; 16] = read_exact(&mut input)
            .map_err(|_| format!("{name}: shorter than the header of a Saleae binary export"))?;
        if head[..8] != MAGIC {
            return Err(format!(
                "{name}: does not start with `<SALEAE>`: not a Saleae binary export"
            ));
        }
        let version = i32::from_le_bytes([head[8], head[9], head[10], head[11]]);
        let kind = i32::from_le_bytes([head[12], head[13], head[14], head[15]]);
        if kind != 0 {
            return Err(format!(
                "{name}: a Saleae binary export of type {kind}{}, not of a digital channel \
                 (type 0): export the encoder's digital channels",
                if kind == 1 { " (analog)" } else { "" }
            ));
        }
        if version != 0 && version != 1 {
            return Err(format!(
                "{name}: a Saleae binary export of version {version}: analyze reads versions 0 \
                 and 1"
            ));
        }
        let mut c = Channel {
            file: file.to_path_buf(),
            input,
            version,
            chunks_left: 1,
            left: 0,
            level: Level::Unknown,
            next: None,
            chunk_end: f64::NEG_INFINITY,
            rate: None,
            end: f64::NEG_INFINITY,
            last: f64::NEG_INFINITY,
        };
        if version == 1 {
            c.chunks_left = u64::from_le_bytes(c.bytes("the chunk count")?);
        }
        c.begin_chunk()?;
        Ok(c)
    }

    /// `N` bytes of the file, saying what they were to be when it ends.
    fn bytes<const N: usize>(&mut self, what: &str) -> Result<[u8; N], String> {
        read_exact(&mut self.input).map_err(|e| {
            format!(
                "{}: ends before {what} ({e}): the file is cut off",
                self.file.display()
            )
        })
    }

    fn double(&mut self, what: &str) -> Result<f64, String> {
        let x = f64::from_le_bytes(self.bytes(what)?);
        if x.is_finite() {
            Ok(x)
        } else {
            Err(format!("{}: {what} is {x}", self.file.display()))
        }
    }

    /// Reads the next chunk's header, its first event the chunk's begin with its initial
    /// level; `next` is `None` when no chunk is left.
    fn begin_chunk(&mut self) -> Result<(), String> {
        if self.chunks_left == 0 {
            self.next = None;
            return Ok(());
        }
        self.chunks_left -= 1;
        let initial = u32::from_le_bytes(self.bytes("a chunk's initial state")?);
        if self.version == 1 {
            let rate = self.double("a chunk's sample rate")?;
            if rate <= 0.0 {
                return Err(format!(
                    "{}: a chunk's sample rate is {rate} Hz",
                    self.file.display()
                ));
            }
            if self.rate.is_some_and(|r| r != rate) {
                return Err(format!(
                    "{}: its chunks were sampled at {} and {rate} Hz: analyze reads a capture \
                     of one sample rate",
                    self.file.display(),
                    self.rate.unwrap_or(rate)
                ));
            }
            self.rate = Some(rate);
        }
        let begin = self.double("a chunk's begin time")?;
        let end = self.double("a chunk's end time")?;
        if end < begin || begin < self.chunk_end {
            return Err(format!(
                "{}: a chunk from {begin} s to {end} s, {}",
                self.file.display(),
                if end < begin {
                    "ending before it begins".to_string()
                } else {
                    format!(
                        "beginning before the chunk before it ends ({} s)",
                        self.chunk_end
                    )
                }
            ));
        }
        self.left = u64::from_le_bytes(self.bytes("the count of transitions")?);
        self.chunk_end = end;
        self.end = self.end.max(end);
        self.last = begin;
        self.next = Some((
            begin,
            if initial == 0 {
                Level::Low
            } else {
                Level::High
            },
        ));
        Ok(())
    }

    /// Takes the next event (its level becomes the channel's) and reads the one after it.
    fn advance(&mut self) -> Result<(), String> {
        let Some((_, level)) = self.next else {
            return Ok(());
        };
        self.level = level;
        if level == Level::Unknown {
            // The gap after a chunk: the next chunk begins.
            return self.begin_chunk();
        }
        if self.left > 0 {
            self.left -= 1;
            let t = self.double("a transition's time")?;
            if t < self.last || t > self.chunk_end {
                return Err(format!(
                    "{}: a transition at {t} s, {}",
                    self.file.display(),
                    if t < self.last {
                        format!("before the one before it ({} s)", self.last)
                    } else {
                        format!("after its chunk's end ({} s)", self.chunk_end)
                    }
                ));
            }
            self.last = t;
            let flipped = if level == Level::High {
                Level::Low
            } else {
                Level::High
            };
            self.next = Some((t, flipped));
            return Ok(());
        }
        if self.chunks_left > 0 {
            // No data from this chunk's end to the next one's begin.
            self.next = Some((self.chunk_end, Level::Unknown));
            return Ok(());
        }
        self.next = None;
        // Nothing may follow the last chunk.
        let mut extra = [0u8; 1];
        if self.input.read(&mut extra).map_err(|e| e.to_string())? > 0 {
            return Err(format!(
                "{}: bytes after its last transition: not one channel's binary export",
                self.file.display()
            ));
        }
        Ok(())
    }
}

/// A Saleae binary export being read: its channels merged in time order.
#[derive(Debug)]
pub(super) struct Export {
    channels: Vec<Channel>,
    /// The channels' names, in order.
    pub(super) names: Vec<String>,
    /// The last row's time, and whether the last (end of recording) row was given.
    last: Option<f64>,
    ended: bool,
}

/// `Channel N` for `digital_N.bin`, else the file's stem.
fn channel_name(file: &Path) -> (u64, String) {
    let stem = file
        .file_stem()
        .map(|s| s.to_string_lossy().to_string())
        .unwrap_or_default();
    match stem.strip_prefix("digital_").and_then(|n| n.parse().ok()) {
        Some(n) => (n, format!("Channel {n}")),
        None => (u64::MAX, stem),
    }
}

impl Export {
    /// The export at `path`: a folder (every `*.bin` in it that is a digital channel's export;
    /// an analog one, `analog_N.bin`, is passed over) or one channel's file.
    pub(super) fn open(path: &Path) -> Result<Self, String> {
        let mut files: Vec<PathBuf> = if path.is_dir() {
            let entries = std::fs::read_dir(path)
                .map_err(|e| format!("{}: cannot list the folder: {e}", path.display()))?;
            let mut files = Vec::new();
            for entry in entries {
                let p = entry
                    .map_err(|e| format!("{}: cannot list the folder: {e}", path.display()))?
                    .path();
                let bin = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("bin"));
                let analog = p
                    .file_name()
                    .is_some_and(|n| n.to_string_lossy().starts_with("analog_"));
                if bin && !analog && p.is_file() {
                    files.push(p);
                }
            }
            if files.is_empty() {
                return Err(format!(
                    "{}: a folder without a digital channel's binary export (digital_0.bin, \
                     ...): give a capture file, or the folder Saleae Logic 2 exported the raw \
                     data of digital channels to as binary",
                    path.display()
                ));
            }
            files
        } else {
            vec![path.to_path_buf()]
        };
        files.sort_by_key(|f| channel_name(f));
        let mut channels = Vec::new();
        let mut names = Vec::new();
        for f in &files {
            let c = Channel::open(f)?;
            if let Some(first) = channels.first() {
                let first: &Channel = first;
                if first.version != c.version || first.rate != c.rate {
                    return Err(format!(
                        "{} and {} are exports of different versions or sample rates: not one \
                         capture",
                        first.file.display(),
                        c.file.display()
                    ));
                }
            }
            channels.push(c);
            names.push(channel_name(f).1);
        }
        for w in names.windows(2) {
            if w[0] == w[1] {
                return Err(format!("two files give the channel `{}`", w[0]));
            }
        }
        Ok(Export {
            channels,
            names,
            last: None,
            ended: false,
        })
    }

    /// The sample rate the export states (version 1), Hz.
    pub(super) fn rate(&self) -> Option<f64> {
        self.channels.first().and_then(|c| c.rate)
    }

    /// The next row: its time, s, the levels written to `levels` (in [`Export::names`]
    /// order); `None` after the last.
    pub(super) fn next_row(&mut self, levels: &mut [Level]) -> Result<Option<f64>, String> {
        let earliest = self
            .channels
            .iter()
            .filter_map(|c| c.next.map(|(t, _)| t))
            .fold(None, |m: Option<f64>, t| Some(m.map_or(t, |m| m.min(t))));
        let Some(t) = earliest else {
            // The end of the recording: a row at the latest end, unless one was given there.
            let end = self
                .channels
                .iter()
                .map(|c| c.end)
                .fold(f64::NEG_INFINITY, f64::max);
            if self.ended || self.last.is_some_and(|l| l >= end) {
                return Ok(None);
            }
            self.ended = true;
            self.last = Some(end);
            for (level, c) in levels.iter_mut().zip(&self.channels) {
                *level = c.level;
            }
            return Ok(Some(end));
        };
        for c in &mut self.channels {
            // Every event at this time (a transition at a chunk's very begin, or several at
            // one sample).
            while c.next.is_some_and(|(u, _)| u == t) {
                c.advance()?;
            }
        }
        for (level, c) in levels.iter_mut().zip(&self.channels) {
            *level = c.level;
        }
        self.last = Some(t);
        Ok(Some(t))
    }
}
