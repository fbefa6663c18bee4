//! One zlib stream (RFC 1950) from strips compressed independently and in parallel, for
//! PNG image data: each strip of filtered scan lines is compressed by its own
//! [`fdeflate::Compressor`] (the `png` crate's fast encoder: one dynamic-Huffman block
//! with a fixed code tuned for filtered image bytes, runs of zeros as distance-1 matches,
//! so no strip refers back into another), and the streams are joined:
//!
//! - every strip but the first loses its 2-byte zlib header, every strip its Adler-32;
//! - every block but the last gets BFINAL = 0 (RFC 1951 §3.2.3, the first bit of the block
//!   header, bit 0 of the byte after the zlib header) and is followed by an empty stored
//!   block — 3 header bits 000, zero padding to a byte boundary, LEN = 0x0000,
//!   NLEN = 0xFFFF, zlib's "sync flush" — so that the next strip's block starts on a byte
//!   boundary, as its compressor wrote it;
//! - the stream ends with the Adler-32 of all the strips' bytes, combined from the strips'
//!   own checksums (zlib's `adler32_combine`).
//!
//! The empty stored block's header has to start right after the block's end-of-block
//! code, inside the zero bits fdeflate padded the stream's last byte with. Their number is
//! found from that byte: fdeflate's end-of-block code (canonical 111111110001, written
//! from its most significant bit) ends with a 1, so the padding is the byte's leading
//! zeros. [`joining_works`] checks this once per process on a probe (strips of 1 to 24
//! bytes, every padding length), so that a future fdeflate with another code makes the
//! caller fall back to one sequential stream instead of writing broken files.

use std::io;
use std::sync::OnceLock;

/// Adler-32 modulus (RFC 1950 §8).
const ADLER_BASE: u64 = 65521;

/// Adler-32 of the concatenation A ‖ B from adler(A), adler(B) and |B| (zlib's
/// `adler32_combine`: s1 = 1 + Σ bytes, s2 = Σ of the running s1 values, so B's s2 gains
/// |B| · (s1(A) − 1) and B's s1 gains s1(A) − 1).
pub(crate) fn adler32_combine(a: u32, b: u32, len_b: usize) -> u32 {
    let rem = len_b as u64 % ADLER_BASE;
    let (a1, a2) = ((a & 0xffff) as u64, (a >> 16) as u64);
    let (b1, b2) = ((b & 0xffff) as u64, (b >> 16) as u64);
    let s1 = (a1 + b1 + ADLER_BASE - 1) % ADLER_BASE;
    let s2 = (rem * a1 % ADLER_BASE + a2 + b2 + ADLER_BASE - rem) % ADLER_BASE;
    ((s2 << 16) | s1) as u32
}

/// One strip as a complete zlib stream of its own, with its input length.
pub(crate) struct CompressedStrip {
    stream: Vec<u8>,
    input_len: usize,
    /// Offset of the last block's header when the stream is stored blocks (no
    /// compression), `None` for one fdeflate block.
    stored_last_header: Option<usize>,
}

impl CompressedStrip {
    /// Bytes of the strip's zlib stream.
    pub(crate) fn len(&self) -> usize {
        self.stream.len()
    }
}

/// Compresses `data` (one strip of filtered scan lines) into its own zlib stream.
pub(crate) fn compress_strip(data: &[u8]) -> io::Result<CompressedStrip> {
    let mut compressor = fdeflate::Compressor::new(Vec::with_capacity(data.len() / 2 + 64))?;
    compressor.write_data(data)?;
    Ok(CompressedStrip {
        stream: compressor.finish()?,
        input_len: data.len(),
        stored_last_header: None,
    })
}

/// Size of [`store_strip`]'s stream for `len` bytes of input: zlib header, a 5-byte
/// header per stored block of at most 65 535 bytes (one block for no input), Adler-32.
/// (`fdeflate::StoredOnlyCompressor::compressed_size` undercounts exact multiples of
/// 65 535 bytes by one block.)
pub(crate) fn stored_size(len: usize) -> usize {
    2 + len + 5 * len.div_ceil(65_535).max(1) + 4
}

