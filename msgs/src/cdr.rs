//! ROS 2 serialized messages: a 4-byte CDR encapsulation header, then the message in plain
//! (XCDR version 1) CDR.
//!
//! This is the form of a message in a DDS sample, in `rmw_serialize`'s output and in ros2 bag
//! files. Multi-byte values are aligned to their size (8 for `float64`) counted from the start of
//! the body, i.e. after the header; strings are a `u32` length (including the terminating NUL),
//! the bytes and a NUL; sequences are a `u32` count and the elements; fixed arrays are the
//! elements alone.

use std::fmt;

use byteorder::{BigEndian, LittleEndian};
use serde::de::DeserializeOwned;
use serde::Serialize;

/// Encapsulation header of little-endian plain CDR (`CDR_LE`), the one [`to_cdr`] writes.
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Encapsulation identifier of big-endian plain CDR (`CDR_BE`).
const CDR_BE_ID: [u8; 2] = [0x00, 0x00];
/// Encapsulation identifier of little-endian plain CDR (`CDR_LE`).
const CDR_LE_ID: [u8; 2] = [0x00, 0x01];

/// Why a message could not be encoded or decoded.
#[derive(Debug)]
pub enum CdrError {
    /// The input is shorter than the 4-byte encapsulation header.
    TooShort {
        /// Length of the input, bytes.
        len: usize,
    },
    /// The encapsulation identifier (first two bytes) is not plain CDR (`00 00` or `00 01`),
    /// e.g. XCDR2 (`00 07`, `00 09`, ...) or a parameter list (`00 02`, `00 03`).
    UnsupportedEncapsulation([u8; 2]),
    /// The body does not decode as the requested type.
    Decode(cdr_encoding::Error),
    /// The value cannot be CDR-encoded.
    Encode(cdr_encoding::Error),
}

impl fmt::Display for CdrError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CdrError::TooShort { len } => write!(
                f,
                "serialized message is {len} bytes long, shorter than the 4-byte CDR encapsulation header"
            ),
            CdrError::UnsupportedEncapsulation([a, b]) => write!(
                f,
                "unsupported encapsulation {a:02x} {b:02x}: only plain CDR (00 01 little endian, \
                 00 00 big endian) is supported"
            ),
            CdrError::Decode(e) => write!(f, "CDR decoding failed: {e}"),
            CdrError::Encode(e) => write!(f, "CDR encoding failed: {e}"),
        }
    }
}

impl std::error::Error for CdrError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            CdrError::Decode(e) | CdrError::Encode(e) => Some(e),
            _ => None,
        }
    }
}

/// Encodes `msg` as a ROS 2 serialized message: [`CDR_LE_HEADER`], then the little-endian CDR
/// body.
///
/// Fails only for values CDR cannot represent (a sequence of unknown length, a serde error of
/// the value's own); never for the message types of this crate.
pub fn try_to_cdr<T: Serialize + ?Sized>(msg: &T) -> Result<Vec<u8>, CdrError> {
    let mut buf = Vec::with_capacity(64);
    buf.extend_from_slice(&CDR_LE_HEADER);
    // The serializer counts alignment from the bytes it writes itself, i.e. from the body start.
    msg.serialize(&mut cdr_encoding::CdrSerializer::<_, LittleEndian>::new(
        &mut buf,
    ))
    .map_err(CdrError::Encode)?;
    Ok(buf)
}

/// Encodes `msg` as a ROS 2 serialized message: [`CDR_LE_HEADER`], then the little-endian CDR
/// body.
///
/// # Panics
/// If [`try_to_cdr`] fails, which it cannot for the message types of this crate.
pub fn to_cdr<T: Serialize + ?Sized>(msg: &T) -> Vec<u8> {
    match try_to_cdr(msg) {
        Ok(bytes) => bytes,
        Err(e) => panic!("to_cdr: {e}"),
    }
}

/// Decodes a ROS 2 serialized message (encapsulation header, then the body) written in
/// little-endian (`00 01`) or big-endian (`00 00`) plain CDR.
///
/// The two option bytes of the header and any bytes after the message (DDS implementations pad
/// samples to a multiple of 4) are ignored.
pub fn from_cdr<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, CdrError> {
    if bytes.len() < 4 {
        return Err(CdrError::TooShort { len: bytes.len() });
    }
    let (header, body) = bytes.split_at(4);
    let id = [header[0], header[1]];
    let decoded = match id {
        CDR_LE_ID => cdr_encoding::from_bytes::<T, LittleEndian>(body),
        CDR_BE_ID => cdr_encoding::from_bytes::<T, BigEndian>(body),
        _ => return Err(CdrError::UnsupportedEncapsulation(id)),
    };
    decoded
        .map(|(msg, _consumed)| msg)
        .map_err(CdrError::Decode)
}

