//! The messages of Foxglove's scene schemas that the logs write, with the schemas' field
//! names and numbers (fields the logs never set are left out and skipped when read).

use super::wire::{self, Value};
use super::{DecodeError, Message, Schema};

/// How a field is written and read.
trait Field {
    /// The field's type in a `FieldDescriptorProto` (1 double, 9 string, 11 message, 14 enum).
    #[cfg(test)]
    const TYPE: i32;
    /// Whether the field is `repeated`.
    #[cfg(test)]
    const REPEATED: bool = false;
    fn put(&self, buf: &mut Vec<u8>, field: u32);
    fn take(&mut self, value: Value<'_>) -> Result<(), DecodeError>;
}

impl Field for f64 {
    #[cfg(test)]
    const TYPE: i32 = 1;
    fn put(&self, buf: &mut Vec<u8>, field: u32) {
        wire::double(buf, field, *self);
    }
    fn take(&mut self, value: Value<'_>) -> Result<(), DecodeError> {
        *self = value.double()?;
        Ok(())
    }
}

/// Enums.
impl Field for i32 {
    #[cfg(test)]
    const TYPE: i32 = 14;
    fn put(&self, buf: &mut Vec<u8>, field: u32) {
        wire::int(buf, field, i64::from(*self));
    }
    fn take(&mut self, value: Value<'_>) -> Result<(), DecodeError> {
        *self = value.int()? as i32;
        Ok(())
    }
}

impl Field for String {
    #[cfg(test)]
    const TYPE: i32 = 9;
    fn put(&self, buf: &mut Vec<u8>, field: u32) {
        wire::string(buf, field, self);
    }
    fn take(&mut self, value: Value<'_>) -> Result<(), DecodeError> {
        *self = value.string()?;
        Ok(())
    }
}

impl<M: Message> Field for Option<M> {
    #[cfg(test)]
    const TYPE: i32 = 11;
    fn put(&self, buf: &mut Vec<u8>, field: u32) {
        if let Some(m) = self {
            wire::message(buf, field, |b| m.encode(b));
        }
    }
    /// A message field read twice merges, as protobuf says.
    fn take(&mut self, value: Value<'_>) -> Result<(), DecodeError> {
        self.get_or_insert_default().merge(value.bytes()?)
    }
}

impl<M: Message> Field for Vec<M> {
    #[cfg(test)]
    const TYPE: i32 = 11;
    #[cfg(test)]
    const REPEATED: bool = true;
    fn put(&self, buf: &mut Vec<u8>, field: u32) {
        for m in self {
            wire::message(buf, field, |b| m.encode(b));
        }
    }
    fn take(&mut self, value: Value<'_>) -> Result<(), DecodeError> {
        self.push(M::decode(value.bytes()?)?);
        Ok(())
    }
}

/// A field's name, number, descriptor type and whether it is repeated.
#[cfg(test)]
type FieldInfo = (&'static str, u32, i32, bool);

/// Declares messages: each field with its number in the schema.
macro_rules! messages {
    ($(
        $(#[$meta:meta])*
        $name:ident { $( $(#[$fmeta:meta])* $field:ident: $ty:ty = $num:literal ),* $(,)? }
    )*) => {$(
        $(#[$meta])*
        #[derive(Debug, Clone, Default, PartialEq)]
        pub struct $name {
            $( $(#[$fmeta])* pub $field: $ty, )*
        }

        impl $name {
            /// Each field's name, number, descriptor type and whether it is repeated.
            #[cfg(test)]
            const FIELDS: &'static [FieldInfo] = &[
                $( (stringify!($field), $num, <$ty as Field>::TYPE, <$ty as Field>::REPEATED), )*
            ];
        }

        impl Message for $name {
            fn encode(&self, buf: &mut Vec<u8>) {
                $( Field::put(&self.$field, buf, $num); )*
            }
            fn merge_field(&mut self, field: u32, value: Value<'_>) -> Result<(), DecodeError> {
                match field {
                    $( $num => Field::take(&mut self.$field, value), )*
                    _ => Ok(()),
                }
            }
        }
    )*};
}

messages! {
    /// `foxglove.Color`: RGBA in `[0, 1]`.
    #[derive(Copy)]
    Color { r: f64 = 1, g: f64 = 2, b: f64 = 3, a: f64 = 4 }

    /// `foxglove.Vector3`.
    #[derive(Copy)]
    Vector3 { x: f64 = 1, y: f64 = 2, z: f64 = 3 }

    /// `foxglove.Point3`.
    #[derive(Copy)]
    Point3 { x: f64 = 1, y: f64 = 2, z: f64 = 3 }

    /// `foxglove.Quaternion`.
    #[derive(Copy)]
    Quaternion { x: f64 = 1, y: f64 = 2, z: f64 = 3, w: f64 = 4 }

    /// `foxglove.Pose`.
    Pose { position: Option<Vector3> = 1, orientation: Option<Quaternion> = 2 }

    /// `foxglove.PoseInFrame`.
    PoseInFrame { timestamp: Option<Timestamp> = 1, frame_id: String = 2, pose: Option<Pose> = 3 }

    /// `foxglove.FrameTransform`: the pose of `child_frame_id` in `parent_frame_id`.
    FrameTransform {
        timestamp: Option<Timestamp> = 1,
        parent_frame_id: String = 2,
        child_frame_id: String = 3,
        translation: Option<Vector3> = 4,
        rotation: Option<Quaternion> = 5,
    }

    /// `foxglove.ArrowPrimitive`: an arrow along the pose's +x.
    ArrowPrimitive {
        pose: Option<Pose> = 1,
        shaft_length: f64 = 2,
        shaft_diameter: f64 = 3,
        head_length: f64 = 4,
        head_diameter: f64 = 5,
        color: Option<Color> = 6,
    }

    /// `foxglove.CubePrimitive`.
    CubePrimitive { pose: Option<Pose> = 1, size: Option<Vector3> = 2, color: Option<Color> = 3 }

    /// `foxglove.SpherePrimitive`.
    SpherePrimitive { pose: Option<Pose> = 1, size: Option<Vector3> = 2, color: Option<Color> = 3 }

    /// `foxglove.CylinderPrimitive`: its axis along the pose's z.
    CylinderPrimitive {
        pose: Option<Pose> = 1,
        size: Option<Vector3> = 2,
        bottom_scale: f64 = 3,
        top_scale: f64 = 4,
        color: Option<Color> = 5,
    }

    /// `foxglove.LinePrimitive`.
    LinePrimitive {
        /// One of [`LinePrimitive::LINE_STRIP`], `LINE_LOOP` or `LINE_LIST`.
        r#type: i32 = 1,
        pose: Option<Pose> = 2,
        thickness: f64 = 3,
        points: Vec<Point3> = 5,
        color: Option<Color> = 6,
    }

    /// `foxglove.TriangleListPrimitive`: every three points a triangle.
    TriangleListPrimitive { pose: Option<Pose> = 1, points: Vec<Point3> = 2, color: Option<Color> = 3 }

    /// `foxglove.SceneEntity`.
    SceneEntity {
        timestamp: Option<Timestamp> = 1,
        frame_id: String = 2,
        id: String = 3,
        arrows: Vec<ArrowPrimitive> = 7,
        cubes: Vec<CubePrimitive> = 8,
        spheres: Vec<SpherePrimitive> = 9,
        cylinders: Vec<CylinderPrimitive> = 10,
        lines: Vec<LinePrimitive> = 11,
        triangles: Vec<TriangleListPrimitive> = 12,
    }

    /// `foxglove.SceneUpdate`.
    SceneUpdate { entities: Vec<SceneEntity> = 2 }
}

impl LinePrimitive {
    /// Consecutive points joined.
    pub const LINE_STRIP: i32 = 0;
    /// Consecutive points joined, the last to the first.
    pub const LINE_LOOP: i32 = 1;
    /// Each pair of points a segment.
    pub const LINE_LIST: i32 = 2;
}

/// A time as `google.protobuf.Timestamp` (which Foxglove's schemas use): seconds and
/// nanoseconds since the Unix epoch.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Timestamp {
    /// Whole seconds.
    pub sec: u32,
    /// Nanoseconds, below 10⁹.
    pub nsec: u32,
}

impl Timestamp {
    /// The time `sec` s + `nsec` ns (nanoseconds past a second carried into the seconds).
    pub fn new(sec: u32, nsec: u32) -> Self {
        Timestamp {
            sec: sec.saturating_add(nsec / 1_000_000_000),
            nsec: nsec % 1_000_000_000,
        }
    }
}

impl Message for Timestamp {
    fn encode(&self, buf: &mut Vec<u8>) {
        wire::int(buf, 1, i64::from(self.sec));
        wire::int(buf, 2, i64::from(self.nsec));
    }
    fn merge_field(&mut self, field: u32, value: Value<'_>) -> Result<(), DecodeError> {
        let out_of_range = |_| DecodeError;
        match field {
            1 => self.sec = u32::try_from(value.int()?).map_err(out_of_range)?,
            2 => self.nsec = u32::try_from(value.int()?).map_err(out_of_range)?,
            _ => {}
        }
        Ok(())
    }
}

impl Schema for SceneUpdate {
    const NAME: &'static str = "foxglove.SceneUpdate";
    const DESCRIPTOR: &'static [u8] = include_bytes!("descriptors/SceneUpdate.bin");
}

impl Schema for PoseInFrame {
    const NAME: &'static str = "foxglove.PoseInFrame";
    const DESCRIPTOR: &'static [u8] = include_bytes!("descriptors/PoseInFrame.bin");
}

impl Schema for FrameTransform {
    const NAME: &'static str = "foxglove.FrameTransform";
    const DESCRIPTOR: &'static [u8] = include_bytes!("descriptors/FrameTransform.bin");
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::foxglove::wire::for_each_field;
    use std::collections::HashMap;

    /// `(message, field) → (number, type, repeated)` of every field of every message in a
    /// binary `FileDescriptorSet`, read with the same wire reader (descriptors are protobuf).
    fn descriptor_fields(set: &[u8]) -> HashMap<(String, String), (u32, i32, bool)> {
        let mut out = HashMap::new();
        for_each_field(set, |f, file| {
            assert_eq!(f, 1, "FileDescriptorSet.file");
            let mut package = String::new();
            let mut messages = Vec::new();
            for_each_field(file.bytes()?, |f, v| {
                match f {
                    2 => package = v.string()?,
                    4 => messages.push(v.bytes()?),
                    _ => {}
                }
                Ok(())
            })?;
            for m in messages {
                let mut name = String::new();
                let mut fields = Vec::new();
                for_each_field(m, |f, v| {
                    match f {
                        1 => name = v.string()?,
                        2 => fields.push(v.bytes()?),
                        _ => {}
                    }
                    Ok(())
                })?;
                for field in fields {
                    let (mut fname, mut num, mut label, mut ty) = (String::new(), 0, 0, 0);
                    for_each_field(field, |f, v| {
                        match f {
                            1 => fname = v.string()?,
                            3 => num = v.int()? as u32,
                            4 => label = v.int()? as i32,
                            5 => ty = v.int()? as i32,
                            _ => {}
                        }
                        Ok(())
                    })?;
                    out.insert((format!("{package}.{name}"), fname), (num, ty, label == 3));
                }
            }
            Ok(())
        })
        .expect("the descriptor decodes");
        out
    }

    #[test]
    fn every_field_has_the_number_and_type_foxglove_s_schema_gives_it() {
        let mut known = HashMap::new();
        for d in [
            SceneUpdate::DESCRIPTOR,
            PoseInFrame::DESCRIPTOR,
            FrameTransform::DESCRIPTOR,
        ] {
            known.extend(descriptor_fields(d));
        }
        let ours: [(&str, &[FieldInfo]); 16] = [
            ("Color", Color::FIELDS),
            ("Vector3", Vector3::FIELDS),
            ("Point3", Point3::FIELDS),
            ("Quaternion", Quaternion::FIELDS),
            ("Pose", Pose::FIELDS),
            ("PoseInFrame", PoseInFrame::FIELDS),
            ("FrameTransform", FrameTransform::FIELDS),
            ("ArrowPrimitive", ArrowPrimitive::FIELDS),
            ("CubePrimitive", CubePrimitive::FIELDS),
            ("SpherePrimitive", SpherePrimitive::FIELDS),
            ("CylinderPrimitive", CylinderPrimitive::FIELDS),
            ("LinePrimitive", LinePrimitive::FIELDS),
            ("TriangleListPrimitive", TriangleListPrimitive::FIELDS),
            ("SceneEntity", SceneEntity::FIELDS),
            ("SceneUpdate", SceneUpdate::FIELDS),
            (
                "google.protobuf.Timestamp",
                // int64 seconds and int32 nanos.
                &[("seconds", 1, 3, false), ("nanos", 2, 5, false)],
            ),
        ];
        let mut checked = 0;
        for (message, fields) in ours {
            let full = if message.contains('.') {
                message.to_string()
            } else {
                format!("foxglove.{message}")
            };
            for &(name, num, ty, repeated) in fields {
                let name = name.trim_start_matches("r#");
                let got = known.get(&(full.clone(), name.to_string()));
                assert_eq!(got, Some(&(num, ty, repeated)), "{full}.{name}");
                checked += 1;
            }
        }
        assert_eq!(checked, 61);
    }

    /// A scene update with one of every primitive, long enough for two-byte lengths.
    fn every_primitive() -> SceneUpdate {
        let pose = Some(Pose {
            position: Some(Vector3 {
                x: 1.0,
                y: -2.0,
                z: 0.0,
            }),
            orientation: Some(Quaternion {
                x: 0.0,
                y: 0.6,
                z: 0.0,
                w: 0.8,
            }),
        });
        let c = Some(Color {
            r: 0.5,
            g: 0.25,
            b: 1.0,
            a: 0.6,
        });
        let pts: Vec<Point3> = (0..100)
            .map(|i| Point3 {
                x: f64::from(i),
                y: -0.5 * f64::from(i),
                z: 1e-300,
            })
            .collect();
        SceneUpdate {
            entities: vec![SceneEntity {
                timestamp: Some(Timestamp::new(1_700_000_000, 1_500_000_000)),
                frame_id: "rod".into(),
                id: "obstacle/α".into(),
                arrows: vec![ArrowPrimitive {
                    pose: pose.clone(),
                    shaft_length: 0.7,
                    head_length: 0.3,
                    color: c,
                    ..Default::default()
                }],
                cubes: vec![CubePrimitive {
                    pose: pose.clone(),
                    size: Some(Vector3 {
                        x: 1.0,
                        y: 2.0,
                        z: 3.0,
                    }),
                    color: c,
                }],
                spheres: vec![SpherePrimitive::default()],
                cylinders: vec![CylinderPrimitive {
                    top_scale: 1.0,
                    bottom_scale: 1.0,
                    ..Default::default()
                }],
                lines: vec![LinePrimitive {
                    r#type: LinePrimitive::LINE_LIST,
                    pose: pose.clone(),
                    thickness: 0.01,
                    points: pts.clone(),
                    color: c,
                }],
                triangles: vec![TriangleListPrimitive {
                    pose,
                    points: pts,
                    color: c,
                }],
            }],
        }
    }

    #[test]
    fn a_scene_update_with_every_primitive_round_trips() {
        let up = every_primitive();
        let bytes = up.encode_to_vec();
        assert_eq!(SceneUpdate::decode(&bytes), Ok(up.clone()));
        assert_eq!(
            up.entities[0].timestamp,
            Some(Timestamp {
                sec: 1_700_000_001,
                nsec: 500_000_000
            })
        );
        // A cut message is an error, not a shorter message.
        assert!(SceneUpdate::decode(&bytes[..bytes.len() - 1]).is_err());
        // Unknown fields (here `deletions`, 1) are skipped.
        let mut with_unknown = vec![0x0a, 0x00];
        with_unknown.extend_from_slice(&bytes);
        assert_eq!(SceneUpdate::decode(&with_unknown), Ok(up));
    }

    /// Damaged messages (a byte changed, inserted or cut off, or random bytes) decode to some
    /// message or fail with an error: the decoder never panics, reads past the end, or loops.
    #[test]
    fn damaged_messages_decode_or_fail_without_panicking() {
        let valid = every_primitive().encode_to_vec();
        let mut state = 0x9E37_79B9_7F4A_7C15_u64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        let (mut ok, mut failed) = (0, 0);
        for round in 0..20_000 {
            let mut b = valid.clone();
            let at = (next() % b.len() as u64) as usize;
            match round % 4 {
                0 => b[at] ^= 1 << (next() % 8),
                1 => b.insert(at, next() as u8),
                2 => b.truncate(at),
                _ => b = (0..next() % 64).map(|_| next() as u8).collect(),
            }
            match SceneUpdate::decode(&b) {
                Ok(_) => ok += 1,
                Err(DecodeError) => failed += 1,
            }
            let _ = PoseInFrame::decode(&b);
            let _ = FrameTransform::decode(&b);
        }
        // Both outcomes occur: a changed double still decodes, a cut sub-message does not.
        assert!(
            ok > 1_000 && failed > 1_000,
            "{ok} decoded, {failed} failed"
        );
    }
}