/// `data` as stored (uncompressed) blocks of at most 65 535 bytes in a zlib stream, for
/// strips that deflate would enlarge (as the `png` crate falls back for whole images).
pub(crate) fn store_strip(data: &[u8]) -> io::Result<CompressedStrip> {
    let mut compressor = fdeflate::StoredOnlyCompressor::new(io::Cursor::new(Vec::with_capacity(
        stored_size(data.len()),
    )))?;
    compressor.write_data(data)?;
    let stream = compressor.finish()?.into_inner();
    // fdeflate fills blocks to 65 535 bytes in order: the last holds the rest.
    let last_len = if data.is_empty() {
        0
    } else {
        (data.len() - 1) % 65_535 + 1
    };
    Ok(CompressedStrip {
        stored_last_header: stream.len().checked_sub(4 + 5 + last_len),
        stream,
        input_len: data.len(),
    })
}

/// The strips' streams joined into one zlib stream, as consecutive pieces (write them in
/// order, e.g. one IDAT chunk each); `None` if a stream does not have the expected form.
pub(crate) fn join(strips: Vec<CompressedStrip>) -> Option<Vec<Vec<u8>>> {
    let count = strips.len();
    let mut adler = 1u32; // Adler-32 of nothing
    let mut pieces = Vec::with_capacity(count);
    for (i, strip) in strips.into_iter().enumerate() {
        let mut s = strip.stream;
        // zlib header (CM = 8, no dictionary), at least one byte of block, Adler-32.
        if s.len() < 7 || s[0] != 0x78 || s[1] != 0x01 {
            return None;
        }
        let tail = s.len() - 4;
        let strip_adler = u32::from_be_bytes(s[tail..].try_into().ok()?);
        adler = adler32_combine(adler, strip_adler, strip.input_len);
        s.truncate(tail);
        let last_strip = i + 1 == count;
        if let Some(h) = strip.stored_last_header {
            // Stored blocks end on a byte boundary: only the final flag changes.
            let len = u16::from_le_bytes([*s.get(h + 1)?, *s.get(h + 2)?]);
            let nlen = u16::from_le_bytes([*s.get(h + 3)?, *s.get(h + 4)?]);
            if s[h] != 1 || nlen != !len || h + 5 + len as usize != s.len() {
                return None;
            }
            s[h] = last_strip as u8;
        } else {
            if s[2] & 1 != 1 {
                return None;
            }
            if !last_strip {
                s[2] &= !1; // BFINAL = 0
                let last = *s.last()?;
                if last == 0 {
                    return None; // the end-of-block code's last bit must be a 1
                }
                if last.leading_zeros() < 3 {
                    s.push(0); // the stored block's header spills into one more byte
                }
                s.extend_from_slice(&[0x00, 0x00, 0xff, 0xff]);
            }
        }
        if last_strip {
            s.extend_from_slice(&adler.to_be_bytes());
        }
        if i > 0 {
            s.drain(..2);
        }
        pieces.push(s);
    }
    Some(pieces)
}

