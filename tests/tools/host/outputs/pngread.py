# SPDX-License-Identifier: MIT
"""pngread.py - a small PNG reader (zlib from Python's standard library) for the
report tests: 8-bit greyscale/RGB/RGBA, non-interlaced, which is what headless
Chromium writes. Returns the pixels as rows of bytes."""
import struct
import zlib


def _add_bytes(a, b, n):
    """Bytewise (a + b) mod 256 of two n-byte strings, without a Python loop."""
    lo = int.from_bytes(b'\x7f' * n, 'big')
    hi = int.from_bytes(b'\x80' * n, 'big')
    x = int.from_bytes(a, 'big')
    y = int.from_bytes(b, 'big')
    return (((x & lo) + (y & lo)) ^ ((x ^ y) & hi)).to_bytes(n, 'big')


def read(path):
    """(width, height, bytes per pixel, [row bytes]) of a PNG file."""
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        raise ValueError('%s: not a PNG file' % path)
    pos, idat, hdr = 8, [], None
    while pos < len(data):
        n, = struct.unpack('>I', data[pos:pos + 4])
        kind, body = data[pos + 4:pos + 8], data[pos + 8:pos + 8 + n]
        pos += 12 + n
        if kind == b'IHDR':
            hdr = struct.unpack('>IIBBBBB', body)
        elif kind == b'IDAT':
            idat.append(body)
        elif kind == b'IEND':
            break
    if hdr is None:
        raise ValueError('%s: no IHDR' % path)
    w, h, depth, ctype, _, _, interlace = hdr
    bpp = {0: 1, 2: 3, 4: 2, 6: 4}.get(ctype)
    if depth != 8 or bpp is None or interlace:
        raise ValueError('%s: unsupported PNG (depth %d, colour type %d, interlace %d)' % (path, depth, ctype,
                                                                                          interlace))
    raw = zlib.decompress(b''.join(idat))
    stride = w * bpp
    if len(raw) != h * (stride + 1):
        raise ValueError('%s: %d bytes of image data, expected %d' % (path, len(raw), h * (stride + 1)))
    rows, prev = [], bytes(stride)
    for y in range(h):
        f = raw[y * (stride + 1)]
        line = raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)]
        if f == 0:
            out = bytes(line)
        elif f == 2:
            out = _add_bytes(line, prev, stride)
        else:
            cur = bytearray(line)
            for x in range(stride):
                a = cur[x - bpp] if x >= bpp else 0
                if f == 1:
                    cur[x] = (cur[x] + a) & 255
                elif f == 3:
                    cur[x] = (cur[x] + ((a + prev[x]) >> 1)) & 255
                elif f == 4:
                    b = prev[x]
                    c = prev[x - bpp] if x >= bpp else 0
                    p = a + b - c
                    pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                    cur[x] = (cur[x] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
                else:
                    raise ValueError('%s: bad filter %d in row %d' % (path, f, y))
            out = bytes(cur)
        rows.append(out)
        prev = out
    return w, h, bpp, rows


def count_non_white(img, x0=0, y0=0, x1=None, y1=None, level=245):
    """Pixels in [x0, x1) x [y0, y1) with any colour channel below `level`."""
    w, h, bpp, rows = img
    x1 = w if x1 is None else min(x1, w)
    y1 = h if y1 is None else min(y1, h)
    n = 0
    ch = min(bpp, 3)
    for y in range(max(y0, 0), y1):
        r = rows[y]
        for x in range(max(x0, 0), x1):
            p = r[x * bpp:x * bpp + ch]
            if min(p) < level:
                n += 1
    return n


def count_colour(img, rgb, tol=8):
    """Pixels within `tol` of the colour rgb = (r, g, b)."""
    w, h, bpp, rows = img
    n = 0
    for r in rows:
        for x in range(0, w * bpp, bpp):
            if abs(r[x] - rgb[0]) <= tol and abs(r[x + 1] - rgb[1]) <= tol and abs(r[x + 2] - rgb[2]) <= tol:
                n += 1
    return n
