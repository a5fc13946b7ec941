#!/usr/bin/env python3
"""Reads an X window dump (xwd -root, 24/32-bit TrueColor) with the standard library only, and
either writes it as a PNG (`png IN.xwd OUT.png`) or checks the display calibration's placement
screen in it (`placement IN.xwd`): a bright square patch at the screen centre, a dark target mark
at the patch centre, dark text (the instructions) in the grey surround's top left. Exit 0 when
the check passes, 1 with the reason."""
import struct
import sys
import zlib


def read_xwd(path):
    data = open(path, "rb").read()
    f = struct.unpack(">25I", data[:100])
    header_size, version = f[0], f[1]
    if version != 7:
        raise ValueError("not an XWD version 7 file")
    width, height, byte_order = f[4], f[5], f[7]
    bpp, bpl, ncolors = f[11], f[12], f[19]
    rmask, gmask, bmask = f[14], f[15], f[16]
    if bpp not in (24, 32):
        raise ValueError("only 24/32-bit dumps are read (this is %d-bit)" % bpp)
    off = header_size + 12 * ncolors
    step = bpp // 8
    order = "<" if byte_order == 0 else ">"
    shifts = [(m & -m).bit_length() - 1 for m in (rmask, gmask, bmask)]
    rows = []
    for y in range(height):
        row = bytearray()
        base = off + y * bpl
        for x in range(width):
            b = data[base + x * step: base + x * step + step]
            v = struct.unpack(order + "I", b if step == 4 else b + b"\0")[0]
            row += bytes(((v >> shifts[0]) & 255, (v >> shifts[1]) & 255, (v >> shifts[2]) & 255))
        rows.append(bytes(row))
    return width, height, rows


def write_png(path, width, height, rows):
    raw = b"".join(b"\0" + r for r in rows)

    def chunk(tag, body):
        return struct.pack(">I", len(body)) + tag + body + struct.pack(">I", zlib.crc32(tag + body) & 0xFFFFFFFF)

    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    open(path, "wb").write(png)


def grey(rows, x, y):
    r = rows[y]
    return (r[3 * x] + r[3 * x + 1] + r[3 * x + 2]) / 3


def check_placement(width, height, rows):
    cx, cy = width // 2, height // 2
    # the patch: bright pixels around the centre (off the mark's lines), extending to a square edge
    probe = grey(rows, cx + width // 40 + 3, cy + height // 40 + 3)
    if probe < 230:
        return "no bright patch at the centre (level %.0f)" % probe
    right = cx + width // 40 + 3
    while right < width - 1 and grey(rows, right + 1, cy + height // 40 + 3) > 220:
        right += 1
    half = right - cx
    if not (8 < half < width // 2 - 2):
        return "no patch edge found right of the centre (half width %d px)" % half
    surround = grey(rows, min(width - 1, right + 8), cy + height // 40 + 3)
    if not (40 < surround < 200):
        return "the surround is not mid-grey (level %.0f)" % surround
    # the mark: dark pixels on the patch's horizontal and vertical centre lines
    dark_h = sum(1 for x in range(cx - half // 2, cx + half // 2) if grey(rows, x, cy) < 110 or grey(rows, x, cy - 1) < 110)
    dark_v = sum(1 for y in range(cy - half // 2, cy + half // 2) if grey(rows, cx, y) < 110 or grey(rows, cx - 1, y) < 110)
    if dark_h < half // 2 or dark_v < half // 2:
        return "no target mark at the patch centre (%d, %d dark pixels on its lines)" % (dark_h, dark_v)
    # the instructions: dark text pixels in the top-left corner of the surround
    text = sum(1 for y in range(0, height // 6) for x in range(0, width // 2) if grey(rows, x, y) < 110)
    if text < 50:
        return "no instructions in the top left (%d dark pixels)" % text
    print("placement screen: patch %d px across, mark %d/%d px, text %d px, surround %.0f" %
          (2 * half, dark_h, dark_v, text, surround))
    return None


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: xwd_tool.py png IN.xwd OUT.png | placement IN.xwd")
    width, height, rows = read_xwd(sys.argv[2])
    if sys.argv[1] == "png":
        write_png(sys.argv[3], width, height, rows)
        return 0
    why = check_placement(width, height, rows)
    if why:
        print("placement screen check failed: " + why)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