/// Whether [`join`] yields a valid stream with this build's fdeflate (checked once: a
/// probe of 24 strips of 1–24 pseudo-random bytes, inflated and compared).
pub(crate) fn joining_works() -> bool {
    static WORKS: OnceLock<bool> = OnceLock::new();
    *WORKS.get_or_init(|| {
        let mut state = 0x9e37_79b9u32;
        let strips: Vec<Vec<u8>> = (1..=24)
            .map(|n| {
                (0..n)
                    .map(|_| {
                        state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                        // Mostly small values and zeros, like filtered image bytes.
                        let v = (state >> 24) as u8;
                        if v < 96 {
                            0
                        } else {
                            v
                        }
                    })
                    .collect()
            })
            .collect();
        let Ok(compressed) = strips
            .iter()
            .map(|s| compress_strip(s))
            .collect::<io::Result<Vec<_>>>()
        else {
            return false;
        };
        let Some(pieces) = join(compressed) else {
            return false;
        };
        fdeflate::decompress_to_vec(&pieces.concat()).is_ok_and(|d| d == strips.concat())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adler32(data: &[u8]) -> u32 {
        let (mut a, mut b) = (1u64, 0u64);
        for &x in data {
            a = (a + x as u64) % ADLER_BASE;
            b = (b + a) % ADLER_BASE;
        }
        ((b << 16) | a) as u32
    }

    fn bytes(n: usize, seed: u32) -> Vec<u8> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s.wrapping_mul(1_103_515_245).wrapping_add(12_345);
                (s >> 23) as u8
            })
            .collect()
    }

    #[test]
    fn adler_combine_equals_adler_of_the_concatenation() {
        for (la, lb) in [
            (0, 0),
            (0, 5),
            (5, 0),
            (1, 1),
            (100, 70_000),
            (200_000, 65_521),
        ] {
            let (a, b) = (bytes(la, 1), bytes(lb, 2));
            let whole = [a.clone(), b.clone()].concat();
            assert_eq!(
                adler32_combine(adler32(&a), adler32(&b), b.len()),
                adler32(&whole),
                "{la} + {lb}"
            );
        }
        // All 0xff: the sums reach their largest residues.
        let (a, b) = (vec![0xffu8; 5552], vec![0xffu8; 100_000]);
        assert_eq!(
            adler32_combine(adler32(&a), adler32(&b), b.len()),
            adler32(&[a, b].concat())
        );
    }

    #[test]
    fn joined_strips_inflate_to_the_concatenated_input() {
        assert!(joining_works());
        // Strips of every length 1..=64 (every padding length several times), including
        // long zero runs and incompressible bytes.
        let strips: Vec<Vec<u8>> = (1..=64)
            .map(|n| {
                let mut v = bytes(n * 37 % 301 + 1, n as u32);
                if n % 3 == 0 {
                    v.iter_mut().take(n * 5).for_each(|x| *x = 0);
                }
                v
            })
            .collect();
        // Every fifth strip stored, as incompressible strips are.
        let compressed = strips
            .iter()
            .enumerate()
            .map(|(k, s)| {
                if k % 5 == 4 {
                    store_strip(s).unwrap()
                } else {
                    compress_strip(s).unwrap()
                }
            })
            .collect();
        let joined = join(compressed).unwrap().concat();
        let whole = strips.concat();
        assert_eq!(fdeflate::decompress_to_vec(&joined).unwrap(), whole);
        // An independent inflater (miniz_oxide, zlib's algorithm) agrees, Adler-32 included.
        assert_eq!(
            miniz_oxide::inflate::decompress_to_vec_zlib(&joined).unwrap(),
            whole
        );
        // The trailer is the Adler-32 of everything (decompress_to_vec checks it too).
        assert_eq!(
            u32::from_be_bytes(joined[joined.len() - 4..].try_into().unwrap()),
            adler32(&whole)
        );
        // Stored strips longer than one stored block, last strip stored too.
        let long: Vec<Vec<u8>> = [65_535, 65_536, 200_000, 1]
            .map(|n| bytes(n, n as u32))
            .to_vec();
        let joined = join(long.iter().map(|s| store_strip(s).unwrap()).collect())
            .unwrap()
            .concat();
        assert_eq!(
            joined.len(),
            2 + long.iter().map(|s| stored_size(s.len()) - 6).sum::<usize>() + 4
        );
        for (s, blocks) in long.iter().zip([1, 2, 4, 1]) {
            assert_eq!(stored_size(s.len()), s.len() + 5 * blocks + 6);
            assert_eq!(store_strip(s).unwrap().len(), stored_size(s.len()));
        }
        assert_eq!(
            miniz_oxide::inflate::decompress_to_vec_zlib(&joined).unwrap(),
            long.concat()
        );
        // A single strip is left a plain fdeflate stream.
        let one = join(vec![compress_strip(&whole).unwrap()])
            .unwrap()
            .concat();
        assert_eq!(one, fdeflate::compress_to_vec(&whole));
    }
}