/// Serde helpers for `uint8[]` fields held as `Vec<u8>`: the same bytes as a CDR
/// `sequence<uint8>` (a `u32` count, then the bytes) as serde's default for `Vec<u8>`, but
/// written and read in one piece instead of byte by byte.
pub(crate) mod byte_seq {
    use std::fmt;

    use serde::de::{SeqAccess, Visitor};
    use serde::{Deserializer, Serializer};

    pub fn serialize<S: Serializer>(bytes: &[u8], serializer: S) -> Result<S::Ok, S::Error> {
        serializer.serialize_bytes(bytes)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Vec<u8>, D::Error> {
        deserializer.deserialize_byte_buf(ByteBufVisitor)
    }

    struct ByteBufVisitor;

    impl<'de> Visitor<'de> for ByteBufVisitor {
        type Value = Vec<u8>;

        fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
            f.write_str("a sequence of bytes")
        }

        fn visit_bytes<E: serde::de::Error>(self, v: &[u8]) -> Result<Vec<u8>, E> {
            Ok(v.to_vec())
        }

        fn visit_byte_buf<E: serde::de::Error>(self, v: Vec<u8>) -> Result<Vec<u8>, E> {
            Ok(v)
        }

        fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Vec<u8>, A::Error> {
            let mut out = Vec::with_capacity(seq.size_hint().unwrap_or(0).min(1 << 20));
            while let Some(b) = seq.next_element::<u8>()? {
                out.push(b);
            }
            Ok(out)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Deserialize;

    #[derive(Serialize, Deserialize, Debug, PartialEq)]
    struct Mixed {
        a: u8,
        b: f64,
        s: String,
        c: u32,
        #[serde(with = "byte_seq")]
        data: Vec<u8>,
        plain: Vec<u8>,
        flag: bool,
    }

    fn mixed() -> Mixed {
        Mixed {
            a: 7,
            b: 1.5,
            s: "abc".into(),
            c: 0x0102_0304,
            data: vec![9, 8, 7],
            plain: vec![9, 8, 7],
            flag: true,
        }
    }

    #[test]
    fn layout_is_plain_little_endian_cdr_aligned_from_the_body() {
        let bytes = to_cdr(&mixed());
        #[rustfmt::skip]
        let expected: Vec<u8> = vec![
            0, 1, 0, 0, // header
            7, 0, 0, 0, 0, 0, 0, 0, // a, padding to 8
            0, 0, 0, 0, 0, 0, 0xf8, 0x3f, // b = 1.5
            4, 0, 0, 0, b'a', b'b', b'c', 0, // s
            4, 3, 2, 1, // c
            3, 0, 0, 0, 9, 8, 7, 0, // data (with byte_seq), padding to 4
            3, 0, 0, 0, 9, 8, 7, // plain Vec<u8>: the same layout
            1, // flag
        ];
        assert_eq!(bytes, expected);
        assert_eq!(from_cdr::<Mixed>(&bytes).unwrap(), mixed());
    }

    #[test]
    fn big_endian_is_read() {
        #[rustfmt::skip]
        let bytes = [0, 0, 0, 0, 0, 0, 0, 5, 0, 0, 0, 2, b'h', 0];
        #[derive(Deserialize, Debug, PartialEq)]
        struct S {
            x: i32,
            s: String,
        }
        let s: S = from_cdr(&bytes).unwrap();
        assert_eq!(
            s,
            S {
                x: 5,
                s: "h".into()
            }
        );
    }

    #[test]
    fn trailing_padding_and_options_are_ignored() {
        let mut bytes = to_cdr(&"ab".to_string());
        bytes[3] = 1; // XTypes uses the low option bits for the padding length
        bytes.push(0);
        assert_eq!(from_cdr::<String>(&bytes).unwrap(), "ab");
    }

    #[test]
    fn bad_input_is_an_error() {
        let e = from_cdr::<u32>(&[0, 1]).unwrap_err();
        assert!(matches!(e, CdrError::TooShort { len: 2 }), "{e}");
        let e = from_cdr::<u32>(&[0, 7, 0, 0, 1, 0, 0, 0]).unwrap_err();
        assert!(matches!(e, CdrError::UnsupportedEncapsulation([0, 7])));
        assert!(e.to_string().contains("00 07"), "{e}");
        let e = from_cdr::<u32>(&[0, 1, 0, 0, 1, 0]).unwrap_err();
        assert!(matches!(e, CdrError::Decode(_)), "{e}");
        // A sequence claiming more elements than there are bytes.
        let e = from_cdr::<Vec<u8>>(&[0, 1, 0, 0, 0xff, 0xff, 0xff, 0xff, 1]).unwrap_err();
        assert!(matches!(e, CdrError::Decode(_)), "{e}");
    }
}
