#!/bin/sh
# examples/lod's moving sequence (README.md, "Motion") end to end, with a 3-D table made the way a
# user would: velocity_csv writes a model observer's frequency x eccentricity x velocity grid, and
# `csfcal lut import` turns it into a .csflut. Checks:
#   - at 24 deg/s (fixation) the table at the real velocity keeps fewer triangles than the same table
#     read at velocity 0 (where the table says sensitivity drops: its finest visible detail falls),
#     and the coarser simplification (thresholds x4) fewer still;
#   - the simulated judge tells the coarser sequence from the full one far above chance, and the
#     moving simplification, the static one and identical pairs not above chance;
#   - at 0 deg/s every frame keeps the same triangles with the velocity as without;
#   - a 2-D table (no velocity axis) gives the same count moving as static, every frame;
#   - smooth pursuit (Daly 1998) leaves 0.18 v - 0.15 deg/s on the retina, fixation v;
#   - every frame is a valid PNG of the requested size; bad options exit 2 naming the limit.
# usage: test_lod_motion.sh LOD CSFCAL VELOCITY_CSV SOURCE_DIR
set -eu
LOD=$1 CSFCAL=$2 VCSV=$3 SRC=$4
T=$(mktemp -d /tmp/lod-motion-XXXXXX)
trap 'rm -rf "$T"' EXIT
trap 'exit 1' INT TERM
"$VCSV" --no-low-frequency-gain --velocities 0,1,2,4,8,12,24 >"$T/vel.csv"
"$CSFCAL" lut import "$T/vel.csv" -o "$T/vel.csflut" >"$T/import.log" 2>&1 || { cat "$T/import.log"; echo "FAIL: lut import"; exit 1; }
GEOM="--size 256x192 --ppd 32 --object-deg 4"
run() { # name, then lod's options
    name=$1; shift
    "$LOD" --out "$T/$name" --json "$T/$name.json" "$@" >"$T/$name.log" 2>&1 || { cat "$T/$name.log"; echo "FAIL: lod $name"; exit 1; }
    grep -E "^(triangles|saved|finest|judge)" "$T/$name.log" | sed "s/^/$name: /"
}
run fast --table "$T/vel.csflut" $GEOM --subdiv 6 --frames 4 --object-velocity 24
run still --table "$T/vel.csflut" $GEOM --subdiv 6 --frames 2 --object-velocity 0
run flat --table "$SRC/docs/examples/example_default_observer.csflut" --size 256x192 --ppd 16 --object-deg 8 \
    --subdiv 6 --frames 2 --object-velocity 12
run pursuit --table "$T/vel.csflut" $GEOM --subdiv 4 --frames 2 --object-velocity 12 --eye pursuit

python3 - "$T" <<'PY'
import csv, json, os, struct, sys, zlib
T = sys.argv[1]
fail = []

def check_png(path, w, h):
    data = open(path, 'rb').read()
    if data[:8] != b'\x89PNG\r\n\x1a\n': return 'not a PNG signature'
    pos, idat, ihdr, end = 8, b'', None, False
    while pos < len(data):
        n, kind = struct.unpack('>I4s', data[pos:pos + 8])
        body, crc = data[pos + 8:pos + 8 + n], data[pos + 8 + n:pos + 12 + n]
        if len(crc) != 4 or struct.unpack('>I', crc)[0] != zlib.crc32(kind + body): return 'bad CRC in %r' % kind
        if kind == b'IHDR': ihdr = struct.unpack('>IIBBBBB', body)
        if kind == b'IDAT': idat += body
        if kind == b'IEND': end = True
        pos += 12 + n
    if not ihdr or not end: return 'missing IHDR or IEND'
    if ihdr[:4] != (w, h, 8, 2): return 'IHDR %r, expected %dx%d 8-bit RGB' % (ihdr[:4], w, h)
    if len(zlib.decompress(idat)) != h * (1 + 3 * w): return 'wrong image data size'
    return None

def load(name):
    return json.load(open(os.path.join(T, name + '.json'))), list(csv.DictReader(open(os.path.join(T, name, 'motion_summary.csv'))))

