//! Rewrites an MCAP file whose writer was killed (no summary, maybe a torn last chunk) into a
//! fully indexed one: every message a streaming reader can still reach is copied, with its
//! channel and schema.

use super::writer::LogError;
use std::collections::HashMap;
use std::io::{Seek, Write};

/// What [`recover`] found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Recovery {
    /// Messages copied.
    pub messages: u64,
    /// Whether the input was anything but a finished, undamaged file (a torn or corrupted
    /// record, a missing or damaged summary or footer).
    pub truncated: bool,
    /// The reader's complaint at the point it stopped, if any.
    pub stopped_at: Option<String>,
    /// The first problem a check of the whole input finds, if any (see
    /// [`super::reader::check_finished`]).
    pub damage: Option<String>,
}

/// Copies every readable message of `input` (the bytes of an MCAP file, complete or not) to a
/// new, finished MCAP written on `out`.
pub fn recover<W: Write + Seek>(input: &[u8], out: W) -> Result<Recovery, LogError> {
    super::reader::check_magic(input)?;
    let mut w = super::writer::write_options().create(out)?;
    let mut channels: HashMap<u16, u16> = HashMap::new();
    let mut schemas: HashMap<u16, u16> = HashMap::new();
    let mut messages = 0;
    let stopped_at = super::reader::for_each_readable(input, |m| -> Result<(), LogError> {
        let ch = &m.channel;
        let id = match channels.get(&ch.id) {
            Some(&id) => id,
            None => {
                let sid = match &ch.schema {
                    Some(s) => match schemas.get(&s.id) {
                        Some(&sid) => sid,
                        None => {
                            let sid = w.add_schema(&s.name, &s.encoding, &s.data)?;
                            schemas.insert(s.id, sid);
                            sid
                        }
                    },
                    None => 0,
                };
                let id = w.add_channel(sid, &ch.topic, &ch.message_encoding, &ch.metadata)?;
                channels.insert(ch.id, id);
                id
            }
        };
        w.write_to_known_channel(
            &mcap::records::MessageHeader {
                channel_id: id,
                sequence: m.sequence,
                log_time: m.log_time,
                publish_time: m.publish_time,
            },
            &m.data,
        )?;
        messages += 1;
        Ok(())
    })?;
    w.finish()?;
    let damage = super::reader::check_finished(input).err();
    Ok(Recovery {
        messages,
        truncated: stopped_at.is_some() || damage.is_some(),
        stopped_at,
        damage,
    })
}
