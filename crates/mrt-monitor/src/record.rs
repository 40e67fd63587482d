//! Writing an MCAP file (module doc of the crate): channels by topic, a JSON schema per
//! message type, JSON messages, log times in nanoseconds of the bus's clock; with a
//! [`RecordProfile`], every message or a compact file (`mrt sim --record FILE --compact`).

use crate::profile::RecordProfile;
use mcap::records::MessageHeader;
use mcap::{Compression, WriteOptions, Writer};
use mrt_core::Time;
use schemars::JsonSchema;
use serde::Serialize;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// What can go wrong while recording.
#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The file could not be created or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// The MCAP writer refused (too many channels, an I/O error underneath).
    #[error("{path}: {source}")]
    Mcap {
        /// The file.
        path: PathBuf,
        /// Why.
        source: mcap::McapError,
    },
    /// A value did not serialize as JSON.
    #[error("a message did not serialize as JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// Another thread panicked while it held the recorder.
    #[error("the recorder's lock is poisoned")]
    Poisoned,
    /// More than 65 536 topics in a recording without a file.
    #[error("more topics than a recording's 16-bit channel ids can name")]
    TooManyTopics,
    /// The recorder was to be finished while a tap still held it.
    #[error("the recording cannot be finished while a tap still holds it")]
    StillShared,
}

/// Something an MCAP file can be written to.
pub trait Sink: Write + Seek + Send {}
impl<T: Write + Seek + Send> Sink for T {}

/// How many messages and channels a recording holds.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RecordSummary {
    /// Messages written.
    pub messages: u64,
    /// Channels (topics) written.
    pub channels: usize,
    /// Messages that could not be written (a serialization error), counted and left out.
    pub failed: u64,
    /// Messages a compact profile left out ([`RecordProfile::interval`]).
    pub decimated: u64,
}

/// A recorder shared by the [`Tap`](crate::Tap)s of several Agoras and whoever records the
/// truth.
pub type SharedRecorder = Arc<Mutex<Recorder>>;

/// Sees every message a [`Recorder`] writes: its topic, log time and JSON (the live web
/// monitor's [`Timeline`](crate::Timeline) of `mrt sim --serve`).
pub type Listener = Box<dyn FnMut(&str, Time, &[u8]) + Send>;

/// An MCAP file being written (crate doc), and whoever listens to what is written.
pub struct Recorder {
    /// `None` for a recorder that only feeds its listener ([`Recorder::unwritten`]).
    writer: Option<Writer<Box<dyn Sink>>>,
    path: PathBuf,
    /// Schema ids by type name.
    schemas: BTreeMap<String, u16>,
    /// Channel ids by topic.
    channels: BTreeMap<String, u16>,
    /// Topics by channel id.
    topics: Vec<String>,
    /// By channel id: the least time between two kept messages (ns; 0 keeps all), and the
    /// window (log time / interval) of the last one kept.
    decimation: Vec<(u64, Option<u64>)>,
    profile: RecordProfile,
    /// A message rounded by the profile's precision, reused.
    rounded: Vec<u8>,
    listener: Option<Listener>,
    /// Record every n-th camera image of each robot (0: none).
    images_every: u32,
    summary: RecordSummary,
}

impl std::fmt::Debug for Recorder {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Recorder")
            .field("path", &self.path)
            .field("summary", &self.summary)
            .finish()
    }
}

impl Recorder {
    /// A recording of every message into a new file at `path` (an existing one is
    /// replaced).
    pub fn create(path: &Path) -> Result<Recorder, RecordError> {
        Recorder::create_with(path, RecordProfile::Full)
    }

    /// A recording into a new file at `path` that keeps what `profile` says
    /// ([`RecordProfile::Compact`]: `mrt sim --record FILE --compact`).
    pub fn create_with(path: &Path, profile: RecordProfile) -> Result<Recorder, RecordError> {
        let io = |source| RecordError::Io { path: path.to_path_buf(), source };
        let file = File::create(path).map_err(io)?;
        Recorder::new_with(Box::new(BufWriter::new(file)), path, profile)
    }

    /// A recording of every message into `sink`, called `path` in errors.
    pub fn new(sink: Box<dyn Sink>, path: &Path) -> Result<Recorder, RecordError> {
        Recorder::new_with(sink, path, RecordProfile::Full)
    }

