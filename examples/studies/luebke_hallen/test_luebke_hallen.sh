#!/bin/bash
# Luebke & Hallen sec. 6.2 end to end (examples/studies/luebke_hallen/run.sh), checked from the
# report's JSON: pooled over 4 participants, identical and imperceptible pairs are not told apart
# better than chance (exact binomial p >= 0.01), the deliberately perceptible ones far better
# (p < 1e-6, proportion correct >= 0.8).   usage: test_luebke_hallen.sh CSFCAL LOD
set -eu
T=$(mktemp -d /tmp/csfcal-lh-XXXXXX)
trap 'rm -rf "$T"' EXIT
trap 'exit 1' INT TERM
"$(dirname "$0")/run.sh" "$1" "$2" "$T" 4 || { echo "FAIL: run.sh"; cat "$T/lod.log" 2>/dev/null; exit 1; }
python3 - "$T/report.json" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
fail = []
groups = {g['group']: g for g in r['groups'] if g['scope'] == 'pooled'}
for name in ('identical', 'imperceptible', 'd8', 'k16'):
    if name not in groups: fail.append('no pooled group %s' % name)
for name, g in sorted(groups.items()):
    print('%-13s n %3d  correct %.3f  hit %.3f  false alarm %.3f  p(above chance) %.3g' %
          (name, g['n'], g['p_correct'], g['hit_rate'], g['fa_rate'], g['p_value_above_chance']))
    if name in ('identical', 'imperceptible') and g['p_value_above_chance'] < 0.01:
        fail.append('%s pairs told apart above chance (p %.3g)' % (name, g['p_value_above_chance']))
    if name in ('d8', 'k16') and not (g['p_value_above_chance'] < 1e-6 and g['p_correct'] >= 0.8):
        fail.append('%s pairs not told apart well above chance (correct %.3f, p %.3g)' % (name, g['p_correct'], g['p_value_above_chance']))
if r['sessions_finished'] != 4 or r['trials_scored'] != 4 * 192:
    fail.append('sessions finished %s, trials %s (expected 4, 768)' % (r['sessions_finished'], r['trials_scored']))
for f in fail: print('FAIL:', f)
sys.exit(1 if fail else 0)
PY
