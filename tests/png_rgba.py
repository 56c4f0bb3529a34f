"""8-bit RGBA PNG decoding in pure Python (zlib only), for the script tests
that compare rendered frames pixel by pixel: run_loop.sh (the seam of a
looping effect) and run_egl_gpu.sh (a GPU's frames against llvmpipe's).
pfx writes 8-bit RGBA, non-interlaced, with any of the five filters."""
import struct
import zlib


def read_image_data(path, depth):
    """Checks an RGBA (colour type 6), non-interlaced PNG of `depth` bits a
    sample and returns (width, height, filtered rows as one bytes object)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError(f"{path}: not a PNG")
    pos, idat, head = 8, [], None
    while pos < len(data):
        (length,) = struct.unpack(">I", data[pos : pos + 4])
        kind = data[pos + 4 : pos + 8]
        body = data[pos + 8 : pos + 8 + length]
        if kind == b"IHDR":
            head = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat.append(body)
        elif kind == b"IEND":
            break
        pos += 12 + length
    if head is None:
        raise ValueError(f"{path}: no IHDR")
    w, h, got_depth, ctype, _, _, interlace = head
    if got_depth != depth or ctype != 6 or interlace != 0:
        raise ValueError(f"{path}: expected {depth}-bit RGBA non-interlaced, got {head}")
    return w, h, zlib.decompress(b"".join(idat))


def decode(path):
    """8-bit RGBA (colour type 6), non-interlaced PNG -> (width, height, bytes)."""
    w, h, raw = read_image_data(path, 8)
    stride, bpp = 4 * w, 4
    out = bytearray(h * stride)
    prev = bytearray(stride)
    p = 0
    for y in range(h):
        ftype = raw[p]
        line = bytearray(raw[p + 1 : p + 1 + stride])
        p += 1 + stride
        if ftype == 1:
            for x in range(bpp, stride):
                line[x] = (line[x] + line[x - bpp]) & 255
        elif ftype == 2:
            for x in range(stride):
                line[x] = (line[x] + prev[x]) & 255
        elif ftype == 3:
            for x in range(stride):
                left = line[x - bpp] if x >= bpp else 0
                line[x] = (line[x] + ((left + prev[x]) >> 1)) & 255
        elif ftype == 4:
            for x in range(stride):
                a = line[x - bpp] if x >= bpp else 0
                b = prev[x]
                c = prev[x - bpp] if x >= bpp else 0
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pred) & 255
        elif ftype != 0:
            raise ValueError(f"{path}: bad filter type {ftype}")
        out[y * stride : (y + 1) * stride] = line
        prev = line
    return w, h, bytes(out)


