//! sigrok session files (`.sr`, libsigrok's `srzip`): what PulseView saves and `sigrok-cli -o
//! FILE.sr` writes.
//!
//! A zip archive holding `version` (`2`; `1` in files written before libsigrok 0.4),
//! `metadata` (a key file: a `[device 1]` group with `capturefile = logic-1`, `total probes =
//! N`, `samplerate = 1 MHz`, `unitsize = U` and `probeK = NAME` for each enabled logic channel,
//! channel `K − 1`), and the samples of the logic channels in the entries `logic-1-1`,
//! `logic-1-2`, ... (one entry `logic-1` in version 1), in the order of their numbers: `U`
//! bytes a sample, little-endian, channel `K − 1` in bit `K − 1`. Analog channels
//! (`analog-1-K-n` entries) are not read. Sample `i` is at `i / samplerate` s, as sample `i` of
//! libsigrok's CSV export of the same capture is read.
//!
//! The entries are decompressed as they are read (stored or deflated: what libzip writes), so
//! memory does not grow with the capture, and each must decompress to the size the archive
//! states. A row is given where a channel read changes, at the first sample and at the last
//! (the end of the recording), as the other formats give them.

use std::fs::File;
use std::io::{BufReader, Read, Seek, SeekFrom};
use std::path::{Path, PathBuf};

use super::{clip, parse_rate, Level};

/// The four bytes a zip archive starts with (a local file header).
pub(super) const ZIP_MAGIC: [u8; 4] = *b"PK\x03\x04";

/// Most bytes in a sample (64 channels).
const MAX_UNITSIZE: usize = 8;

/// Bytes decompressed at a time.
const BLOCK: usize = 1 << 16;

/// An entry of samples: its name, number, where its data starts, its sizes and whether it is
/// deflated (else stored).
#[derive(Debug)]
struct Chunk {
    name: String,
    number: u64,
    start: u64,
    compressed: u64,
    size: u64,
    deflated: bool,
}

/// A sigrok session file being read.
pub(super) struct Session {
    file: PathBuf,
    /// The enabled logic channels' names, in the order of their probe numbers.
    pub(super) names: Vec<String>,
    /// Each channel's bit in a sample.
    bits: Vec<u32>,
    /// The bits of the channels read.
    mask: u64,
    unitsize: usize,
    /// The metadata's `samplerate`, Hz, and as written (`None` when absent or 0).
    pub(super) rate: Option<(f64, String)>,
    chunks: Vec<Chunk>,
    next_chunk: usize,
    /// The entry being decompressed, and the bytes it has given.
    source: Option<(Box<dyn Read>, u64)>,
    block: Vec<u8>,
    at: usize,
    filled: usize,
    /// Index of the next sample.
    sample: u64,
    /// The last sample's word (channels read only), and the index of the last sample given as
    /// a row.
    prev: Option<u64>,
    given: Option<u64>,
    ended: bool,
}

impl std::fmt::Debug for Session {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Session")
            .field("file", &self.file)
            .field("names", &self.names)
            .field("unitsize", &self.unitsize)
            .field("chunks", &self.chunks)
            .finish_non_exhaustive()
    }
}

/// The `[device 1]` group of a session file's metadata.
#[derive(Debug, Default)]
struct Device {
    capturefile: Option<String>,
    total_probes: Option<u32>,
    samplerate: Option<String>,
    unitsize: Option<String>,
    /// (K, name) of each `probeK` key.
    probes: Vec<(u32, String)>,
    /// Other device groups than the first.
    others: Vec<String>,
}

/// The metadata's key file: `[group]` lines, `key = value` lines, `#` comments.
fn parse_metadata(text: &str) -> Result<Device, String> {
    let mut device = Device::default();
    let mut group = String::new();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        if let Some(g) = line.strip_prefix('[').and_then(|l| l.strip_suffix(']')) {
            group = g.trim().to_string();
            if group.starts_with("device ") && group != "device 1" {
                device.others.push(group.clone());
            }
            continue;
        }
        let Some((key, value)) = line.split_once('=') else {
            return Err(format!(
                "line {} of `metadata`, `{}`, is neither a `[group]` nor a `key = value`",
                n + 1,
                clip(line)
            ));
        };
        if group != "device 1" {
            continue;
        }
        let (key, value) = (key.trim(), value.trim().to_string());
        match key {
            "capturefile" => device.capturefile = Some(value),
            "total probes" => {
                device.total_probes = Some(value.parse().map_err(|_| {
                    format!(
                        "`total probes = {}` in `metadata` is not a count",
                        clip(&value)
                    )
                })?)
            }
            "samplerate" => device.samplerate = Some(value),
            "unitsize" => device.unitsize = Some(value),
            _ => {
                if let Some(k) = key.strip_prefix("probe") {
                    let k: u32 = k
                        .parse()
                        .map_err(|_| format!("`{}` in `metadata` is no probe number", clip(key)))?;
                    device.probes.push((k, value));
                }
            }
        }
    }
    Ok(device)
}

