//! What an MCAP file's chunks claim, checked before the `mcap` reader trusts it: the reader allocates a
//! chunk's stated uncompressed size before decompressing, and each record's stated length inside a chunk
//! before reading it, so one flipped bit in either field of a damaged recording asked for 2⁵⁷ bytes and
//! aborted the process. A chunk may expand at most [`MAX_RATIO`] times its stored records (plus [`SLACK`])
//! and to at most [`MAX_CHUNK`] bytes; its records must decompress to that size and the records inside
//! must fit in it. The first chunk that fails marks where the readable part of the file ends.

/// Largest expansion of a chunk's stored records believed (zstd on repeated CDR messages reaches tens).
pub const MAX_RATIO: u64 = 4096;
/// Bytes a chunk may claim beyond `MAX_RATIO` times its stored records.
pub const SLACK: u64 = 1 << 20;
/// Largest uncompressed chunk believed, bytes.
pub const MAX_CHUNK: u64 = 1 << 32;

const CHUNK: u8 = 0x06;
const FOOTER: u8 = 0x02;

/// A chunk (or record) the reader must not be given.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Damaged {
    /// Byte offset of the chunk record in the file.
    pub offset: usize,
    /// Its stated uncompressed size and its stored records' length, bytes (for [`Damage::Length`], the
    /// record's stated length and 0).
    pub claimed: u64,
    pub stored: u64,
    /// What is wrong with it.
    pub damage: Damage,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Damage {
    /// The stated uncompressed size is beyond belief.
    Size,
    /// The records do not decompress to the stated size.
    Undecodable,
    /// A record inside claims more bytes than the chunk has left after it (`at`: its offset in the
    /// uncompressed records).
    Record { at: u64, length: u64 },
    /// A record of the file (chunk or not) claims a length that overflows the reader's arithmetic
    /// (`claimed`).
    Length,
}

impl std::fmt::Display for Damaged {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (at, claimed, stored) = (self.offset, self.claimed, self.stored);
        match self.damage {
            Damage::Size => write!(
                f,
                "the chunk at byte {at} claims {claimed} bytes uncompressed from {stored} stored (more than {MAX_RATIO}× or {MAX_CHUNK} bytes: a damaged size field)"
            ),
            Damage::Undecodable => write!(
                f,
                "the chunk at byte {at} does not decompress to the {claimed} bytes it states (damaged compressed data)"
            ),
            Damage::Length => write!(
                f,
                "the record at byte {at} claims {claimed} bytes (a damaged length field)"
            ),
            Damage::Record { at: inner, length } => write!(
                f,
                "a record {inner} bytes into the chunk at byte {at} claims {length} bytes, more than the chunk's {claimed} hold (a damaged length field)"
            ),
        }
    }
}

fn u64_at(b: &[u8], at: usize) -> Option<u64> {
    Some(u64::from_le_bytes(b.get(at..at + 8)?.try_into().ok()?))
}

fn u32_at(b: &[u8], at: usize) -> Option<u32> {
    Some(u32::from_le_bytes(b.get(at..at + 4)?.try_into().ok()?))
}

/// The first chunk of the data section (`bytes` is the whole file, magic included) that the reader must not
/// be given (see [`Damage`]). Records are walked by their stated lengths; a length that runs past the end,
/// or a chunk too short to read, ends the walk (the reader reports such damage itself).
pub fn first_damaged_chunk(bytes: &[u8]) -> Option<Damaged> {
    let mut at = mcap::MAGIC.len();
    while at + 9 <= bytes.len() {
        let op = bytes[at];
        let len = u64_at(bytes, at + 1)?;
        let body = at + 9;
        let end = body.saturating_add(usize::try_from(len).unwrap_or(usize::MAX));
        if op == FOOTER {
            return None;
        }
        if len > (usize::MAX - 9) as u64 {
            // The reader's arithmetic on it (opcode and length, 9 bytes, plus the length) overflows. (The
            // summary section after the data end is walked too: the reader parses it.)
            return Some(Damaged {
                offset: at,
                claimed: len,
                stored: 0,
                damage: Damage::Length,
            });
        }
        // (A chunk is checked even where its stated length runs past the end of the file: the reader
        // starts decompressing what there is.)
        if op == CHUNK {
            // message_start_time, message_end_time, uncompressed_size, uncompressed_crc, compression
            // (u32 length + bytes), records (u64 length + bytes).
            let claimed = u64_at(bytes, body + 16)?;
            let name = u32_at(bytes, body + 28)? as usize;
            let compression = bytes.get(body + 32..(body + 32).checked_add(name)?)?;
            let stored = u64_at(bytes, body + 32 + name)?;
            let damaged = |damage| {
                Some(Damaged {
                    offset: at,
                    claimed,
                    stored,
                    damage,
                })
            };
            if claimed > MAX_CHUNK
                || claimed > stored.saturating_mul(MAX_RATIO).saturating_add(SLACK)
            {
                return damaged(Damage::Size);
            }
            let start = body + 40 + name;
            let stop = start.saturating_add(usize::try_from(stored).unwrap_or(usize::MAX));
            let Some(records) = bytes.get(start..stop) else {
                // Fewer bytes than the chunk stores: the reader would decompress a part.
                return damaged(Damage::Undecodable);
            };
            if let Some(damage) = inner_damage(compression, records, claimed) {
                return damaged(damage);
            }
        }
        if end > bytes.len() {
            return None;
        }
        at = end;
    }
    None
}

