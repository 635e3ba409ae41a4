//! The protobuf wire format, as far as Foxglove's scene schemas need it: varints, doubles,
//! strings and nested messages. Fields at their default value (0, `false`, "") are left out,
//! as every proto3 encoder does; a present sub-message is written even when empty.

/// Wire type of varints (integers, booleans, enums).
const VARINT: u64 = 0;
/// Wire type of 64-bit fields (doubles).
const FIXED64: u64 = 1;
/// Wire type of length-delimited fields (strings, bytes, messages, packed arrays).
const LEN: u64 = 2;
/// Wire type of 32-bit fields.
const FIXED32: u64 = 5;

/// A message that did not decode: a truncated field, a wire type its schema does not allow,
/// or an unsupported (group) field.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct DecodeError;

impl std::fmt::Display for DecodeError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("malformed protobuf message")
    }
}

impl std::error::Error for DecodeError {}

fn varint(buf: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        buf.push((v as u8) | 0x80);
        v >>= 7;
    }
    buf.push(v as u8);
}

fn key(buf: &mut Vec<u8>, field: u32, wire: u64) {
    varint(buf, (u64::from(field) << 3) | wire);
}

/// A `double` field.
pub fn double(buf: &mut Vec<u8>, field: u32, v: f64) {
    if v != 0.0 {
        key(buf, field, FIXED64);
        buf.extend_from_slice(&v.to_le_bytes());
    }
}

/// An integer or enum field (`int32`, `int64`, `uint32`, …; negative values as protobuf writes
/// them, in ten bytes).
pub fn int(buf: &mut Vec<u8>, field: u32, v: i64) {
    if v != 0 {
        key(buf, field, VARINT);
        varint(buf, v as u64);
    }
}

/// A `bool` field.
pub fn boolean(buf: &mut Vec<u8>, field: u32, v: bool) {
    if v {
        key(buf, field, VARINT);
        buf.push(1);
    }
}

/// A `string` field.
pub fn string(buf: &mut Vec<u8>, field: u32, s: &str) {
    if !s.is_empty() {
        key(buf, field, LEN);
        varint(buf, s.len() as u64);
        buf.extend_from_slice(s.as_bytes());
    }
}

/// A sub-message field whose body `body` writes.
pub fn message(buf: &mut Vec<u8>, field: u32, body: impl FnOnce(&mut Vec<u8>)) {
    key(buf, field, LEN);
    // One byte is kept for the length; a longer length moves the body once.
    let at = buf.len();
    buf.push(0);
    body(buf);
    let len = buf.len() - at - 1;
    if len < 0x80 {
        buf[at] = len as u8;
    } else {
        let mut prefix = Vec::with_capacity(4);
        varint(&mut prefix, len as u64);
        buf.splice(at..=at, prefix);
    }
}

/// One field's value as read.
#[derive(Debug, Clone, Copy)]
pub enum Value<'a> {
    /// A varint.
    Varint(u64),
    /// A 64-bit field.
    Fixed64(u64),
    /// A length-delimited field.
    Bytes(&'a [u8]),
    /// A 32-bit field.
    Fixed32(u32),
}

impl<'a> Value<'a> {
    /// The value of a `double` field.
    pub fn double(self) -> Result<f64, DecodeError> {
        match self {
            Value::Fixed64(b) => Ok(f64::from_bits(b)),
            _ => Err(DecodeError),
        }
    }

    /// The value of an integer or enum field.
    pub fn int(self) -> Result<i64, DecodeError> {
        match self {
            Value::Varint(v) => Ok(v as i64),
            _ => Err(DecodeError),
        }
    }

    /// The value of a `bool` field.
    pub fn boolean(self) -> Result<bool, DecodeError> {
        self.int().map(|v| v != 0)
    }

    /// The value of a `string` field.
    pub fn string(self) -> Result<String, DecodeError> {
        match self {
            Value::Bytes(b) => std::str::from_utf8(b)
                .map(str::to_string)
                .map_err(|_| DecodeError),
            _ => Err(DecodeError),
        }
    }

