//! The one streaming reader behind `inspect`, `recover` and `plot`: it reads finished and broken
//! files alike and never trusts a length it has not checked.
//!
//! Every chunk's CRC is checked before any of its messages is handed out (a corrupted chunk ends
//! the read instead of passing its damage on), the data section's CRC is checked at its end, and
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

/// Calls `f` on every message a streaming reader reaches in `bytes` (a finished or a broken
/// MCAP file), in file order; returns where the read stopped early, if it did. Errors of `f`
/// are returned as they are.
pub fn for_each_readable<E: From<LogError>>(
    bytes: &[u8],
    mut f: impl FnMut(&mcap::Message) -> Result<(), E>,
) -> Result<Option<String>, E> {
    check_magic(bytes)?;
    let options = mcap::sans_io::LinearReaderOptions::default()
        .with_skip_end_magic(true)
        .with_prevalidate_chunk_crcs(true)
        .with_validate_data_section_crc(true)
        .with_record_length_limit(record_limit(bytes.len()));
    for m in mcap::io::MessageReader::new_with_options(bytes, options) {
        match m {
            Ok(m) => f(&m)?,
            Err(e) => return Ok(Some(e.to_string())),
        }
    }
    Ok(None)
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
            LinearReadEvent::ReadRequest(need) => {
                let n = need.min(bytes.len() - at);
                reader.insert(n).copy_from_slice(&bytes[at..at + n]);
                reader.notify_read(n);
                at += n;
            }
            LinearReadEvent::Record { opcode, data } => {
                mcap::parse_record(opcode, data).map_err(|e| e.to_string())?;
            }
        }
    }
    match mcap::Summary::read(bytes) {
        Ok(Some(_)) => Ok(()),
        Ok(None) => Err("no summary section".into()),
        Err(e) => Err(e.to_string()),
    }
}
