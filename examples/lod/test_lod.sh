#!/bin/sh
# examples/lod end to end, as a renderer outside csfcal would use csflut: install the build into a
# scratch DESTDIR, build the example with its own Makefile through pkg-config only, run it headless
# (EGL surfaceless, llvmpipe) on the bundled example table, then check what it claims:
#   - the simplification removes many triangles, and more than culling alone;
#   - "imperceptible" renders (distance factor 1) differ from the full one by less than one
#     threshold in the CSF-weighted band-contrast measure (imgdiff.h), and by less than the
#     deliberately perceptible ones (distance factor 8, threshold factor 16), which are well above threshold;
#   - every image is a valid PNG of the requested size, and conditions.csv names only files that exist;
#   - bad options exit 2 and a missing table exits 1, each naming the problem.
# usage: test_lod.sh BUILD_DIR SOURCE_DIR [MESON_BUILT_LOD]
set -eu
BUILD=$1
SRC=$2
T=$(mktemp -d /tmp/lod-test-XXXXXX)
trap 'rm -rf "$T"' EXIT
trap 'exit 1' INT TERM   # so that EXIT runs on a timeout too
meson install -C "$BUILD" --no-rebuild --destdir "$T/root" >"$T/install.log" 2>&1 || { cat "$T/install.log"; exit 1; }
PC=$(find "$T/root" -name csflut.pc | head -1)
[ -n "$PC" ] || { echo "FAIL: no csflut.pc installed"; exit 1; }
PREFIX=$(sed -n 's/^prefix=//p' "$PC")
CSFLUT_PC="env PKG_CONFIG_PATH=$(dirname "$PC") pkg-config --define-variable=prefix=$T/root$PREFIX"
LIBDIR=$($CSFLUT_PC --variable=libdir csflut)
# a sanitizer build of csfcal installs an instrumented library, which needs the runtime in the program
SAN=
if nm -D "$LIBDIR/libcsflut.so" 2>/dev/null | grep -q __asan_init; then SAN="-fsanitize=address,undefined"; fi
make -s -C "$SRC/examples/lod" BUILDDIR="$T" CSFLUT_PKG_CONFIG="$CSFLUT_PC" CFLAGS="-O2 $SAN" >"$T/make.log" 2>&1 ||
    { cat "$T/make.log"; echo "FAIL: the example does not build through pkg-config"; exit 1; }
LD_LIBRARY_PATH="$LIBDIR" ldd "$T/lod" | grep -q "$LIBDIR/libcsflut.so" || { echo "FAIL: not linked to the installed csflut"; exit 1; }
export LD_LIBRARY_PATH="$LIBDIR"

TABLE="$SRC/docs/examples/example_default_observer.csflut"
START=$(date +%s)
"$T/lod" --table "$TABLE" --out "$T/out" --size 256x192 --ppd 16 --object-deg 8 --views 2 \
    --distance-factors 1,8 --threshold-factors 16 >"$T/run.log" 2>&1 || { cat "$T/run.log"; echo "FAIL: lod failed"; exit 1; }
echo "lod ran in $(( $(date +%s) - START )) s"
cat "$T/run.log"

python3 - "$T/out" 256 192 <<'PY'
import csv, os, struct, sys, zlib
out, w, h = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
fail = []

def check_png(path):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n':
        return 'not a PNG signature'
    pos, idat, ihdr, end = 8, b'', None, False
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body, crc = data[pos + 8:pos + 8 + n], data[pos + 8 + n:pos + 12 + n]
        if len(crc) != 4 or struct.unpack('>I', crc)[0] != zlib.crc32(kind + body):
            return 'bad CRC in chunk %r' % kind
        if kind == b'IHDR': ihdr = struct.unpack('>IIBBBBB', body)
        if kind == b'IDAT': idat += body
        if kind == b'IEND': end = True
        pos += 12 + n
    if not ihdr or not end: return 'missing IHDR or IEND'
    if ihdr[:4] != (w, h, 8, 2): return 'IHDR %r, expected %dx%d 8-bit RGB' % (ihdr[:4], w, h)
    raw = zlib.decompress(idat)
    if len(raw) != h * (1 + 3 * w): return 'image data %d bytes, expected %d' % (len(raw), h * (1 + 3 * w))
    return None

rows = list(csv.DictReader(open(os.path.join(out, 'lod_summary.csv'))))
names = [r['image'] for r in rows]
expect = ['view%d_%s.png' % (v, k) for v in range(2) for k in ('full', 'd1', 'd8', 'k16')]
if sorted(names) != sorted(expect): fail.append('images %s, expected %s' % (names, expect))
for n in names:
    err = check_png(os.path.join(out, n))
    if err: fail.append('%s: %s' % (n, err))
for r in csv.DictReader(open(os.path.join(out, 'conditions.csv'))):
    for k in ('image_a', 'image_b'):
        if not os.path.exists(os.path.join(out, r[k])): fail.append('conditions.csv: %s %s missing' % (r['label'], r[k]))
by = {(int(r['view']), r['image'].split('_')[1][:-4]): r for r in rows}
full = sum(int(by[(v, 'd1')]['triangles_full']) for v in range(2))
d1 = sum(int(by[(v, 'd1')]['triangles']) for v in range(2))
cull = sum(int(by[(v, 'd1')]['triangles_cull_only']) for v in range(2))
print('triangles: full %d, culling alone %d, imperceptible %d (%.0f %% of full, %.0f %% of culled)' %
      (full, cull, d1, 100.0 * d1 / full, 100.0 * d1 / cull))
if d1 > 0.75 * full: fail.append('imperceptible simplification keeps %d of %d triangles (limit 75 %%)' % (d1, full))
if d1 > 0.9 * cull: fail.append('the perceptual criterion removes little beyond culling: %d of %d' % (d1, cull))
for v in range(2):
    imp = by[(v, 'd1')]
    vis = float(imp['peak_visibility'])
    if vis >= 1: fail.append('view %d: imperceptible render is %.3g thresholds from the full one' % (v, vis))
    for k in ('d8', 'k16'):
        per = by[(v, k)]
        pv = float(per['peak_visibility'])
        print('view %d: peak visibility d1 %.3g, %s %.3g; rms contrast d1 %.3g, %s %.3g' %
              (v, vis, k, pv, float(imp['rms_contrast']), k, float(per['rms_contrast'])))
        if not (pv > 2 and pv > vis and float(per['rms_contrast']) > float(imp['rms_contrast'])):
            fail.append('view %d: %s is not clearly more visible than d1' % (v, k))
        if int(per['triangles']) >= int(imp['triangles']):
            fail.append('view %d: %s keeps as many triangles as d1' % (v, k))
for f in fail: print('FAIL:', f)
sys.exit(1 if fail else 0)
PY

# bad input: exit 2 for options (naming the limit), 1 for a table that cannot be read
set +e
"$T/lod" --table "$TABLE" --out "$T/bad" --size 8x8 2>"$T/err"; RC=$?
set -e
[ $RC -eq 2 ] && grep -q "16 to 4096" "$T/err" || { cat "$T/err"; echo "FAIL: --size 8x8 gave $RC"; exit 1; }
set +e
"$T/lod" --table "$T/missing.csflut" --out "$T/bad" 2>"$T/err"; RC=$?
set -e
[ $RC -eq 1 ] && grep -q "missing.csflut" "$T/err" || { cat "$T/err"; echo "FAIL: a missing table gave $RC"; exit 1; }
if [ $# -ge 3 ]; then "$3" --help >/dev/null || { echo "FAIL: the meson-built lod does not run"; exit 1; }; fi
echo ok