/// What is wrong with a chunk's records (`stored`: as stored; `claimed`: the uncompressed size, within the
/// bounds), if anything; chunks compressed otherwise than with zstd or not at all are left to the reader.
fn inner_damage(compression: &[u8], stored: &[u8], claimed: u64) -> Option<Damage> {
    let decompressed;
    let records = match compression {
        b"" => stored,
        b"zstd" => match zstd::bulk::decompress(stored, claimed as usize) {
            Ok(d) => {
                decompressed = d;
                &decompressed[..]
            }
            Err(_) => return Some(Damage::Undecodable),
        },
        _ => return None,
    };
    if records.len() as u64 != claimed {
        return Some(Damage::Undecodable);
    }
    let mut at = 0usize;
    while at < records.len() {
        let Some(length) = u64_at(records, at + 1) else {
            return Some(Damage::Record {
                at: at as u64,
                length: 0,
            });
        };
        let room = (records.len() - at - 9) as u64;
        if length > room {
            return Some(Damage::Record {
                at: at as u64,
                length,
            });
        }
        at += 9 + length as usize;
    }
    None
}

/// The part of the file the reader may be given: all of it, or what precedes the first damaged chunk
/// (returned beside it).
pub fn readable(bytes: &[u8]) -> (&[u8], Option<Damaged>) {
    match first_damaged_chunk(bytes) {
        Some(o) => (&bytes[..o.offset], Some(o)),
        None => (bytes, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DATA_END: u8 = 0x0F;

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

    /// Offsets of the chunk records (walked as `first_damaged_chunk` does).
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
        assert_eq!(first_damaged_chunk(&b), None);
        assert_eq!(mcap::MessageStream::new(&b).unwrap().count(), 50);
    }

    #[test]
    fn a_flipped_bit_in_a_chunk_size_is_caught_before_the_reader_allocates() {
        let mut b = bag(50, 2000);
        let second = chunks(&b)[1];
        // Bit 57 of the uncompressed size (the damaged recording of the report).
        b[second + 9 + 16 + 7] ^= 0x02;
        let o = first_damaged_chunk(&b).expect("caught");
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

    /// `b` with the chunk at `at` rebuilt from `records` (uncompressed), zstd-compressed, the uncompressed
    /// size stated as `claimed`.
    fn rebuilt(b: &[u8], at: usize, records: &[u8], claimed: u64) -> Vec<u8> {
        let body = at + 9;
        let name = u32_at(b, body + 28).unwrap() as usize;
        let end = body + u64_at(b, at + 1).unwrap() as usize;
        let packed = zstd::bulk::compress(records, 3).unwrap();
        let mut chunk = b[body..body + 32 + name].to_vec();
        chunk[16..24].copy_from_slice(&claimed.to_le_bytes());
        chunk.extend((packed.len() as u64).to_le_bytes());
        chunk.extend(&packed);
        let mut out = b[..at].to_vec();
        out.push(CHUNK);
        out.extend((chunk.len() as u64).to_le_bytes());
        out.extend(chunk);
        out.extend(&b[end..]);
        out
    }

    /// The uncompressed records of the chunk at `at`.
    fn records(b: &[u8], at: usize) -> Vec<u8> {
        let body = at + 9;
        let name = u32_at(b, body + 28).unwrap() as usize;
        let stored = u64_at(b, body + 32 + name).unwrap() as usize;
        let start = body + 40 + name;
        let claimed = u64_at(b, body + 16).unwrap() as usize;
        zstd::bulk::decompress(&b[start..start + stored], claimed).unwrap()
    }

    #[test]
    fn a_damaged_length_inside_a_chunk_is_caught_before_the_reader_allocates() {
        let b = bag(50, 2000);
        let second = chunks(&b)[1];
        // Rebuilt as it was, the file passes (the rebuilding is sound).
        let inner = records(&b, second);
        let same = rebuilt(&b, second, &inner, inner.len() as u64);
        assert_eq!(first_damaged_chunk(&same), None);
        assert_eq!(mcap::MessageStream::new(&same).unwrap().count(), 50);
        // The first record inside claims 2^59 bytes; the chunk's stated size is right.
        let mut bad = inner.clone();
        bad[1..9].copy_from_slice(&(1u64 << 59).to_le_bytes());
        let b = rebuilt(&b, second, &bad, bad.len() as u64);
        let d = first_damaged_chunk(&b).expect("caught");
        assert_eq!(d.offset, second);
        assert_eq!(
            d.damage,
            Damage::Record {
                at: 0,
                length: 1 << 59
            }
        );
        assert!(
            d.to_string().contains("claims 576460752303423488 bytes"),
            "{d}"
        );
        // Records that do not decompress to the stated size.
        let b2 = rebuilt(&b, second, &inner, inner.len() as u64 + 10);
        assert_eq!(
            first_damaged_chunk(&b2).map(|d| d.damage),
            Some(Damage::Undecodable)
        );
    }

    #[test]
    fn a_chunk_running_past_the_end_is_checked_too() {
        // A recording whose first chunk's record length was damaged to run past the end of the file, and
        // whose chunk records hold a damaged length inside (found by the fuzzing too).
        let b = include_bytes!("../tests/data/chunk_past_the_end.mcap");
        let (part, damaged) = readable(b);
        let d = damaged.expect("caught");
        assert_eq!(d.offset, chunks(b)[0], "{d}");
        assert_eq!(
            mcap::MessageStream::new_with_options(part, mcap::read::Options::IgnoreEndMagic.into())
                .unwrap()
                .count(),
            0
        );
        // A sound file cut inside a chunk: the cut chunk is refused before the reader decompresses a part.
        let sound = bag(50, 2000);
        let second = chunks(&sound)[1];
        // (One byte into its records: opcode and length, three times and a u32, the name "zstd", a u64.)
        let cut = &sound[..second + 9 + 32 + 4 + 8 + 1];
        let d = first_damaged_chunk(cut).expect("caught");
        assert_eq!((d.offset, d.damage), (second, Damage::Undecodable));
    }

    #[test]
    fn a_record_longer_than_the_file_is_caught_in_the_summary_too() {
        // A recording whose summary holds a record claiming 2^64 - 1 bytes: the reader's 9 + length
        // wrapped round and it panicked slicing (found by the fuzzing).
        let b = include_bytes!("../tests/data/summary_length.mcap");
        let d = first_damaged_chunk(b).expect("caught");
        assert_eq!(d.damage, Damage::Length, "{d}");
        let (part, _) = readable(b);
        let n =
            mcap::MessageStream::new_with_options(part, mcap::read::Options::IgnoreEndMagic.into())
                .unwrap()
                .take_while(|m| m.is_ok())
                .count();
        assert!(n > 0, "the messages before it read: {n}");
    }

    #[test]
    fn the_recording_that_aborted_the_reader_reads_up_to_its_damaged_chunk() {
        // A node's recording with a damaged record length inside a compressed chunk, found by the fuzzing
        // of `slosh_tests::fuzz` (`memory allocation of 733649612327447619 bytes failed` in the reader).
        let b = include_bytes!("../tests/data/damaged_record_length.mcap");
        let (part, damaged) = readable(b);
        let d = damaged.expect("caught");
        assert!(
            matches!(d.damage, Damage::Record { .. } | Damage::Undecodable),
            "{d}"
        );
        // Its first chunk is the damaged one: the reader gets the header records only, and returns.
        assert_eq!(d.offset, chunks(b)[0], "{d}");
        let read =
            mcap::MessageStream::new_with_options(part, mcap::read::Options::IgnoreEndMagic.into())
                .unwrap()
                .count();
        assert_eq!(read, 0);
    }
}