    /// A recording into `sink`, called `path` in errors, that keeps what `profile` says.
    pub fn new_with(
        sink: Box<dyn Sink>,
        path: &Path,
        profile: RecordProfile,
    ) -> Result<Recorder, RecordError> {
        let writer = WriteOptions::new()
            .compression(Some(Compression::Zstd))
            .compression_level(profile.zstd_level())
            .chunk_size(profile.chunk_size())
            .profile("")
            .library(concat!("mrt-monitor ", env!("CARGO_PKG_VERSION")))
            .create(sink)
            .map_err(|source| RecordError::Mcap { path: path.to_path_buf(), source })?;
        Ok(Recorder {
            writer: Some(writer),
            path: path.to_path_buf(),
            profile,
            ..Recorder::unwritten()
        })
    }

    /// A recorder that writes no file: its messages go to its listener only
    /// ([`Recorder::listen`]; `mrt sim --serve` without `--record`).
    pub fn unwritten() -> Recorder {
        Recorder {
            writer: None,
            path: PathBuf::new(),
            schemas: BTreeMap::new(),
            channels: BTreeMap::new(),
            topics: Vec::new(),
            decimation: Vec::new(),
            profile: RecordProfile::Full,
            rounded: Vec::new(),
            listener: None,
            images_every: 0,
            summary: RecordSummary::default(),
        }
    }

    /// The same recorder, with every `every`-th camera image of each robot recorded as a JPEG
    /// on `/<robot>/camera` ([`CompressedImage`](crate::camera::CompressedImage); 0: none, the
    /// default). JPEG does not compress further: each image adds its 5 to 7 KB to the file.
    pub fn with_images(self, every: u32) -> Recorder {
        Recorder { images_every: every, ..self }
    }

    /// What this recording keeps.
    pub fn profile(&self) -> RecordProfile {
        self.profile
    }

    /// Every how many camera images one is recorded (0: none).
    pub fn images_every(&self) -> u32 {
        self.images_every
    }

    /// The same recorder, calling `listener` with every message it writes, after writing it.
    pub fn listen(self, listener: Listener) -> Recorder {
        Recorder { listener: Some(listener), ..self }
    }

    /// The same recorder, shared.
    pub fn shared(self) -> SharedRecorder {
        Arc::new(Mutex::new(self))
    }

    /// The channel of `topic`, whose messages are JSON of the type `schema_name` with the
    /// JSON schema `schema` (asked only for a type not seen yet).
    pub fn channel(
        &mut self,
        topic: &str,
        schema_name: &str,
        schema: impl FnOnce() -> serde_json::Value,
    ) -> Result<u16, RecordError> {
        if let Some(&id) = self.channels.get(topic) {
            return Ok(id);
        }
        let id = match &mut self.writer {
            Some(writer) => {
                let schema_id = match self.schemas.get(schema_name) {
                    Some(&id) => id,
                    None => {
                        let data = serde_json::to_vec(&schema())?;
                        let id =
                            writer.add_schema(schema_name, "jsonschema", &data).map_err(|e| {
                                RecordError::Mcap { path: self.path.clone(), source: e }
                            })?;
                        self.schemas.insert(schema_name.to_string(), id);
                        id
                    }
                };
                writer
                    .add_channel(schema_id, topic, "json", &BTreeMap::new())
                    .map_err(|e| RecordError::Mcap { path: self.path.clone(), source: e })?
            }
            None => u16::try_from(self.topics.len()).map_err(|_| RecordError::TooManyTopics)?,
        };
        let slot = usize::from(id);
        if self.topics.len() <= slot {
            self.topics.resize(slot + 1, String::new());
            self.decimation.resize(slot + 1, (0, None));
        }
        self.topics[slot] = topic.to_string();
        self.decimation[slot] = (self.profile.interval(schema_name).unwrap_or(0), None);
        self.channels.insert(topic.to_string(), id);
        self.summary.channels = self.channels.len();
        Ok(id)
    }

    /// Whether a message on `channel` at `time` is kept, by the profile's interval for the
    /// channel's schema ([`RecordProfile::interval`]): the first message of each window of
    /// that length on the bus's (simulated) clock, counted from 0. A message not kept is
    /// counted in [`RecordSummary::decimated`]; a kept one starts its window.
    pub fn due(&mut self, channel: u16, time: Time) -> bool {
        let Some((interval, last)) = self.decimation.get_mut(usize::from(channel)) else {
            return true;
        };
        if *interval == 0 {
            return true;
        }
        let window = time.0 / *interval;
        if *last == Some(window) {
            self.summary.decimated += 1;
            return false;
        }
        *last = Some(window);
        true
    }

    /// Writes one JSON message on `channel` at `time`, its floats rounded when the profile
    /// says so ([`RecordProfile::precision`]). It is written whether [`Recorder::due`] or
    /// not: ask first.
    pub fn write(&mut self, channel: u16, time: Time, json: &[u8]) -> Result<(), RecordError> {
        self.write_with(channel, time, json, self.profile.precision())
    }