impl Session {
    /// Opens the session file `path` and reads its metadata and list of entries. Errors are
    /// the message alone (no line: the file is binary).
    pub(super) fn open(path: &Path) -> Result<Self, String> {
        let file = File::open(path).map_err(|e| format!("cannot open: {e}"))?;
        let mut archive = zip::ZipArchive::new(BufReader::new(file)).map_err(|e| {
            format!(
                "starts as a zip archive (a sigrok session file) but cannot be read as one: {e}"
            )
        })?;
        let mut text = |name: &str| -> Result<Option<String>, String> {
            let Ok(mut entry) = archive.by_name(name) else {
                return Ok(None);
            };
            let mut s = String::new();
            entry
                .read_to_string(&mut s)
                .map_err(|e| format!("its `{name}` cannot be read: {e}"))?;
            Ok(Some(s))
        };
        let not_sigrok = "a zip archive without the `version` and `metadata` of a sigrok session \
                          file (PulseView's .sr): not a capture analyze reads";
        let version = text("version")?.ok_or(not_sigrok)?;
        let version = version.trim();
        if version != "1" && version != "2" {
            return Err(format!(
                "a sigrok session file of version `{}`: analyze reads versions 1 and 2",
                clip(version)
            ));
        }
        let metadata = text("metadata")?.ok_or(not_sigrok)?;
        let device = parse_metadata(&metadata)?;
        if let Some(g) = device.others.first() {
            return Err(format!(
                "its `metadata` has a `[{g}]` besides `[device 1]`: analyze reads a session of \
                 one device"
            ));
        }
        let capture =
            match device.capturefile.as_deref() {
                Some(c) => c.to_string(),
                None => return Err(
                    "its `metadata` names no `capturefile`: the session holds no logic channel \
                     (analog channels alone are no encoder signal)"
                        .to_string(),
                ),
            };
        let unitsize: usize =
            match device.unitsize.as_deref() {
                Some(u) => u
                    .parse()
                    .ok()
                    .filter(|&u| (1..=MAX_UNITSIZE).contains(&u))
                    .ok_or_else(|| {
                        format!(
                            "`unitsize = {}` in `metadata`: a sample is 1 to {MAX_UNITSIZE} bytes",
                            clip(u)
                        )
                    })?,
                None => return Err(
                    "its `metadata` has no `unitsize` (the bytes of a sample): libsigrok adds it \
                     with the first samples, so the session holds none"
                        .to_string(),
                ),
            };
        let mut probes = device.probes;
        probes.sort_by_key(|&(k, _)| k);
        let bits_available = 8 * unitsize as u32;
        for w in probes.windows(2) {
            if w[0].0 == w[1].0 {
                return Err(format!("`probe{}` twice in `metadata`", w[0].0));
            }
        }
        for &(k, ref name) in &probes {
            if k == 0 || k > bits_available || device.total_probes.is_some_and(|t| k > t) {
                return Err(format!(
                    "`probe{k} = {}` in `metadata`: a sample of {unitsize} byte(s) holds probes 1 \
                     to {}",
                    clip(name),
                    device
                        .total_probes
                        .map_or(bits_available, |t| t.min(bits_available))
                ));
            }
        }
        if probes.is_empty() {
            return Err("its `metadata` names no enabled logic channel (`probeK = NAME`)".into());
        }
        // libsigrok writes `0 Hz` where the device gave no rate: as good as none.
        let unknown = |t: &str| {
            t.split_whitespace()
                .next()
                .and_then(|n| n.parse::<f64>().ok())
                == Some(0.0)
        };
        let rate = match device.samplerate {
            Some(text) if unknown(&text) => None,
            Some(text) => {
                let hz = parse_rate(&text).ok_or_else(|| {
                    format!(
                        "`samplerate = {}` in `metadata` is not a rate such as `1 MHz`",
                        clip(&text)
                    )
                })?;
                Some((hz, text))
            }
            None => None,
        };
        // The entries of samples, in the order of their numbers (`logic-1-10` after `-9`).
        let mut chunks = Vec::new();
        for i in 0..archive.len() {
            let entry = archive
                .by_index_raw(i)
                .map_err(|e| format!("entry {i} of the archive cannot be read: {e}"))?;
            let name = entry
                .name()
                .map_err(|e| format!("entry {i} of the archive has no readable name: {e}"))?
                .to_string();
            let number = if name == capture {
                Some(1)
            } else {
                name.strip_prefix(capture.as_str())
                    .and_then(|r| r.strip_prefix('-'))
                    .and_then(|n| n.parse::<u64>().ok())
            };
            let Some(number) = number else { continue };
            let deflated = match entry.compression() {
                zip::CompressionMethod::Stored => false,
                zip::CompressionMethod::Deflated => true,
                other => {
                    return Err(format!(
                        "its `{name}` is compressed by {other:?}: analyze reads stored and \
                         deflated entries (what libsigrok writes)"
                    ))
                }
            };
            if entry.encrypted() {
                return Err(format!("its `{name}` is encrypted"));
            }
            let start = entry
                .data_start()
                .ok_or_else(|| format!("where the data of `{name}` starts cannot be read"))?;
            chunks.push(Chunk {
                name,
                number,
                start,
                compressed: entry.compressed_size(),
                size: entry.size(),
                deflated,
            });
        }
        chunks.sort_by_key(|c| c.number);
        for w in chunks.windows(2) {
            if w[0].number == w[1].number {
                return Err(format!(
                    "its entries `{}` and `{}` are both chunk {} of the samples",
                    w[0].name, w[1].name, w[0].number
                ));
            }
        }
        if chunks.is_empty() {
            return Err(format!(
                "the archive holds no `{capture}-1` (or `{capture}`): the session has no samples"
            ));
        }
        let bits: Vec<u32> = probes.iter().map(|&(k, _)| k - 1).collect();
        Ok(Session {
            file: path.to_path_buf(),
            names: probes.into_iter().map(|(_, n)| n).collect(),
            mask: bits.iter().fold(0, |m, &b| m | 1 << b),
            bits,
            unitsize,
            rate,
            chunks,
            next_chunk: 0,
            source: None,
            block: vec![0; BLOCK],
            at: 0,
            filled: 0,
            sample: 0,
            prev: None,
            given: None,
            ended: false,
        })
    }

