"""Re-encodes a scanline ZIP16 EXR (as seethru writes) as NONE (0), RLE (1) or ZIPS (2), for
the `exr` target's seeds: the same samples through other decoders of the exr crate.

    python3 scripts/exr_recode.py IN.exr OUT.exr COMPRESSION

Checked by `seethru measure` on a run whose EXRs were all re-encoded: metrics.json identical.
"""
import struct, sys, zlib

def parse(data):
    assert data[:4] == b'\x76\x2f\x31\x01'
    p = 8; attrs = []
    while data[p] != 0:
        n = data.index(b'\0', p); name = data[p:n]; p = n + 1
        n = data.index(b'\0', p); typ = data[p:n]; p = n + 1
        size, = struct.unpack_from('<i', data, p); p += 4
        attrs.append([name, typ, data[p:p+size]]); p += size
    p += 1
    return attrs, p

def get(attrs, name):
    return next(a for a in attrs if a[0] == name)

def channels(value):
    out = []; p = 0
    while value[p] != 0:
        n = value.index(b'\0', p); name = value[p:n]; p = n + 1
        pt, = struct.unpack_from('<i', value, p); p += 16
        out.append((name, pt))
    return out

def undo(t):
    t = bytearray(t)
    for i in range(1, len(t)):
        t[i] = (t[i-1] + t[i] - 128) & 255
    h = (len(t) + 1) // 2
    out = bytearray(len(t))
    out[0::2] = t[:h]; out[1::2] = t[h:]
    return bytes(out)

def redo(raw):
    t = bytearray(raw[0::2] + raw[1::2])
    p = t[0] if t else 0
    for i in range(1, len(t)):
        d = t[i]; t[i] = (d - p + 384) & 255; p = d
    return bytes(t)

def rle(b):
    out = bytearray(); i = 0
    while i < len(b):
        j = i
        while j + 1 < len(b) and b[j+1] == b[i] and j - i < 126: j += 1
        if j - i >= 2:
            out += struct.pack('b', j - i) + bytes([b[i]]); i = j + 1
        else:
            k = i
            while k < len(b) and k - i < 127 and not (k + 2 < len(b) and b[k] == b[k+1] == b[k+2]): k += 1
            out += struct.pack('b', -(k - i)) + b[i:k]; i = k
    return bytes(out)

def recode(data, comp):
    attrs, p = parse(data)
    xmin, ymin, xmax, ymax = struct.unpack('<4i', get(attrs, b'dataWindow')[2])
    w, h = xmax - xmin + 1, ymax - ymin + 1
    chans = channels(get(attrs, b'channels')[2])
    line = sum(w * (2 if pt == 1 else 4) for _, pt in chans)
    assert get(attrs, b'compression')[2][0] == 3
    nblocks = (h + 15) // 16
    raw = bytearray()
    for b in range(nblocks):
        off, = struct.unpack_from('<Q', data, p + 8 * b)
        y, size = struct.unpack_from('<ii', data, off)
        chunk = data[off+8:off+8+size]
        lines = min(16, h - b * 16)
        raw += chunk if size == lines * line else undo(zlib.decompress(chunk))
    get(attrs, b'compression')[2] = bytes([comp])
    for a in attrs:
        if a[0] == b'chunkCount': a[2] = struct.pack('<i', h)
    head = bytearray(data[:8])
    for name, typ, val in attrs:
        head += name + b'\0' + typ + b'\0' + struct.pack('<i', len(val)) + val
    head += b'\0'
    chunks = []
    for y in range(h):
        r = bytes(raw[y*line:(y+1)*line])
        c = r if comp == 0 else (rle(redo(r)) if comp == 1 else zlib.compress(redo(r)))
        if len(c) >= len(r): c = r
        chunks.append(struct.pack('<ii', ymin + y, len(c)) + c)
    off = len(head) + 8 * h; table = bytearray()
    for c in chunks:
        table += struct.pack('<Q', off); off += len(c)
    return bytes(head + table + b''.join(chunks))

src, dst, comp = sys.argv[1], sys.argv[2], int(sys.argv[3])
open(dst, 'wb').write(recode(open(src, 'rb').read(), comp))
