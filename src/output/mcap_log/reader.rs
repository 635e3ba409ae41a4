//! The one streaming reader behind `inspect`, `recover` and `plot`: it reads finished and broken
//! files alike and never trusts a length it has not checked.
//!
//! Every chunk's CRC is checked before any of its messages is handed out (a corrupted chunk ends
//! the read instead of passing its damage on), a message record between chunks ends it too, the
//! data section's CRC is checked at its end, and
//! no record may claim more than [`record_limit`] bytes, so a corrupted length field cannot make
//! the reader allocate more than a bounded multiple of the file.

use super::writer::LogError;

/// Largest record (or decompressed chunk) accepted from a file of `len` bytes: 64 times the file
/// (LZ4 rarely compresses our logs 10:1), at least 16 MiB and at most 1 GiB.
pub fn record_limit(len: usize) -> usize {
    len.saturating_mul(64).clamp(16 << 20, 1 << 30)
}

/// Fails unless `bytes` starts with the MCAP magic.
pub fn check_magic(bytes: &[u8]) -> Result<(), LogError> {
    if bytes.starts_with(mcap::MAGIC) {
        Ok(())
    } else {
        Err(mcap::McapError::BadMagic)
    }
}

/// Answers a reader's request for `need` more bytes from `bytes` at `*at` (fewer at the end).
fn feed(reader: &mut mcap::sans_io::LinearReader, bytes: &[u8], at: &mut usize, need: usize) {
    let n = need.min(bytes.len() - *at);
    reader.insert(n).copy_from_slice(&bytes[*at..*at + n]);
    reader.notify_read(n);
    *at += n;
}

/// Calls `f` on every message a streaming reader reaches in `bytes` (a finished or a broken
/// MCAP file), in file order; returns where the read stopped early, if it did. Errors of `f`
/// are returned as they are.
///
/// A message outside a chunk is read only while no chunk has been: a writer that chunks puts
/// every message in a chunk, where its CRC protects it, so a message record between chunks is a
/// damaged record (a message index whose opcode changed reads as a message of a real channel),
/// and the read stops there instead of counting it.
pub fn for_each_readable<E: From<LogError>>(
    bytes: &[u8],
    mut f: impl FnMut(&mcap::Message) -> Result<(), E>,
) -> Result<Option<String>, E> {
    use mcap::records::op;
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    check_magic(bytes)?;
    let limit = record_limit(bytes.len());
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_skip_end_magic(true)
            .with_emit_chunks(true)
            .with_validate_data_section_crc(true)
            .with_record_length_limit(limit),
    );
    let mut links = Links::default();
    let mut chunked = false;
    let mut at = 0;
    while let Some(event) = reader.next_event() {
        let (opcode, data) = match event {
            Err(e) => return Ok(Some(e.to_string())),
            Ok(LinearReadEvent::ReadRequest(need)) => {
                feed(&mut reader, bytes, &mut at, need);
                continue;
            }
            Ok(LinearReadEvent::Record { opcode, data }) => (opcode, data),
        };
        let step = match opcode {
            op::DATA_END => return Ok(None),
            op::CHUNK => {
                chunked = true;
                links.chunk(opcode, data, limit, &mut f)?
            }
            op::MESSAGE if chunked => {
                Err("a message record outside a chunk, between chunks".into())
            }
            _ => links.record(opcode, data, &mut f)?,
        };
        if let Err(e) = step {
            return Ok(Some(e));
        }
    }
    Ok(None)
}

