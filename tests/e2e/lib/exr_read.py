#!/usr/bin/env python3
"""A small reader of the EXR files obscura writes (tests/e2e/dynamic.sh),
from the OpenEXR file layout alone: one scanline part, no compression,
ZIPS or ZIP, half or float channels.  read(path) -> (width, height,
{channel: [values row by row]})."""
import struct
import zlib


def _unzip(data, size):
    if len(data) == size:  # stored when compression would not help
        return data
    t = bytearray(zlib.decompress(data))
    for i in range(1, len(t)):  # the predictor
        t[i] = (t[i - 1] + t[i] - 128) & 0xFF
    half = (len(t) + 1) // 2
    out = bytearray(len(t))
    out[0::2] = t[:half]  # the two halves interleaved
    out[1::2] = t[half:]
    return bytes(out)


def read(path):
    d = open(path, "rb").read()
    if d[:4] != b"\x76\x2f\x31\x01":
        raise ValueError("%s: not an EXR" % path)
    if struct.unpack_from("<I", d, 4)[0] & 0x1600:
        raise ValueError("%s: tiled, deep or multi-part: not read here" % path)
    at, chans, comp, win = 8, [], 0, None
    while d[at] != 0:
        name_end = d.index(b"\0", at)
        name = d[at:name_end].decode()
        type_end = d.index(b"\0", name_end + 1)
        size = struct.unpack_from("<i", d, type_end + 1)[0]
        val = d[type_end + 5:type_end + 5 + size]
        if name == "channels":
            k = 0
            while val[k] != 0:
                e = val.index(b"\0", k)
                chans.append((val[k:e].decode(), struct.unpack_from("<i", val, e + 1)[0]))
                k = e + 17
        elif name == "compression":
            comp = val[0]
        elif name == "dataWindow":
            win = struct.unpack("<4i", val)
        at = type_end + 5 + size
    at += 1
    if comp not in (0, 2, 3):
        raise ValueError("%s: compression %d not read here" % (path, comp))
    w, h = win[2] - win[0] + 1, win[3] - win[1] + 1
    lines = {0: 1, 2: 1, 3: 16}[comp]
    nblocks = (h + lines - 1) // lines
    offsets = struct.unpack_from("<%dQ" % nblocks, d, at)
    out = {c: [0.0] * (w * h) for c, _ in chans}
    for off in offsets:
        y, size = struct.unpack_from("<ii", d, off)
        y -= win[1]
        n = min(lines, h - y)
        want = n * w * sum(2 if t == 1 else 4 for _, t in chans)
        raw = d[off + 8:off + 8 + size]
        data = raw if comp == 0 else _unzip(raw, want)
        k = 0
        for r in range(n):
            for c, t in chans:
                fmt, sz = ("<%de" % w, 2) if t == 1 else ("<%df" % w, 4)
                if t == 0:
                    fmt = "<%dI" % w
                vals = struct.unpack_from(fmt, data, k)
                out[c][(y + r) * w:(y + r + 1) * w] = vals
                k += sz * w
    return w, h, out
