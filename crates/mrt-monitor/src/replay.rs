//! Reading a recording back (`mrt replay`): any MCAP file, ours or another tool's. Channels
//! of JSON messages are read; any other (another encoding, no schema) is listed as skipped. A
//! file that is not MCAP, or is cut short, is an error naming the file, never a panic.

use mrt_core::Time;
use serde::de::DeserializeOwned;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What can go wrong while reading a recording.
#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    /// The file could not be read.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The file is not MCAP, or message `index` (from 0, in file order) could not be read.
    #[error("{path}: not a readable MCAP recording (message {index}): {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// The message that failed.
        index: u64,
        /// Why.
        source: mcap::McapError,
    },
    /// The `mcap` crate's record framing panicked on the file (its chunk reader, no longer
    /// used, did on damaged chunks; the guard stays for the framing). The panic is caught and
    /// reported as this error.
    #[error("{path}: not a readable MCAP recording (its reader failed on a corrupted chunk)")]
    Corrupt {
        /// The file.
        path: PathBuf,
    },
    /// A chunk near message `index` could not be read.
    #[error("{path}: not a readable MCAP recording (near message {index}): {why}")]
    Chunk {
        /// The file.
        path: PathBuf,
        /// The messages read before it.
        index: u64,
        /// Why.
        why: String,
    },
    /// A message did not decode as the type asked for.
    #[error("{path}: {topic} at {time:.3} s does not decode as {ty}: {source}")]
    Json {
        /// The file.
        path: PathBuf,
        /// The message's topic.
        topic: String,
        /// Its log time, s.
        time: f64,
        /// The type asked for.
        ty: String,
        /// Why.
        source: serde_json::Error,
    },
}

/// The longest record read (a decompressed chunk included), bytes: a corrupted length asks
/// for no more memory than this. MRT's chunks are under a megabyte.
pub const RECORD_LIMIT: usize = 64 << 20;

/// The largest recording [`Recording::open`] reads, bytes (4 GiB: it is read whole); a path
/// that is not a regular file is refused too.
pub const MAX_RECORDING_BYTES: u64 = 4 << 30;

/// One message of a recording, as read.
#[derive(Clone, Copy, Debug)]
pub struct Entry<'a> {
    /// Its topic, e.g. `/home/2/WorldSnapshot`.
    pub topic: &'a str,
    /// Its schema's name, e.g. `WorldSnapshot`.
    pub schema: &'a str,
    /// Its schema's text (a JSON Schema in MRT's recordings; empty when the channel has none).
    pub schema_data: &'a [u8],
    /// Its log time.
    pub time: Time,
    /// The message, JSON.
    pub json: &'a [u8],
}

/// What a scan keeps between records: schemas (name, encoding) and channels (topic,
/// schema, encoding) by id, the topics so far, and the messages read.
#[derive(Default)]
struct Scan {
    schemas: BTreeMap<u16, (String, String, Vec<u8>)>,
    channels: BTreeMap<u16, (String, u16, String)>,
    topics: BTreeMap<String, TopicInfo>,
    index: u64,
    /// Records read (the file's magic was MCAP's once there is one).
    records: u64,
}

/// MCAP's opcodes of the records read (the others are passed over).
const OP_SCHEMA: u8 = 0x03;
const OP_CHANNEL: u8 = 0x04;
const OP_MESSAGE: u8 = 0x05;
const OP_CHUNK: u8 = 0x06;

/// A record's fields, little-endian, each length checked against what is left of the record.
struct Fields<'a>(&'a [u8]);

impl<'a> Fields<'a> {
    fn take(&mut self, n: usize) -> Option<&'a [u8]> {
        if n > self.0.len() {
            return None;
        }
        let (head, tail) = self.0.split_at(n);
        self.0 = tail;
        Some(head)
    }

    fn u16(&mut self) -> Option<u16> {
        Some(u16::from_le_bytes(self.take(2)?.try_into().ok()?))
    }

    fn u32(&mut self) -> Option<u32> {
        Some(u32::from_le_bytes(self.take(4)?.try_into().ok()?))
    }

    fn u64(&mut self) -> Option<u64> {
        Some(u64::from_le_bytes(self.take(8)?.try_into().ok()?))
    }

    /// Bytes prefixed by their length (u32).
    fn bytes(&mut self) -> Option<&'a [u8]> {
        let n = usize::try_from(self.u32()?).ok()?;
        self.take(n)
    }

    /// A string prefixed by its length in bytes (u32); not UTF-8 is malformed.
    fn string(&mut self) -> Option<String> {
        std::str::from_utf8(self.bytes()?).ok().map(str::to_string)
    }
}