    /// [`Recorder::write`] with the floats rounded to `precision` (`None`: as they are).
    fn write_with(
        &mut self,
        channel: u16,
        time: Time,
        json: &[u8],
        precision: Option<crate::profile::Precision>,
    ) -> Result<(), RecordError> {
        match precision {
            Some(p) => {
                let mut rounded = std::mem::take(&mut self.rounded);
                rounded.clear();
                p.round_json(json, &mut rounded);
                let done = self.write_exact(channel, time, &rounded);
                self.rounded = rounded;
                done
            }
            None => self.write_exact(channel, time, json),
        }
    }

    /// Writes `json` as it is.
    fn write_exact(&mut self, channel: u16, time: Time, json: &[u8]) -> Result<(), RecordError> {
        let header = MessageHeader {
            channel_id: channel,
            sequence: u32::try_from(self.summary.messages).unwrap_or(u32::MAX),
            log_time: time.0,
            publish_time: time.0,
        };
        if let Some(writer) = &mut self.writer {
            writer
                .write_to_known_channel(&header, json)
                .map_err(|e| RecordError::Mcap { path: self.path.clone(), source: e })?;
        }
        self.summary.messages += 1;
        if let (Some(listen), Some(topic)) =
            (&mut self.listener, self.topics.get(usize::from(channel)))
        {
            listen(topic, time, json);
        }
        Ok(())
    }

    /// Writes a message read from another recording ([`Recording::scan`](crate::Recording::scan))
    /// on its topic, with its schema and log time, when the profile keeps it: a recording
    /// merged from several (each robot's own in `mrt world mujoco --record`).
    pub fn copy(&mut self, e: &crate::replay::Entry<'_>) -> Result<(), RecordError> {
        let schema = || serde_json::from_slice(e.schema_data).unwrap_or(serde_json::Value::Null);
        let channel = self.channel(e.topic, e.schema, schema)?;
        if self.due(channel, e.time) {
            self.write(channel, e.time, e.json)?;
        }
        Ok(())
    }

    /// Writes `value` as JSON on `topic` at `time`, its channel's schema `T`'s, when the
    /// profile keeps it ([`Recorder::due`]).
    pub fn record<T: Serialize + JsonSchema>(
        &mut self,
        topic: &str,
        time: Time,
        value: &T,
    ) -> Result<(), RecordError> {
        self.record_with(topic, time, value, self.profile.precision())
    }

    /// [`Recorder::record`] with the floats rounded to `precision` whatever the profile
    /// (the Foxglove views drawn from other messages: `/scene`, `/<robot>/pose`).
    pub fn record_rounded<T: Serialize + JsonSchema>(
        &mut self,
        topic: &str,
        time: Time,
        value: &T,
        precision: crate::profile::Precision,
    ) -> Result<(), RecordError> {
        self.record_with(topic, time, value, Some(precision))
    }

    fn record_with<T: Serialize + JsonSchema>(
        &mut self,
        topic: &str,
        time: Time,
        value: &T,
        precision: Option<crate::profile::Precision>,
    ) -> Result<(), RecordError> {
        let name = T::schema_name();
        let channel = self.channel(topic, &name, crate::catalogue::schema_of::<T>)?;
        if !self.due(channel, time) {
            return Ok(());
        }
        let json = serde_json::to_vec(value)?;
        self.write_with(channel, time, &json, precision)
    }

    /// Counts a message that could not be written.
    pub fn failed(&mut self) {
        self.summary.failed += 1;
    }

    /// What was written so far.
    pub fn summary(&self) -> RecordSummary {
        self.summary
    }

    /// Writes the summary and the footer and closes the file.
    /// The file's metadata record `mrt` holds the profile (`profile`: `full` or `compact`).
    pub fn finish(self) -> Result<RecordSummary, RecordError> {
        let Some(mut writer) = self.writer else { return Ok(self.summary) };
        let metadata = mcap::records::Metadata {
            name: "mrt".into(),
            metadata: BTreeMap::from([("profile".to_string(), self.profile.name().to_string())]),
        };
        writer
            .write_metadata(&metadata)
            .map_err(|source| RecordError::Mcap { path: self.path.clone(), source })?;
        writer.finish().map_err(|source| RecordError::Mcap { path: self.path.clone(), source })?;
        let mut sink = writer.into_inner();
        sink.flush().map_err(|source| RecordError::Io { path: self.path.clone(), source })?;
        Ok(self.summary)
    }

