#!/usr/bin/env python3
"""Decodes PNG files independently of Rust (Python's zlib, i.e. the C zlib; and Pillow
when installed) and checks that pairs of files hold the same samples.

usage: python3 tools/bench-post/check_png.py A.png B.png [A2.png B2.png ...]

For each pair: parses the chunks (CRC-32 of every chunk checked), inflates the
concatenated IDAT data with zlib (which checks the Adler-32), undoes the per-row filters
(PNG §9: None, Sub, Up, Average, Paeth) and compares the raw samples; with Pillow, also
opens both files (Pillow decodes 16-bit RGB to 8 bits, so that compares its own
reduction of both). Written to check the parallel PNG writer (crates/post/src/io/png.rs)
against the png crate's sequential encoder on the files the tests write.
"""
import struct
import sys
import zlib


def chunks(data):
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG signature"
    pos = 8
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos:pos + 4])
        kind = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:pos + 12 + length])
        assert zlib.crc32(kind + body) == crc, f"CRC mismatch in {kind}"
        yield kind, body
        pos += 12 + length


def samples(path):
    data = open(path, "rb").read()
    idat = b""
    names = []
    for kind, body in chunks(data):
        names.append(kind.decode())
        if kind == b"IHDR":
            w, h, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            assert colour == 2 and interlace == 0, "expects non-interlaced RGB"
        elif kind == b"IDAT":
            idat += body
    raw = zlib.decompress(idat)  # checks the Adler-32
    bpp = 3 * depth // 8
    stride = w * bpp
    assert len(raw) == h * (stride + 1), "wrong amount of image data"
    out = bytearray()
    prev = bytearray(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if f == 1:
                line[i] = (line[i] + a) & 255
            elif f == 2:
                line[i] = (line[i] + b) & 255
            elif f == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[i] = (line[i] + pred) & 255
            else:
                assert f == 0, f"filter type {f}"
        out += line
        prev = line
    colour_chunks = [n for n in names if n in ("sRGB", "cHRM", "gAMA")]
    return (w, h, depth), bytes(out), colour_chunks, names.count("IDAT")


def main(paths):
    ok = True
    for a, b in zip(paths[::2], paths[1::2]):
        (ia, sa, ca, na), (ib, sb, cb, nb) = samples(a), samples(b)
        same = ia == ib and sa == sb and ca == cb
        line = f"{a} ({na} IDAT) vs {b} ({nb} IDAT): {ia}, zlib samples {'equal' if same else 'DIFFER'}"
        try:
            from PIL import Image
            pa, pb = Image.open(a), Image.open(b)
            pil_same = pa.size == pb.size and pa.tobytes() == pb.tobytes()
            line += f", Pillow {'equal' if pil_same else 'DIFFER'}"
            same = same and pil_same
        except ImportError:
            line += ", Pillow not installed"
        print(line)
        ok = ok and same
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main(sys.argv[1:])
