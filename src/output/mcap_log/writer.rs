//! A streaming MCAP writer: LZ4-compressed chunks written as they fill, Foxglove's protobuf
//! schemas registered on first use, JSON for numeric topics, and per-topic sequence numbers.

use crate::output::foxglove::Schema;
use std::collections::{BTreeMap, HashMap};
use std::fs::File;
use std::io::{BufWriter, Seek, Write};
use std::path::Path;

/// Chunk size: small enough that a killed run loses little, large enough to compress well.
pub const CHUNK_BYTES: u64 = 64 * 1024;

/// The options of every log written here: LZ4 chunks of [`CHUNK_BYTES`], compressed on the
/// thread that writes them. (LZ4 rather than zstd: every MCAP reader decodes both, and LZ4
/// compresses faster and builds without zstd's C library.)
pub fn write_options() -> mcap::WriteOptions {
    mcap::WriteOptions::new()
        .compression(Some(mcap::Compression::Lz4))
        .chunk_size(Some(CHUNK_BYTES))
        .profile("")
}

/// The writer behind every log.
pub struct McapWriter<W: Write + Seek> {
    inner: Option<mcap::Writer<W>>,
    channels: HashMap<String, u16>,
    schemas: HashMap<String, u16>,
    sequence: HashMap<u16, u32>,
    buf: Vec<u8>,
    messages: u64,
}

/// Errors of the log writer.
pub type LogError = mcap::McapError;

impl McapWriter<BufWriter<File>> {
    /// Creates `path` (its directory too).
    pub fn create(path: &Path) -> Result<Self, LogError> {
        if let Some(dir) = path.parent()
            && !dir.as_os_str().is_empty()
        {
            std::fs::create_dir_all(dir)?;
        }
        let file = BufWriter::new(File::create(path)?);
        Self::new(file)
    }
}

/// What a channel is created with: its schema and its messages' encoding.
struct ChannelSpec {
    schema_name: String,
    schema_encoding: String,
    schema: Vec<u8>,
    message_encoding: String,
}

impl<W: Write + Seek> McapWriter<W> {
    /// Starts a log on `w`.
    pub fn new(w: W) -> Result<Self, LogError> {
        let inner = write_options()
            .library(format!("dlo-planner {}", env!("CARGO_PKG_VERSION")))
            .create(w)?;
        Ok(McapWriter {
            inner: Some(inner),
            channels: HashMap::new(),
            schemas: HashMap::new(),
            sequence: HashMap::new(),
            buf: Vec::new(),
            messages: 0,
        })
    }

    /// Messages written so far.
    pub fn messages(&self) -> u64 {
        self.messages
    }

    fn writer(&mut self) -> Result<&mut mcap::Writer<W>, LogError> {
        self.inner
            .as_mut()
            .ok_or_else(|| std::io::Error::other("log already finished").into())
    }

    /// The id of `topic`'s channel, created (with its schema, once per schema name) the first
    /// time from what `describe` says.
    fn channel(
        &mut self,
        topic: &str,
        describe: impl FnOnce() -> ChannelSpec,
    ) -> Result<u16, LogError> {
        if let Some(&id) = self.channels.get(topic) {
            return Ok(id);
        }
        let spec = describe();
        let sid = match self.schemas.get(&spec.schema_name) {
            Some(&s) => s,
            None => {
                let s = self.writer()?.add_schema(
                    &spec.schema_name,
                    &spec.schema_encoding,
                    &spec.schema,
                )?;
                self.schemas.insert(spec.schema_name, s);
                s
            }
        };
        let id =
            self.writer()?
                .add_channel(sid, topic, &spec.message_encoding, &BTreeMap::new())?;
        self.channels.insert(topic.to_string(), id);
        Ok(id)
    }

    fn put(&mut self, id: u16, log_time: u64) -> Result<(), LogError> {
        let seq = self.sequence.entry(id).or_insert(0);
        *seq += 1;
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: *seq,
            log_time,
            publish_time: log_time,
        };
        let data = std::mem::take(&mut self.buf);
        let r = self.writer()?.write_to_known_channel(&header, &data);
        self.buf = data;
        self.messages += 1;
        r
    }

    /// Writes a Foxglove protobuf message on `topic` at `log_time` (ns).
    pub fn proto<T: Schema>(
        &mut self,
        topic: &str,
        log_time: u64,
        msg: &T,
    ) -> Result<(), LogError> {
        let id = self.channel(topic, || ChannelSpec {
            schema_name: T::NAME.to_string(),
            schema_encoding: "protobuf".to_string(),
            schema: T::DESCRIPTOR.to_vec(),
            message_encoding: "protobuf".to_string(),
        })?;
        self.buf.clear();
        msg.encode(&mut self.buf);
        self.put(id, log_time)
    }

    /// Writes a JSON message on `topic` with the JSON schema `schema` named `name`.
    pub fn json(
        &mut self,
        topic: &str,
        name: &str,
        schema: &serde_json::Value,
        log_time: u64,
        msg: &serde_json::Value,
    ) -> Result<(), LogError> {
        let id = self.channel(topic, || ChannelSpec {
            schema_name: name.to_string(),
            schema_encoding: "jsonschema".to_string(),
            schema: serde_json::to_vec(schema).expect("schema serialises"),
            message_encoding: "json".to_string(),
        })?;
        self.buf.clear();
        // A member without a value is left out, as the schemas say (see `json_schemas`).
        serde_json::to_writer(&mut self.buf, &super::json_schemas::WithoutNulls(msg))
            .expect("JSON serialises");
        self.put(id, log_time)
    }

    /// Closes the current chunk so that everything so far is readable by a streaming reader.
    pub fn flush(&mut self) -> Result<(), LogError> {
        self.writer()?.flush()
    }

    /// Writes the summary and index; later calls do nothing.
    pub fn finish(&mut self) -> Result<(), LogError> {
        if let Some(mut w) = self.inner.take() {
            w.finish()?;
            let mut inner = w.into_inner();
            inner.flush()?;
        }
        Ok(())
    }

    /// Whether [`McapWriter::finish`] has run.
    pub fn is_finished(&self) -> bool {
        self.inner.is_none()
    }
}

impl<W: Write + Seek> Drop for McapWriter<W> {
    fn drop(&mut self) {
        let _ = self.finish();
    }
}