    /// [`Recorder::finish`] on a shared recorder that no one else holds any more.
    pub fn finish_shared(shared: SharedRecorder) -> Result<RecordSummary, RecordError> {
        let recorder = Arc::try_unwrap(shared)
            .map_err(|_| RecordError::StillShared)?
            .into_inner()
            .map_err(|_| RecordError::Poisoned)?;
        recorder.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mrt_msgs::{GameInfo, Localization};

    fn temp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("mrt-monitor-{name}-{}.mcap", std::process::id()))
    }

    /// What a reader of the file sees: (topic, schema name, schema encoding, message
    /// encoding, log time, JSON) per message.
    pub(crate) fn read_back(path: &Path) -> Vec<(String, String, String, String, u64, String)> {
        let bytes = std::fs::read(path).unwrap_or_default();
        mcap::MessageStream::new(&bytes)
            .map(|s| s.filter_map(Result::ok).collect::<Vec<_>>())
            .unwrap_or_default()
            .into_iter()
            .map(|m| {
                let schema = m.channel.schema.as_ref();
                (
                    m.channel.topic.clone(),
                    schema.map(|s| s.name.clone()).unwrap_or_default(),
                    schema.map(|s| s.encoding.clone()).unwrap_or_default(),
                    m.channel.message_encoding.clone(),
                    m.log_time,
                    String::from_utf8_lossy(&m.data).into_owned(),
                )
            })
            .collect()
    }

    #[test]
    fn messages_come_back_on_their_topics_with_their_schemas_and_times() {
        let path = temp("roundtrip");
        let mut rec = Recorder::create(&path).unwrap();
        let game = GameInfo { attack: -1.0, ..Default::default() };
        rec.record("/home/0/GameInfo", Time(100), &game).unwrap();
        rec.record("/home/1/GameInfo", Time(200), &game).unwrap();
        rec.record("/home/0/Localization", Time(300), &Localization::default()).unwrap();
        let s = rec.finish().unwrap();
        assert_eq!(s, RecordSummary { messages: 3, channels: 3, failed: 0, decimated: 0 });
        let back = read_back(&path);
        std::fs::remove_file(&path).ok();
        let topics: Vec<_> = back.iter().map(|m| (m.0.as_str(), m.1.as_str(), m.4)).collect();
        assert_eq!(
            topics,
            [
                ("/home/0/GameInfo", "GameInfo", 100),
                ("/home/1/GameInfo", "GameInfo", 200),
                ("/home/0/Localization", "Localization", 300)
            ]
        );
        assert!(back.iter().all(|m| m.2 == "jsonschema" && m.3 == "json"));
        let decoded: GameInfo = serde_json::from_str(&back[0].5).unwrap();
        assert_eq!(decoded, game);
    }

    /// Messages copied from one recording into another keep their topics, schemas (name
    /// and text), times and bytes.
    #[test]
    fn a_copied_message_keeps_its_topic_schema_time_and_bytes() {
        let (from, to) = (temp("copy-from"), temp("copy-to"));
        let mut rec = Recorder::create(&from).unwrap();
        let game = GameInfo { attack: -1.0, ..Default::default() };
        rec.record("/away/1/GameInfo", Time(700), &game).unwrap();
        rec.record("/away/1/Localization", Time(800), &Localization::default()).unwrap();
        rec.finish().unwrap();
        let mut copy = Recorder::create(&to).unwrap();
        crate::Recording::open(&from).unwrap().scan(|e| copy.copy(&e).unwrap()).unwrap();
        assert_eq!(copy.finish().unwrap().messages, 2);
        let (a, b) = (read_back(&from), read_back(&to));
        let schema = |p: &Path| {
            let bytes = std::fs::read(p).unwrap();
            let s = mcap::MessageStream::new(&bytes).unwrap().next().unwrap().unwrap();
            s.channel.schema.as_ref().unwrap().data.to_vec()
        };
        assert_eq!(schema(&from), schema(&to));
        std::fs::remove_file(&from).ok();
        std::fs::remove_file(&to).ok();
        assert_eq!(a, b);
    }

    /// A compact recording keeps a `Localization` topic at 2 Hz of the simulated clock (the
    /// first message of each half second: 0, 0.5, 1.0 and 1.5 s of 20 messages at 10 Hz),
    /// every `GameInfo`, and writes floats with 4 decimals; the file's metadata names the
    /// profile. The full one keeps all 40 with every digit.
    #[test]
    fn compact_decimates_by_simulated_time_and_rounds() {
        let record = |profile: RecordProfile, name: &str| {
            let path = temp(name);
            let mut rec = Recorder::create_with(&path, profile).unwrap();
            for k in 0..20u64 {
                let t = Time(k * 100_000_000);
                let l = Localization { sigma_xy: 0.0123456789, ..Default::default() };
                rec.record("/home/0/Localization", t, &l).unwrap();
                rec.record("/home/0/GameInfo", t, &GameInfo { attack: -1.0, ..Default::default() })
                    .unwrap();
            }
            let summary = rec.finish().unwrap();
            let bytes = std::fs::read(&path).unwrap();
            let back = read_back(&path);
            std::fs::remove_file(&path).ok();
            (summary, back, bytes)
        };
        let (s, back, bytes) = record(RecordProfile::Compact, "compact");
        assert_eq!(s, RecordSummary { messages: 24, channels: 2, failed: 0, decimated: 16 });
        let times: Vec<u64> =
            back.iter().filter(|m| m.0 == "/home/0/Localization").map(|m| m.4).collect();
        assert_eq!(times, [0, 500_000_000, 1_000_000_000, 1_500_000_000]);
        let l = back.iter().find(|m| m.0 == "/home/0/Localization").unwrap();
        assert!(l.5.contains("\"sigma_xy\":0.0123,"), "{}", l.5);
        let decoded: Localization = serde_json::from_str(&l.5).unwrap();
        assert_eq!(decoded.sigma_xy, 0.0123);
        let has = |needle: &[u8]| bytes.windows(needle.len()).any(|w| w == needle);
        assert!(has(b"profile") && has(b"compact"));
        let (s, back, bytes) = record(RecordProfile::Full, "full");
        assert_eq!(s, RecordSummary { messages: 40, channels: 2, failed: 0, decimated: 0 });
        assert!(back[0].5.contains("\"sigma_xy\":0.0123456789,"), "{}", back[0].5);
        assert!(bytes.windows(4).any(|w| w == b"full"));
    }

    #[test]
    fn a_recording_still_held_by_a_tap_is_not_finished() {
        let path = temp("held");
        let shared = Recorder::create(&path).unwrap().shared();
        let tap = crate::Tap::new("home/0", shared.clone());
        let e = Recorder::finish_shared(shared).unwrap_err();
        assert!(matches!(e, RecordError::StillShared), "{e}");
        drop(tap);
        std::fs::remove_file(&path).ok();
    }

    #[test]
    fn a_file_that_cannot_be_created_says_which() {
        let path = Path::new("/nonexistent-dir-of-mrt/x.mcap");
        let e = Recorder::create(path).unwrap_err().to_string();
        assert!(e.starts_with("/nonexistent-dir-of-mrt/x.mcap: "), "{e}");
    }

    /// A recorder without a file hands every message to its listener (the live monitor's
    /// feed), with the topic it was written on; one with a file does both.
    #[test]
    fn a_listener_sees_every_message_written() {
        type Seen = Arc<Mutex<Vec<(String, u64, String)>>>;
        let seen = Seen::default();
        let listener = |seen: &Seen| -> Listener {
            let seen = seen.clone();
            Box::new(move |topic, time, json| {
                let json = String::from_utf8_lossy(json).into_owned();
                seen.lock().unwrap().push((topic.to_string(), time.0, json));
            })
        };
        let mut rec = Recorder::unwritten().listen(listener(&seen));
        rec.record("/home/0/GameInfo", Time(5), &GameInfo::default()).unwrap();
        rec.record("/away/1/GameInfo", Time(7), &GameInfo { attack: -1.0, ..Default::default() })
            .unwrap();
        assert_eq!(rec.finish().unwrap().messages, 2);
        let seen_now = seen.lock().unwrap().clone();
        assert_eq!(seen_now.len(), 2);
        assert_eq!((seen_now[0].0.as_str(), seen_now[0].1), ("/home/0/GameInfo", 5));
        assert_eq!((seen_now[1].0.as_str(), seen_now[1].1), ("/away/1/GameInfo", 7));
        assert!(seen_now[1].2.contains("\"attack\":-1.0"), "{}", seen_now[1].2);

        let path = temp("listened");
        let mut rec = Recorder::create(&path).unwrap().listen(listener(&seen));
        rec.record("/truth", Time(9), &GameInfo::default()).unwrap();
        rec.finish().unwrap();
        assert_eq!(seen.lock().unwrap().len(), 3);
        let topics = crate::Recording::open(&path).unwrap().topics().unwrap();
        assert_eq!(topics.len(), 1);
        std::fs::remove_file(&path).ok();
    }
}