/// The first record of a chunk's records: opcode, body and what follows; `None` when the
/// record runs past the end.
fn split_record(bytes: &[u8]) -> Option<(u8, &[u8], &[u8])> {
    let (&opcode, rest) = bytes.split_first()?;
    let len = u64::from_le_bytes(rest.get(..8)?.try_into().ok()?);
    let len = usize::try_from(len).ok()?;
    let body = rest.get(8..8usize.checked_add(len)?)?;
    Some((opcode, body, &rest[8 + len..]))
}

/// A topic's messages as read: log time and JSON, in file order ([`Recording::raw`]).
pub type Raw = Vec<(Time, Vec<u8>)>;

/// One topic of a recording.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TopicInfo {
    /// The topic.
    pub topic: String,
    /// Its schema's name (empty without a schema).
    pub schema: String,
    /// Its schema's encoding (`jsonschema` for MRT's recordings; empty without a schema).
    pub schema_encoding: String,
    /// Its messages' encoding (`json` for MRT's recordings).
    pub encoding: String,
    /// How many messages.
    pub count: u64,
    /// The first and last log times.
    pub first: Time,
    /// The last log time.
    pub last: Time,
}

impl TopicInfo {
    /// Whether `mrt replay` reads it: JSON messages with a JSON schema.
    pub fn readable(&self) -> bool {
        self.encoding == "json" && !self.schema.is_empty() && self.schema_encoding == "jsonschema"
    }
}

/// A recording in memory (module doc).
#[derive(Clone, Debug)]
pub struct Recording {
    path: PathBuf,
    bytes: Vec<u8>,
    /// Whether its scans end quietly where the file is damaged ([`Recording::open_salvaged`]).
    salvaged: bool,
    /// The topics, once a scan has counted them ([`Recording::salvage`]).
    topics: Option<Vec<TopicInfo>>,
}

/// Where a damaged recording (cut short, a process killed while it wrote) stops being
/// readable, and what is kept before it ([`Recording::open_salvaged`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Damage {
    /// The messages read before the damage.
    pub kept: u64,
    /// The latest log time among them.
    pub until: Time,
    /// What is wrong there (without the file's name).
    pub why: String,
}

impl Recording {
    /// Reads the file at `path`.
    pub fn open(path: &Path) -> Result<Recording, ReplayError> {
        let bytes = mrt_core::read_bounded(path, MAX_RECORDING_BYTES)
            .map_err(|source| ReplayError::Io { path: path.to_path_buf(), source })?;
        Ok(Recording::from_bytes(bytes, path))
    }

    /// A recording of `bytes`, called `path` in errors.
    pub fn from_bytes(bytes: Vec<u8>, path: &Path) -> Recording {
        Recording { path: path.to_path_buf(), bytes, salvaged: false, topics: None }
    }

    /// Reads the file at `path` as far as it is readable: a recording cut short or damaged
    /// (after its first record) reads up to the damage, every scan of it ending there without
    /// an error, and the [`Damage`] says how much was kept. A file that is not MCAP at all is
    /// still an error.
    pub fn open_salvaged(path: &Path) -> Result<(Recording, Option<Damage>), ReplayError> {
        Recording::open(path)?.salvage()
    }

    /// This recording read as far as it is readable ([`Recording::open_salvaged`]).
    pub fn salvage(mut self) -> Result<(Recording, Option<Damage>), ReplayError> {
        let recording = &mut self;
        let (topics, damage) = recording.scan_salvaging(|_| {}, true)?;
        let named = format!("{}: ", recording.path.display());
        let damage = damage.map(|e| {
            let text = e.to_string();
            Damage {
                kept: topics.iter().map(|t| t.count).sum(),
                until: topics.iter().map(|t| t.last).max().unwrap_or_default(),
                why: text.strip_prefix(&named).unwrap_or(&text).to_string(),
            }
        });
        recording.salvaged = damage.is_some();
        recording.topics = Some(topics);
        Ok((self, damage))
    }

