//! What an MCAP file holds: topics, schemas, message counts and time ranges, read with a
//! streaming reader so that unfinished files can be inspected too.

use super::writer::LogError;
use serde::Serialize;
use std::collections::BTreeMap;

/// One topic.
#[derive(Clone, Debug, Default, Serialize)]
pub struct TopicSummary {
    /// Schema name.
    pub schema: String,
    /// Message encoding.
    pub encoding: String,
    /// Messages.
    pub messages: u64,
    /// First log time (ns).
    pub first_log_time: u64,
    /// Last log time (ns).
    pub last_log_time: u64,
    /// Whether log times never go backwards on the topic.
    pub monotonic: bool,
}

/// A file's contents.
#[derive(Clone, Debug, Serialize)]
pub struct Inspection {
    /// By topic name.
    pub topics: BTreeMap<String, TopicSummary>,
    /// Messages in total.
    pub messages: u64,
    /// Earliest log time (ns).
    pub start_time: Option<u64>,
    /// Latest log time (ns).
    pub end_time: Option<u64>,
    /// Whether the file has a summary section (finished writer).
    pub indexed: bool,
    /// Where a streaming read stopped early, if it did.
    pub stopped_at: Option<String>,
    /// The first problem a check of the whole file finds (a bad CRC, a torn or missing
    /// summary, bytes after the end), or `None` for a finished, undamaged file.
    pub damage: Option<String>,
}

/// Reads every message of `bytes`.
pub fn inspect(bytes: &[u8]) -> Result<Inspection, LogError> {
    let mut topics: BTreeMap<String, TopicSummary> = BTreeMap::new();
    let mut messages = 0;
    let (mut start, mut end): (Option<u64>, Option<u64>) = (None, None);
    let stopped_at = super::reader::for_each_readable(bytes, |m| -> Result<(), LogError> {
        let t = topics
            .entry(m.channel.topic.clone())
            .or_insert_with(|| TopicSummary {
                schema: m
                    .channel
                    .schema
                    .as_ref()
                    .map_or(String::new(), |s| s.name.clone()),
                encoding: m.channel.message_encoding.clone(),
                first_log_time: m.log_time,
                monotonic: true,
                ..Default::default()
            });
        if t.messages > 0 && m.log_time < t.last_log_time {
            t.monotonic = false;
        }
        t.messages += 1;
        t.last_log_time = m.log_time;
        messages += 1;
        start = Some(start.map_or(m.log_time, |s| s.min(m.log_time)));
        end = Some(end.map_or(m.log_time, |e| e.max(m.log_time)));
        Ok(())
    })?;
    Ok(Inspection {
        topics,
        messages,
        start_time: start,
        end_time: end,
        indexed: matches!(mcap::Summary::read(bytes), Ok(Some(_))),
        stopped_at,
        damage: super::reader::check_finished(bytes).err(),
    })
}