/// The schemas and channels read so far, and the messages they link.
#[derive(Default)]
struct Links(mcap::read::ChannelAccumulator<'static>);

impl Links {
    /// Reads one record: links a schema or channel, hands a message to `f`. The outer result
    /// is `f`'s error; the inner one is where the read must stop.
    fn record<E>(
        &mut self,
        opcode: u8,
        data: &[u8],
        f: &mut impl FnMut(&mcap::Message) -> Result<(), E>,
    ) -> Result<Result<(), String>, E> {
        use mcap::records::Record;
        let linked = match mcap::parse_record(opcode, data) {
            Err(e) => Err(e),
            Ok(Record::Schema { header, data }) => self
                .0
                .add_schema(header, std::borrow::Cow::Owned(data.into_owned())),
            Ok(Record::Channel(channel)) => self.0.add_channel(channel),
            Ok(Record::Message { header, data }) => match self.0.get(header.channel_id) {
                None => Err(mcap::McapError::UnknownChannel(
                    header.sequence,
                    header.channel_id,
                )),
                Some(channel) => {
                    f(&mcap::Message {
                        channel,
                        sequence: header.sequence,
                        log_time: header.log_time,
                        publish_time: header.publish_time,
                        data,
                    })?;
                    Ok(())
                }
            },
            Ok(_) => Ok(()),
        };
        Ok(linked.map_err(|e| e.to_string()))
    }

    /// Reads the records of one chunk record (`opcode`, `data`), after checking its CRC and
    /// bounding its decompressed size by `limit`.
    fn chunk<E>(
        &mut self,
        opcode: u8,
        data: &[u8],
        limit: usize,
        f: &mut impl FnMut(&mcap::Message) -> Result<(), E>,
    ) -> Result<Result<(), String>, E> {
        use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
        let mut record = Vec::with_capacity(9 + data.len());
        record.push(opcode);
        record.extend_from_slice(&(data.len() as u64).to_le_bytes());
        record.extend_from_slice(data);
        let mut reader = LinearReader::new_with_options(
            LinearReaderOptions::default()
                .with_skip_start_magic(true)
                .with_skip_end_magic(true)
                .with_prevalidate_chunk_crcs(true)
                .with_record_length_limit(limit),
        );
        let mut at = 0;
        while let Some(event) = reader.next_event() {
            match event {
                Err(e) => return Ok(Err(e.to_string())),
                Ok(LinearReadEvent::ReadRequest(need)) => feed(&mut reader, &record, &mut at, need),
                Ok(LinearReadEvent::Record { opcode, data }) => {
                    if let Err(e) = self.record(opcode, data, f)? {
                        return Ok(Err(e));
                    }
                }
            }
        }
        Ok(Ok(()))
    }
}

/// Checks the whole of `bytes` as a finished file: every record's length, every chunk's CRC,
/// the data and summary sections' CRCs, the footer and both magics. Returns the first problem.
pub fn check_finished(bytes: &[u8]) -> Result<(), String> {
    use mcap::sans_io::{LinearReadEvent, LinearReader, LinearReaderOptions};
    check_magic(bytes).map_err(|e| e.to_string())?;
    let mut reader = LinearReader::new_with_options(
        LinearReaderOptions::default()
            .with_prevalidate_chunk_crcs(true)
            .with_validate_data_section_crc(true)
            .with_validate_summary_section_crc(true)
            .with_check_finishes_after_end_magic(true)
            .with_record_length_limit(record_limit(bytes.len())),
    );
    let mut at = 0;
    while let Some(event) = reader.next_event() {
        match event.map_err(|e| e.to_string())? {
            LinearReadEvent::ReadRequest(need) => feed(&mut reader, bytes, &mut at, need),
            LinearReadEvent::Record { opcode, data } => {
                mcap::parse_record(opcode, data).map_err(|e| e.to_string())?;
            }
        }
    }
    check_footer_offsets(bytes)?;
    match mcap::Summary::read(bytes) {
        Ok(Some(_)) => Ok(()),
        Ok(None) => Err("no summary section".into()),
        Err(e) => Err(e.to_string()),
    }
}

/// Checks where the footer of a file whose records have all been read points: the summary
/// section starts right after the data end record, and the summary offset section (if any)
/// starts inside it at a summary offset record. The footer's CRC covers these offsets, but a
/// CRC of 0 means "not computed", so a damaged footer whose CRC became 0 is found only here.
fn check_footer_offsets(bytes: &[u8]) -> Result<(), String> {
    const FOOTER_RECORD: usize = 1 + 8 + 8 + 8 + 4;
    let footer = mcap::read::footer(bytes).map_err(|e| e.to_string())?;
    let footer_at = (bytes.len() - mcap::MAGIC.len() - FOOTER_RECORD) as u64;
    let (start, offsets) = (footer.summary_start, footer.summary_offset_start);
    if start != 0 && start != data_end(bytes).unwrap_or(0) {
        return Err(format!(
            "the footer's summary start {start} is not where the data section ends"
        ));
    }
    if offsets != 0
        && (start == 0
            || !(start..footer_at).contains(&offsets)
            || bytes[offsets as usize] != mcap::records::op::SUMMARY_OFFSET)
    {
        return Err(format!(
            "the footer's summary offset start {offsets} is not a summary offset record"
        ));
    }
    Ok(())
}

/// Where the data end record of `bytes` ends, walking the top-level records by their lengths.
fn data_end(bytes: &[u8]) -> Option<u64> {
    let mut at = mcap::MAGIC.len();
    loop {
        let opcode = *bytes.get(at)?;
        let len = u64::from_le_bytes(bytes.get(at + 1..at + 9)?.try_into().ok()?);
        at = at.checked_add(9)?.checked_add(usize::try_from(len).ok()?)?;
        if opcode == mcap::records::op::DATA_END {
            return Some(at as u64);
        }
    }
}
