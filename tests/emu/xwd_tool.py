#!/usr/bin/env python3
"""Reads an X window dump (xwd -root, 24/32-bit TrueColor) with the standard library only, and
writes it as a PNG or checks what a csfcal screen shows in it:
  png IN.xwd OUT.png          the dump as a PNG
  placement IN.xwd            the display calibration's placement screen: a bright square patch at
                              the screen centre, a dark target mark at the patch centre, dark text
                              (the instructions) in the grey surround's top left
  caption IN.xwd              a caption line (dark text) in the top rows (stimulus show)
  captiondiff A.xwd B.xwd N   the caption's text differs between A and B over at least N columns
                              (first to last column where the text pixels differ)
  text IN.xwd                 a text screen: dark text on a uniform field (an observer session's
                              instructions, break and pause screens)
  differ A.xwd B.xwd          A and B show different text (more than dithering changes)
  rings IN.xwd WMM HMM DMM ECC RADIUS POLARS [CONTROLS]
                              place rings (observer sessions' four-place trials): a ring darker
                              than the field, RADIUS deg around each place at ECC deg and each polar
                              angle of POLARS (comma separated), on a screen WMM x HMM mm seen
                              from DMM mm (eye on the normal through the centre); none at the
                              polar angles of CONTROLS
Exit 0 when the check passes, 1 with the reason."""
import math
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
    if all(sh % 8 == 0 for sh in shifts) and all((m >> sh) == 255 for m, sh in zip((rmask, gmask, bmask), shifts)):
        # byte-aligned channels (what Xvfb's TrueColor gives): sliced out of each row at once
        at = [sh // 8 if byte_order == 0 else step - 1 - sh // 8 for sh in shifts]
        rows = []
        for y in range(height):
            base, row = off + y * bpl, bytearray(3 * width)
            for c in range(3):
                row[c::3] = data[base + at[c]: base + width * step: step]
            rows.append(bytes(row))
        return width, height, rows
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


def median_level(rows, width, y0, y1):
    """The field's grey level: the median over rows y0..y1 (text covers far less than half)."""
    levels = sorted(grey(rows, x, y) for y in range(y0, y1) for x in range(0, width, 3))
    return levels[len(levels) // 2]


def caption_ink(width, height, rows):
    """The caption band (the top rows: the caption's font is 1/45 of the height, at least 8 px, its
    baseline at 1.2 font sizes): per column, the ink, summed darkness below the field's level
    (antialiased text is dark by degrees); and the number of text pixels, more than 8 levels
    below the field (its dither steps one level)."""
    band = max(20, height // 15)
    field = median_level(rows, width, 0, band)
    ink = [sum(max(0.0, field - 3 - grey(rows, x, y)) for y in range(band)) for x in range(width)]
    text = sum(1 for y in range(band) for x in range(width) if grey(rows, x, y) < field - 8)
    return ink, text, field


def check_caption(width, height, rows):
    _, text, field = caption_ink(width, height, rows)
    if text < 100:
        return "no caption text in the top rows (%d text pixels on a field of level %.0f)" % (text, field)
    print("caption: %d text pixels on a field of level %.0f" % (text, field))
    return None


def check_caption_diff(a, b, min_span):
    """The columns whose ink differs by more than dithering moves it (a level or so on each of a
    column's dozen text pixels) between two screenshots: the first to the last such column must
    span at least min_span. An unchanged line differs nowhere; text added at its far end differs
    only there."""
    if a[:2] != b[:2]:
        return "the screenshots differ in size"
    ia, _, _ = caption_ink(*a)
    ib, _, _ = caption_ink(*b)
    cols = [x for x in range(a[0]) if abs(ia[x] - ib[x]) > 40]
    span = cols[-1] - cols[0] + 1 if cols else 0
    if span < min_span:
        where = " (columns %d to %d)" % (cols[0], cols[-1]) if cols else ""
        return "the caption's text differs over %d columns%s, fewer than %d" % (span, where, min_span)
    print("caption: text differs over %d columns (%d to %d)" % (span, cols[0], cols[-1]))
    return None


def text_pixels(width, height, rows):
    """Pixels more than 8 levels darker than the field (its dither steps one level)."""
    field = median_level(rows, width, 0, height)
    return [(x, y) for y in range(height) for x in range(width) if grey(rows, x, y) < field - 8], field


def check_text(width, height, rows):
    """Text has a dark core (below 0.6 of the field's level); the place rings (0.7 of the mean
    luminance, about 0.85 of its level) and the dither do not reach it, and a blank or trial frame
    holds only the fixation mark (0.12 deg radius: a few pixels)."""
    field = median_level(rows, width, 0, height)
    ink = [(x, y) for y in range(height) for x in range(width) if grey(rows, x, y) < 0.6 * field]
    if len(ink) < 150:
        return "no text: %d dark pixels on a field of level %.0f" % (len(ink), field)
    xs = sorted(x for x, _ in ink)
    print("text: %d dark pixels, columns %d to %d, field level %.0f" % (len(ink), xs[0], xs[-1], field))
    return None


def check_differ(a, b):
    if a[:2] != b[:2]:
        return "the screenshots differ in size"
    da, _ = text_pixels(*a)
    db, _ = text_pixels(*b)
    changed = len(set(da) ^ set(db))
    if changed < 100:
        return "the two screens show the same text (%d text pixels differ)" % changed
    print("differ: %d text pixels differ" % changed)
    return None


def ring_contrast(shot, geom, polar_deg):
    """Mean level just inside and outside the ring (0.4 to 1 deg off it) minus the mean level on
    the ring (within 0.05 deg of its radius), for the place at geom's eccentricity and polar_deg.
    Distances are angles between the eye's rays to a pixel and to the place (exact, flat screen)."""
    width, height, rows = shot
    wmm, hmm, dmm, ecc, radius = geom
    e, p = math.radians(ecc), math.radians(polar_deg)
    place = (math.sin(e) * math.cos(p), math.sin(e) * math.sin(p), math.cos(e))
    cx = width / 2 + dmm * math.tan(e) * math.cos(p) * width / wmm
    cy = height / 2 - dmm * math.tan(e) * math.sin(p) * height / hmm
    half = int(dmm * (math.tan(e + math.radians(radius + 1.5)) - math.tan(e)) * width / wmm) + 2
    on, off = [], []
    for y in range(max(0, int(cy) - half), min(height, int(cy) + half)):
        for x in range(max(0, int(cx) - half), min(width, int(cx) + half)):
            xm, ym = ((x + 0.5) / width - 0.5) * wmm, (0.5 - (y + 0.5) / height) * hmm
            n = math.sqrt(xm * xm + ym * ym + dmm * dmm)
            cosd = (xm * place[0] + ym * place[1] + dmm * place[2]) / n
            d = math.degrees(math.acos(max(-1.0, min(1.0, cosd)))) - radius
            if abs(d) < 0.05:
                on.append(grey(rows, x, y))
            elif 0.4 < abs(d) < 1.0:
                off.append(grey(rows, x, y))
    if not on or not off:
        return 0.0
    return sum(off) / len(off) - sum(on) / len(on)


def check_rings(shot, geom, polars, controls):
    # the ring is 0.7 of the mean luminance: about 0.85 of its drive level, some 25 levels at mid-grey
    got = [ring_contrast(shot, geom, p) for p in polars]
    ctl = [ring_contrast(shot, geom, p) for p in controls]
    if min(got) < 10:
        return "no ring at every place: %s levels darker than around them" % ", ".join("%.1f" % g for g in got)
    if ctl and max(ctl) > 3:
        return "a ring where no place is: %s levels" % ", ".join("%.1f" % g for g in ctl)
    print("rings: %s levels darker than around them; %s where no place is" %
          (", ".join("%.1f" % g for g in got), ", ".join("%.1f" % g for g in ctl)))
    return None


def angles(arg):
    return [float(v) for v in arg.split(",") if v]


def main():
    if len(sys.argv) < 3:
        sys.exit("usage: xwd_tool.py png IN.xwd OUT.png | placement IN.xwd | caption IN.xwd | "
                 "captiondiff A.xwd B.xwd MIN_COLUMNS | text IN.xwd | differ A.xwd B.xwd | "
                 "rings IN.xwd WMM HMM DMM ECC RADIUS POLARS [CONTROLS]")
    cmd = sys.argv[1]
    shot = read_xwd(sys.argv[2])
    if cmd == "png":
        write_png(sys.argv[3], *shot)
        return 0
    if cmd == "placement":
        why = check_placement(*shot)
    elif cmd == "caption":
        why = check_caption(*shot)
    elif cmd == "captiondiff":
        why = check_caption_diff(shot, read_xwd(sys.argv[3]), int(sys.argv[4]))
    elif cmd == "text":
        why = check_text(*shot)
    elif cmd == "differ":
        why = check_differ(shot, read_xwd(sys.argv[3]))
    elif cmd == "rings":
        geom = tuple(float(v) for v in sys.argv[3:8])
        why = check_rings(shot, geom, angles(sys.argv[8]), angles(sys.argv[9]) if len(sys.argv) > 9 else [])
    else:
        sys.exit("xwd_tool.py: unknown check '%s'" % cmd)
    if why:
        print("%s check failed: %s" % (cmd, why))
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
