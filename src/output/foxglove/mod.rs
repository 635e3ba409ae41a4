//! Foxglove's scene schemas (`foxglove.SceneUpdate`, `foxglove.PoseInFrame`,
//! `foxglove.FrameTransform` and the messages inside them) as Rust types that encode to and
//! decode from protobuf, with the schemas' descriptors that a log registers.
//!
//! The types carry the fields the logs write, under the schemas' names; the wire format is in
//! [`wire`]. The descriptors (`descriptors/*.bin`, binary `FileDescriptorSet`s) are Foxglove's
//! own, from the MIT-licensed Foxglove SDK (see `descriptors/README.md`), so a viewer reads the
//! messages against exactly the schemas it knows.

pub mod messages;
pub mod wire;

pub use messages::*;
pub use wire::DecodeError;

/// A protobuf message: written field by field, read by merging fields into a default value.
pub trait Message: Default {
    /// Appends the message's encoding to `buf`.
    fn encode(&self, buf: &mut Vec<u8>);

    /// Merges one field read from the wire (fields of unknown numbers are skipped).
    fn merge_field(&mut self, field: u32, value: wire::Value<'_>) -> Result<(), DecodeError>;

    /// Merges the fields of `bytes` into `self`.
    fn merge(&mut self, bytes: &[u8]) -> Result<(), DecodeError> {
        wire::for_each_field(bytes, |f, v| self.merge_field(f, v))
    }

    /// Reads a message.
    fn decode(bytes: &[u8]) -> Result<Self, DecodeError> {
        let mut m = Self::default();
        m.merge(bytes)?;
        Ok(m)
    }

    /// The message's encoding.
    fn encode_to_vec(&self) -> Vec<u8> {
        let mut buf = Vec::new();
        self.encode(&mut buf);
        buf
    }
}

/// A message with a schema of its own: what a log's channel is created with.
pub trait Schema: Message {
    /// The schema's name, as Foxglove recognises it (`foxglove.SceneUpdate`).
    const NAME: &'static str;
    /// The schema: a binary `FileDescriptorSet` holding the message and everything it uses.
    const DESCRIPTOR: &'static [u8];
}