    /// The next row: the index of a sample where a channel changes (the first and the last
    /// sample are rows too), its levels written to `levels` (in [`Session::names`] order);
    /// `None` after the last.
    pub(super) fn next_change(&mut self, levels: &mut [Level]) -> Result<Option<u64>, String> {
        let row = loop {
            let Some(word) = self.next_sample()? else {
                if self.ended {
                    return Ok(None);
                }
                self.ended = true;
                // The end of the recording: its last sample, unless it was given.
                match (self.prev, self.given) {
                    (Some(w), Some(g)) if self.sample - 1 > g => break (self.sample - 1, w),
                    _ => return Ok(None),
                }
            };
            let i = self.sample;
            self.sample += 1;
            let word = word & self.mask;
            if self.prev != Some(word) {
                self.prev = Some(word);
                self.given = Some(i);
                break (i, word);
            }
        };
        for (level, &b) in levels.iter_mut().zip(&self.bits) {
            *level = if row.1 >> b & 1 == 1 {
                Level::High
            } else {
                Level::Low
            };
        }
        Ok(Some(row.0))
    }

    /// The next sample's bytes as a little-endian word, or `None` after the last.
    fn next_sample(&mut self) -> Result<Option<u64>, String> {
        let u = self.unitsize;
        if self.filled - self.at < u {
            self.refill()?;
            if self.filled - self.at < u {
                if self.filled > self.at {
                    return Err(format!(
                        "the samples end {} byte(s) into a sample of {u}: the last entry is cut \
                         off",
                        self.filled - self.at
                    ));
                }
                return Ok(None);
            }
        }
        let bytes = &self.block[self.at..self.at + u];
        self.at += u;
        Ok(Some(
            bytes.iter().rev().fold(0u64, |w, &b| w << 8 | u64::from(b)),
        ))
    }

    /// Moves the bytes not read to the front of the block and fills the rest from the entries
    /// (a sample may straddle two of them).
    fn refill(&mut self) -> Result<(), String> {
        self.block.copy_within(self.at..self.filled, 0);
        self.filled -= self.at;
        self.at = 0;
        while self.filled < self.unitsize {
            if self.source.is_none() {
                let Some(c) = self.chunks.get(self.next_chunk) else {
                    return Ok(());
                };
                self.next_chunk += 1;
                let mut f = File::open(&self.file).map_err(|e| format!("cannot open: {e}"))?;
                f.seek(SeekFrom::Start(c.start))
                    .map_err(|e| format!("cannot read `{}`: {e}", c.name))?;
                let raw = BufReader::new(f).take(c.compressed);
                let reader: Box<dyn Read> = if c.deflated {
                    Box::new(flate2::read::DeflateDecoder::new(raw))
                } else {
                    Box::new(raw)
                };
                self.source = Some((reader, 0));
            }
            let chunk = &self.chunks[self.next_chunk - 1];
            let Some((reader, got)) = self.source.as_mut() else {
                continue;
            };
            let n = reader
                .read(&mut self.block[self.filled..])
                .map_err(|e| format!("`{}` cannot be decompressed: {e}", chunk.name))?;
            *got += n as u64;
            self.filled += n;
            if n == 0 {
                if *got != chunk.size {
                    return Err(format!(
                        "`{}` holds {got} bytes of samples, not the {} the archive states: the \
                         file is damaged",
                        chunk.name, chunk.size
                    ));
                }
                self.source = None;
            }
        }
        Ok(())
    }
}