    /// Calls `f` with every message of a readable channel ([`TopicInfo::readable`]), in file
    /// order, and returns every topic with its counts (readable or not).
    pub fn scan(&self, f: impl FnMut(Entry<'_>)) -> Result<Vec<TopicInfo>, ReplayError> {
        self.scan_salvaging(f, self.salvaged).map(|(topics, _)| topics)
    }

    /// [`Recording::scan`]; with `salvage`, an error after the first record ends the scan
    /// with what was read and the error beside it.
    fn scan_salvaging(
        &self,
        mut f: impl FnMut(Entry<'_>),
        salvage: bool,
    ) -> Result<(Vec<TopicInfo>, Option<ReplayError>), ReplayError> {
        let mut scan = Scan::default();
        let read = std::panic::AssertUnwindSafe(|| self.scan_unguarded(&mut scan, &mut f));
        let result = std::panic::catch_unwind(read)
            .unwrap_or_else(|_| Err(ReplayError::Corrupt { path: self.path.clone() }));
        let topics = scan.topics.into_values().collect();
        match result {
            Ok(()) => Ok((topics, None)),
            Err(e) if salvage && scan.records > 0 => Ok((topics, Some(e))),
            Err(e) => Err(e),
        }
    }

    /// [`Recording::scan`] without the guard against the reader's panics. `mcap`'s sans-I/O
    /// reader splits the file into records, bounded by [`RECORD_LIMIT`]. The records read
    /// (schema, channel, message, chunk) are parsed here, every length checked against the
    /// record before anything is allocated, and chunks decompressed here into at most the
    /// size they claim: the crate's own record parser allocates whatever length a string
    /// claims, and its chunk decompression loops forever on some damaged chunks (both found
    /// by fuzzing: this module's property test, `mrt-fuzz run mcap`).
    fn scan_unguarded(
        &self,
        scan: &mut Scan,
        f: &mut impl FnMut(Entry<'_>),
    ) -> Result<(), ReplayError> {
        use mcap::sans_io::linear_reader::{LinearReadEvent, LinearReader, LinearReaderOptions};
        let options = LinearReaderOptions::default()
            .with_record_length_limit(RECORD_LIMIT)
            .with_emit_chunks(true);
        let mut reader = LinearReader::new_with_options(options);
        let mut rest: &[u8] = &self.bytes;
        while let Some(event) = reader.next_event() {
            let (opcode, data) = match event.map_err(|e| self.mcap_error(scan.index, e))? {
                LinearReadEvent::ReadRequest(n) => {
                    let k = n.min(rest.len());
                    reader.insert(k).copy_from_slice(&rest[..k]);
                    reader.notify_read(k);
                    rest = &rest[k..];
                    continue;
                }
                LinearReadEvent::Record { opcode, data } => (opcode, data),
            };
            scan.records += 1;
            if opcode != OP_CHUNK {
                self.take(scan, opcode, data, f)?;
                continue;
            }
            let inner = self.chunk(data, scan.index)?;
            let mut body: &[u8] = &inner;
            while !body.is_empty() {
                let (opcode, data, after) = split_record(body)
                    .ok_or_else(|| self.corrupt(scan.index, "a record runs past its chunk"))?;
                self.take(scan, opcode, data, f)?;
                body = after;
            }
        }
        Ok(())
    }

    /// One record outside or inside a chunk: schemas and channels are kept, messages counted
    /// and handed to `f` when readable; other records are passed over.
    fn take(
        &self,
        scan: &mut Scan,
        opcode: u8,
        data: &[u8],
        f: &mut impl FnMut(Entry<'_>),
    ) -> Result<(), ReplayError> {
        let mut r = Fields(data);
        let cut = |what: &str| self.corrupt(scan.index, &format!("a {what} record is cut short"));
        match opcode {
            OP_SCHEMA => {
                let (id, name, encoding, text) =
                    (|| Some((r.u16()?, r.string()?, r.string()?, r.bytes()?)))()
                        .ok_or_else(|| cut("schema"))?;
                scan.schemas.insert(id, (name, encoding, text.to_vec()));
            }
            OP_CHANNEL => {
                let (id, schema, topic, encoding) =
                    (|| Some((r.u16()?, r.u16()?, r.string()?, r.string()?)))()
                        .ok_or_else(|| cut("channel"))?;
                scan.channels.insert(id, (topic, schema, encoding));
            }
            OP_MESSAGE => {
                let (channel, sequence, log_time) =
                    (|| Some((r.u16()?, r.u32()?, r.u64()?, r.u64()?)))()
                        .map(|(c, s, t, _)| (c, s, t))
                        .ok_or_else(|| cut("message"))?;
                let data = r.0;
                let Some((topic, schema_id, encoding)) = scan.channels.get(&channel) else {
                    let unknown = mcap::McapError::UnknownChannel(sequence, channel);
                    return Err(self.mcap_error(scan.index, unknown));
                };
                scan.index += 1;
                let time = Time(log_time);
                let (schema, schema_encoding, schema_data) = scan
                    .schemas
                    .get(schema_id)
                    .map_or(("", "", &[][..]), |(n, e, d)| (n.as_str(), e.as_str(), d.as_slice()));
                let info = scan.topics.entry(topic.clone()).or_insert_with(|| TopicInfo {
                    topic: topic.clone(),
                    schema: schema.to_string(),
                    schema_encoding: schema_encoding.to_string(),
                    encoding: encoding.clone(),
                    count: 0,
                    first: time,
                    last: time,
                });
                info.count += 1;
                info.first = info.first.min(time);
                info.last = info.last.max(time);
                if info.readable() {
                    f(Entry { topic, schema, schema_data, time, json: data });
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// A chunk record's records, decompressed into at most the size the chunk claims (and
    /// [`RECORD_LIMIT`]).
    fn chunk(&self, data: &[u8], index: u64) -> Result<Vec<u8>, ReplayError> {
        let mut r = Fields(data);
        let header = (|| {
            let (_start, _end, size, _crc) = (r.u64()?, r.u64()?, r.u64()?, r.u32()?);
            let compression = r.string()?;
            let compressed = usize::try_from(r.u64()?).ok()?;
            Some((size, compression, r.take(compressed)?))
        })();
        let (size, compression, records) =
            header.ok_or_else(|| self.corrupt(index, "a chunk record is cut short"))?;
        let size = usize::try_from(size).unwrap_or(usize::MAX);
        if size > RECORD_LIMIT {
            return Err(self.corrupt(index, "a chunk claims more than the record limit"));
        }
        let inner = match compression.as_str() {
            "" => records.to_vec(),
            "zstd" => zstd::bulk::decompress(records, size).map_err(|e| {
                self.corrupt(index, &format!("a zstd chunk does not decompress: {e}"))
            })?,
            other => {
                return Err(self.corrupt(
                    index,
                    &format!("chunks compressed with `{other}` are not read (zstd or none)"),
                ))
            }
        };
        if inner.len() != size {
            return Err(self.corrupt(index, "a chunk is not the size it claims"));
        }
        Ok(inner)
    }

    fn mcap_error(&self, index: u64, source: mcap::McapError) -> ReplayError {
        ReplayError::Mcap { path: self.path.clone(), index, source }
    }

    fn corrupt(&self, index: u64, why: &str) -> ReplayError {
        ReplayError::Chunk { path: self.path.clone(), index, why: why.to_string() }
    }

    /// Every topic with its counts.
    pub fn topics(&self) -> Result<Vec<TopicInfo>, ReplayError> {
        match &self.topics {
            Some(topics) => Ok(topics.clone()),
            None => self.scan(|_| {}),
        }
    }

    /// The messages of `topic` decoded as `T`, in log-time order.
    pub fn messages<T: DeserializeOwned + schemars::JsonSchema>(
        &self,
        topic: &str,
    ) -> Result<Vec<(Time, T)>, ReplayError> {
        let mut raw = self.raw(&[topic])?;
        self.decode(topic, raw.remove(topic).unwrap_or_default())
    }

    /// The JSON messages of each of `topics`, in file order, read in one pass over the file
    /// (topics without messages are absent).
    pub fn raw(&self, topics: &[&str]) -> Result<BTreeMap<String, Raw>, ReplayError> {
        let mut out: BTreeMap<String, Raw> = BTreeMap::new();
        self.scan(|e| {
            if topics.contains(&e.topic) {
                out.entry(e.topic.to_string()).or_default().push((e.time, e.json.to_vec()));
            }
        })?;
        Ok(out)
    }

    /// `raw` messages of `topic` ([`Recording::raw`]) decoded as `T`, in log-time order; the
    /// first that does not decode is an error naming the file, the topic, the time and `T`.
    pub fn decode<T: DeserializeOwned + schemars::JsonSchema>(
        &self,
        topic: &str,
        raw: Raw,
    ) -> Result<Vec<(Time, T)>, ReplayError> {
        let mut out = Vec::with_capacity(raw.len());
        for (time, json) in raw {
            match serde_json::from_slice::<T>(&json) {
                Ok(v) => out.push((time, v)),
                Err(source) => {
                    let ty = T::schema_name().into_owned();
                    let (path, topic) = (self.path.clone(), topic.to_string());
                    let time = time.as_secs_f64();
                    return Err(ReplayError::Json { path, topic, time, ty, source });
                }
            }
        }
        out.sort_by_key(|(t, _)| *t);
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Recorder;
    use mrt_msgs::{GameInfo, Localization};
    use proptest::prelude::*;
    use std::collections::BTreeMap as Map;

    fn recorded() -> (Vec<u8>, PathBuf) {
        let path = std::env::temp_dir().join(format!(
            "mrt-monitor-replay-{}-{:?}.mcap",
            std::process::id(),
            std::thread::current().id()
        ));
        let mut rec = Recorder::create(&path).unwrap();
        for k in 0..5u64 {
            let game = GameInfo { attack: k as f64, ..Default::default() };
            rec.record("/home/0/GameInfo", Time(k * 100_000_000), &game).unwrap();
        }
        rec.record("/home/0/Localization", Time(7), &Localization::default()).unwrap();
        rec.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).ok();
        (bytes, path)
    }

    /// A recording of `n` GameInfo messages (`attack` = 0, 1, ...), many chunks long.
    fn long_recording(n: u64) -> Vec<u8> {
        let path = std::env::temp_dir().join(format!(
            "mrt-monitor-long-{}-{:?}.mcap",
            std::process::id(),
            std::thread::current().id()
        ));
        let mut rec = Recorder::create(&path).unwrap();
        for k in 0..n {
            let game = GameInfo { attack: k as f64, ..Default::default() };
            rec.record("/home/0/GameInfo", Time(k * 1_000_000), &game).unwrap();
        }
        rec.finish().unwrap();
        let bytes = std::fs::read(&path).unwrap();
        std::fs::remove_file(&path).ok();
        bytes
    }

    /// A recording cut anywhere reads up to the cut: the messages before it, in order, none
    /// invented, and the damage says how many; a whole file has none.
    #[test]
    fn a_recording_cut_short_reads_up_to_the_cut() {
        let n = 40_000;
        let bytes = long_recording(n);
        let path = PathBuf::from("cut.mcap");
        let (whole, damage) = Recording::from_bytes(bytes.clone(), &path).salvage().unwrap();
        assert_eq!(damage, None);
        assert_eq!(whole.topics().unwrap()[0].count, n);
        let mut kept_before = u64::MAX;
        for cut in [bytes.len() - 1, bytes.len() * 3 / 4, bytes.len() / 2, bytes.len() / 4] {
            let cut_short = Recording::from_bytes(bytes[..cut].to_vec(), &path);
            assert!(cut_short.topics().is_err(), "a strict read refuses a file cut at {cut}");
            let (r, damage) = cut_short.salvage().unwrap();
            let damage = damage.expect("damaged");
            let mut attacks = Vec::new();
            r.scan(|e| {
                let g: GameInfo = serde_json::from_slice(e.json).unwrap();
                attacks.push(g.attack);
            })
            .unwrap();
            assert_eq!(attacks.len() as u64, damage.kept, "cut at {cut}");
            assert!(attacks.iter().enumerate().all(|(i, &a)| a == i as f64), "in order, a prefix");
            assert!(damage.kept <= kept_before, "a shorter file keeps no more");
            assert_eq!(damage.until, Time(damage.kept.saturating_sub(1) * 1_000_000));
            kept_before = damage.kept;
        }
        assert!(kept_before > 0 && kept_before < n / 2, "a quarter of the file: {kept_before}");
        // Not MCAP at all is still an error.
        assert!(Recording::from_bytes(b"not a recording".to_vec(), &path).salvage().is_err());
    }

    #[test]
    fn a_recording_lists_its_topics_and_gives_back_typed_messages() {
        let (bytes, path) = recorded();
        let r = Recording::from_bytes(bytes, &path);
        let topics = r.topics().unwrap();
        let names: Vec<_> =
            topics.iter().map(|t| (t.topic.as_str(), t.schema.as_str(), t.count)).collect();
        assert_eq!(
            names,
            [("/home/0/GameInfo", "GameInfo", 5), ("/home/0/Localization", "Localization", 1)]
        );
        assert_eq!((topics[0].first, topics[0].last), (Time(0), Time(400_000_000)));
        assert!(topics.iter().all(TopicInfo::readable));
        let games = r.messages::<GameInfo>("/home/0/GameInfo").unwrap();
        let attacks: Vec<f64> = games.iter().map(|(_, g)| g.attack).collect();
        assert_eq!(attacks, [0.0, 1.0, 2.0, 3.0, 4.0]);
        // Asked for the wrong type: the error names the file, the topic, the time and the type.
        let e = r.messages::<Localization>("/home/0/GameInfo").unwrap_err().to_string();
        assert!(e.contains("/home/0/GameInfo at 0.000 s does not decode as Localization"), "{e}");
    }

    /// Another tool's channels are listed but not read: CDR without a schema, and JSON
    /// messages whose schema is not a JSON schema (a protobuf one).
    #[test]
    fn channels_of_other_encodings_are_listed_and_skipped() {
        let mut w = mcap::Writer::new(std::io::Cursor::new(Vec::new())).unwrap();
        let cdr = w.add_channel(0, "/ros/odom", "cdr", &Map::new()).unwrap();
        let proto = w.add_schema("pose", "protobuf", b"\x0a\x01").unwrap();
        let json = w.add_channel(proto, "/odd/pose", "json", &Map::new()).unwrap();
        for channel_id in [cdr, json] {
            let header = mcap::records::MessageHeader {
                channel_id,
                sequence: 0,
                log_time: 5,
                publish_time: 5,
            };
            w.write_to_known_channel(&header, b"{}").unwrap();
        }
        w.finish().unwrap();
        let bytes = w.into_inner().into_inner();
        let r = Recording::from_bytes(bytes, Path::new("other.mcap"));
        let mut read = 0;
        let topics = r.scan(|_| read += 1).unwrap();
        assert_eq!(read, 0);
        assert_eq!(topics.len(), 2);
        let odd = topics.iter().find(|t| t.topic == "/odd/pose").unwrap();
        assert!(!odd.readable() && odd.encoding == "json" && odd.schema_encoding == "protobuf");
        let odom = topics.iter().find(|t| t.topic == "/ros/odom").unwrap();
        assert!(!odom.readable() && odom.encoding == "cdr");
    }

    #[test]
    fn a_file_that_is_not_mcap_or_is_cut_short_is_an_error_that_names_it() {
        let r = Recording::from_bytes(b"not an mcap file".to_vec(), Path::new("junk.mcap"));
        let e = r.topics().unwrap_err().to_string();
        assert!(e.starts_with("junk.mcap: not a readable MCAP recording"), "{e}");
        let (bytes, path) = recorded();
        let cut = Recording::from_bytes(bytes[..bytes.len() / 2].to_vec(), &path);
        assert!(cut.topics().is_err());
        let e = Recording::open(Path::new("/nonexistent-mrt/x.mcap")).unwrap_err().to_string();
        assert!(e.starts_with("/nonexistent-mrt/x.mcap: "), "{e}");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(256))]
        /// Random bytes, and a real recording with bytes flipped: an answer or an error,
        /// never a panic.
        #[test]
        fn any_bytes_read_without_panicking(noise in proptest::collection::vec(any::<u8>(), 0..2048),
                                            flips in proptest::collection::vec((any::<usize>(), any::<u8>()), 0..8)) {
            let _ = Recording::from_bytes(noise, Path::new("noise.mcap")).topics();
            let (mut bytes, path) = recorded();
            let n = bytes.len();
            for (at, b) in flips {
                bytes[at % n] ^= b;
            }
            let r = Recording::from_bytes(bytes, &path);
            let _ = r.topics();
            let _ = r.messages::<GameInfo>("/home/0/GameInfo");
        }
    }
}