    /// The bytes of a sub-message field.
    pub fn bytes(self) -> Result<&'a [u8], DecodeError> {
        match self {
            Value::Bytes(b) => Ok(b),
            _ => Err(DecodeError),
        }
    }
}

fn read_varint(buf: &mut &[u8]) -> Result<u64, DecodeError> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let (&b, rest) = buf.split_first().ok_or(DecodeError)?;
        *buf = rest;
        v |= u64::from(b & 0x7f) << shift;
        if b < 0x80 {
            return Ok(v);
        }
    }
    Err(DecodeError)
}

fn take<'a>(buf: &mut &'a [u8], n: usize) -> Result<&'a [u8], DecodeError> {
    if buf.len() < n {
        return Err(DecodeError);
    }
    let (head, rest) = buf.split_at(n);
    *buf = rest;
    Ok(head)
}

/// Calls `f` with every field of the message `buf`, in the order written.
pub fn for_each_field<'a>(
    mut buf: &'a [u8],
    mut f: impl FnMut(u32, Value<'a>) -> Result<(), DecodeError>,
) -> Result<(), DecodeError> {
    while !buf.is_empty() {
        let k = read_varint(&mut buf)?;
        let field = u32::try_from(k >> 3).map_err(|_| DecodeError)?;
        let value = match k & 7 {
            VARINT => Value::Varint(read_varint(&mut buf)?),
            FIXED64 => Value::Fixed64(u64::from_le_bytes(
                take(&mut buf, 8)?.try_into().expect("8 bytes"),
            )),
            LEN => {
                let n = usize::try_from(read_varint(&mut buf)?).map_err(|_| DecodeError)?;
                Value::Bytes(take(&mut buf, n)?)
            }
            FIXED32 => Value::Fixed32(u32::from_le_bytes(
                take(&mut buf, 4)?.try_into().expect("4 bytes"),
            )),
            _ => return Err(DecodeError),
        };
        if field == 0 {
            return Err(DecodeError);
        }
        f(field, value)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn varints_round_trip_at_every_length() {
        for v in [
            0u64,
            1,
            127,
            128,
            300,
            16_383,
            16_384,
            u32::MAX as u64,
            u64::MAX,
        ] {
            let mut b = Vec::new();
            int(&mut b, 3, v as i64);
            let mut got = None;
            for_each_field(&b, |f, x| {
                got = Some((f, x.int()? as u64));
                Ok(())
            })
            .unwrap();
            assert_eq!(got, if v == 0 { None } else { Some((3, v)) });
        }
    }

    #[test]
    fn a_long_sub_message_gets_a_two_byte_length() {
        let mut b = Vec::new();
        message(&mut b, 5, |b| string(b, 1, &"x".repeat(200)));
        // key, 2-byte length 203, then the body: key, 2-byte length 200, 200 bytes.
        assert_eq!(&b[..3], &[(5 << 3) | 2, 0xcb, 0x01]);
        assert_eq!(b.len(), 3 + 203);
        let mut inner = None;
        for_each_field(&b, |_, v| {
            for_each_field(v.bytes()?, |_, s| {
                inner = Some(s.string()?);
                Ok(())
            })
        })
        .unwrap();
        assert_eq!(inner.as_deref(), Some("x".repeat(200).as_str()));
    }

    #[test]
    fn truncated_or_mistyped_fields_are_errors() {
        let mut b = Vec::new();
        double(&mut b, 1, 2.5);
        assert!(for_each_field(&b[..b.len() - 1], |_, _| Ok(())).is_err());
        assert!(for_each_field(&b, |_, v| v.string().map(|_| ())).is_err());
        assert!(
            for_each_field(&[0x0b], |_, _| Ok(())).is_err(),
            "group start"
        );
        assert!(
            for_each_field(&[0x80], |_, _| Ok(())).is_err(),
            "cut varint"
        );
    }
}
