//! What an MCAP file's chunks claim, checked before the `mcap` reader trusts it: the reader allocates a
//! chunk's stated uncompressed size before decompressing, so one flipped bit in that field of a damaged
//! recording asked for 2⁵⁷ bytes and aborted the process. A chunk may expand at most [`MAX_RATIO`] times
//! its stored records (plus [`SLACK`]) and to at most [`MAX_CHUNK`] bytes; the first that claims more marks
//! where the readable part of the file ends.

/// Largest expansion of a chunk's stored records believed (zstd on repeated CDR messages reaches tens).
pub const MAX_RATIO: u64 = 4096;
/// Bytes a chunk may claim beyond `MAX_RATIO` times its stored records.
pub const SLACK: u64 = 1 << 20;
/// Largest uncompressed chunk believed, bytes.
pub const MAX_CHUNK: u64 = 1 << 32;

const CHUNK: u8 = 0x06;
const DATA_END: u8 = 0x0F;
const FOOTER: u8 = 0x02;

/// A chunk whose stated uncompressed size is beyond belief.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Oversized {
    /// Byte offset of the chunk record in the file.
    pub offset: usize,
    /// Its stated uncompressed size and its stored records' length, bytes.
    pub claimed: u64,
    pub stored: u64,
}

impl std::fmt::Display for Oversized {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "the chunk at byte {} claims {} bytes uncompressed from {} stored (more than {MAX_RATIO}× or {MAX_CHUNK} bytes: a damaged size field)",
            self.offset, self.claimed, self.stored
        )
    }
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// The first chunk of the data section (`bytes` is the whole file, magic included) whose stated
/// uncompressed size is beyond the bounds. Records are walked by their stated lengths; a length that runs
/// past the end, or a chunk too short to read, ends the walk (the reader reports such damage itself).
pub fn first_oversized_chunk(bytes: &[u8]) -> Option<Oversized> {
    let mut at = mcap::MAGIC.len();
    while at + 9 <= bytes.len() {
        let op = bytes[at];
        let len = u64_at(bytes, at + 1)?;
        let body = at + 9;
        let end = body.checked_add(usize::try_from(len).ok()?)?;
        if end > bytes.len() || op == DATA_END || op == FOOTER {
            return None;
        }
        if op == CHUNK {
            // message_start_time, message_end_time, uncompressed_size, uncompressed_crc, compression
            // (u32 length + bytes), records (u64 length + bytes).
            let claimed = u64_at(bytes, body + 16)?;
            let name = u32_at(bytes, body + 28)? as usize;
            let stored = u64_at(bytes, body + 32 + name)?;
            if claimed > MAX_CHUNK
                || claimed > stored.saturating_mul(MAX_RATIO).saturating_add(SLACK)
            {
                return Some(Oversized {
                    offset: at,
                    claimed,
                    stored,
                });
            }
        }
        at = end;
    }
    None
}

/// The part of the file the reader may be given: all of it, or what precedes the first oversized chunk
/// (returned beside it).
pub fn readable(bytes: &[u8]) -> (&[u8], Option<Oversized>) {
    match first_oversized_chunk(bytes) {
        Some(o) => (&bytes[..o.offset], Some(o)),
        None => (bytes, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A small MCAP file of `n` messages in zstd chunks of ~`chunk` bytes.
    fn bag(n: usize, chunk: u64) -> Vec<u8> {
        let mut out = std::io::Cursor::new(Vec::new());
        {
            let mut w = mcap::WriteOptions::new()
                .chunk_size(Some(chunk))
                .compression(Some(mcap::Compression::Zstd))
                .create(&mut out)
                .unwrap();
            let ch = w
                .add_channel(0, "/t", "cdr", &std::collections::BTreeMap::new())
                .unwrap();
            for i in 0..n {
                let header = mcap::records::MessageHeader {
                    channel_id: ch,
                    sequence: i as u32,
                    log_time: i as u64,
                    publish_time: i as u64,
                };
                w.write_to_known_channel(&header, &[7u8; 200]).unwrap();
            }
            w.finish().unwrap();
        }
        out.into_inner()
    }

    /// Offsets of the chunk records (walked as `first_oversized_chunk` does).
    fn chunks(b: &[u8]) -> Vec<usize> {
        let (mut at, mut v) = (mcap::MAGIC.len(), vec![]);
        while at + 9 <= b.len() && b[at] != DATA_END {
            if b[at] == CHUNK {
                v.push(at);
            }
            at += 9 + u64_at(b, at + 1).unwrap() as usize;
        }
        v
    }

    #[test]
    fn a_sound_file_passes() {
        let b = bag(50, 2000);
        assert!(chunks(&b).len() > 2);
        assert_eq!(first_oversized_chunk(&b), None);
        assert_eq!(mcap::MessageStream::new(&b).unwrap().count(), 50);
    }

    #[test]
    fn a_flipped_bit_in_a_chunk_size_is_caught_before_the_reader_allocates() {
        let mut b = bag(50, 2000);
        let second = chunks(&b)[1];
        // Bit 57 of the uncompressed size (the damaged recording of the report).
        b[second + 9 + 16 + 7] ^= 0x02;
        let o = first_oversized_chunk(&b).expect("caught");
        assert_eq!(o.offset, second);
        assert!(o.claimed > 1 << 56, "{o:?}");
        assert!(o.to_string().contains(&format!("byte {second}")), "{o}");
        // What lies before it reads whole.
        let (part, again) = readable(&b);
        assert_eq!(again, Some(o));
        let before =
            mcap::MessageStream::new_with_options(part, mcap::read::Options::IgnoreEndMagic.into())
                .unwrap()
                .take_while(|m| m.is_ok())
                .count();
        assert!(before > 0 && before < 50, "{before}");
    }
}