fast, fast_rows = load('fast')
tri = fast['triangles']
if len(fast_rows) != 4: fail.append('fast: %d frames in motion_summary.csv, expected 4' % len(fast_rows))
for f in range(4):
    for kind in ('full', 'static', 'moving', 'coarse'):
        err = check_png(os.path.join(T, 'fast', 'frame%03d_%s.png' % (f, kind)), 256, 192)
        if err: fail.append('fast frame %d %s: %s' % (f, kind, err))
fd = fast['finest_detail_cpd_at_10pct']
if not fd['moving'] < fd['static'] / 2: fail.append('the table does not lose detail at 24 deg/s: %s' % fd)
if not tri['moving'] <= 0.9 * tri['static']:
    fail.append('moving keeps %d of the static table\'s %d triangles (limit 90 %%)' % (tri['moving'], tri['static']))
if fast['triangles_saved_vs_static'] != tri['static'] - tri['moving']: fail.append('saved figure inconsistent')
for r in fast_rows:
    if not int(r['triangles_moving']) < int(r['triangles_static']): fail.append('frame %s: moving not below static' % r['frame'])
if not tri['coarse'] < 0.8 * tri['moving']: fail.append('coarse keeps %d, moving %d: not clearly coarser' % (tri['coarse'], tri['moving']))
if not 22 < float(fast['retinal_velocity_median_dps']) < 26: fail.append('fixation: median retinal %s, expected ~24' % fast['retinal_velocity_median_dps'])
j = fast['judge']
if not (j['coarse']['p_above_chance'] < 1e-6 and j['coarse']['visibility'] > 1):
    fail.append('the coarser sequence is not told apart: %s' % j['coarse'])
for k in ('identical', 'static', 'moving'):
    if j[k]['p_above_chance'] < 0.01: fail.append('%s pairs told apart above chance: %s' % (k, j[k]))
if not j['moving']['visibility'] < 1: fail.append('moving sequence at %.3g thresholds' % j['moving']['visibility'])

still, still_rows = load('still')
for r in still_rows:
    if r['triangles_moving'] != r['triangles_static'] or float(r['retinal_max_dps']) != 0:
        fail.append('v = 0, frame %s: static %s, moving %s, retinal max %s' % (r['frame'], r['triangles_static'], r['triangles_moving'], r['retinal_max_dps']))
if not still['triangles']['static'] < still['triangles']['cull_only']: fail.append('v = 0: the static table folds nothing, the check is empty')

flat, flat_rows = load('flat')
if flat['table_has_velocity_axis']: fail.append('the bundled table claims a velocity axis')
for r in flat_rows:
    if r['triangles_moving'] != r['triangles_static']: fail.append('2-D table, frame %s: static %s, moving %s' % (r['frame'], r['triangles_static'], r['triangles_moving']))
if not flat['triangles']['static'] < flat['triangles']['cull_only']: fail.append('2-D table folds nothing, the check is empty: %s' % flat['triangles'])

pur, _ = load('pursuit')
v = float(pur['retinal_velocity_median_dps'])
print('pursuit at 12 deg/s: median retinal %.3f deg/s (Daly: %.3f)' % (v, 0.18 * 12 - 0.15))
if pur['eye'] != 'pursuit' or not abs(v - (0.18 * 12 - 0.15)) < 0.3: fail.append('pursuit: median retinal %.3g' % v)
for f in fail: print('FAIL:', f)
sys.exit(1 if fail else 0)
PY

bad() { # expected message part, then options
    want=$1; shift
    set +e
    "$LOD" --table "$T/vel.csflut" --out "$T/bad" "$@" 2>"$T/err"; rc=$?
    set -e
    [ $rc -eq 2 ] && grep -q "$want" "$T/err" || { cat "$T/err"; echo "FAIL: $* gave $rc"; exit 1; }
}
bad "from 2 to 240" --frames 1
bad "fixate or pursuit" --frames 4 --eye saccade
bad "from 1 to 1000" --frames 4 --coarse-factor 0.5
bad "from 0 to 80" --frames 4 --object-velocity 100
bad "the image is" $GEOM --frames 240 --object-velocity 60
bad "from 10 to 100000" --frames 4 --judge-trials 5
echo ok
