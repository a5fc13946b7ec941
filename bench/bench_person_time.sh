#!/bin/bash
# The person's time a session takes: N simulated people (slope and lapse drawn from the seed) on the
# default 6 x 4 grid, with --precision P (default 0.10) or a fixed budget (--trials T). Prints one
# line per session and the median and 90th percentile of person time (min) and trials, and the
# median predicted RMS error. Person time is the session's own clock: frames shown plus the
# simulated person's answer times (csf_obs_result.person_s).
#   bench/bench_person_time.sh CSFCAL [N] [extra observer-calibrate options...]
set -u
CSFCAL=$(realpath "$1"); N=${2:-20}; shift 2 2>/dev/null || shift $#
T=$(mktemp -d /tmp/csfcal-ptime-XXXXXX)
trap 'rm -rf "$T"' EXIT
opts=("$@"); [ ${#opts[@]} -eq 0 ] && opts=(--precision 0.10)
for i in $(seq 1 "$N"); do
    "$CSFCAL" observer calibrate --headless --observer "sim:slope=draw,lapse=draw" --seed "$((100 + i))" \
        --store "$T/s$i.sqlite" --out "$T/t$i.csflut" --json "${opts[@]}" 2>/dev/null
done | python3 -c '
import json, sys, statistics
rows = [json.loads(l) for l in sys.stdin if l.startswith("{")]
ok = [r for r in rows if r.get("status") == "ok"]
for r in ok:
    print("seed session %3d: %4d trials, person time %5.2f min, predicted RMS %.3f" % (r["session"], r["trials"], r["person_s"] / 60, r["predicted_rms_log10"]))
def q(v, p):
    v = sorted(v); return v[min(len(v) - 1, int(round(p * (len(v) - 1))))]
pt = [r["person_s"] / 60 for r in ok]; tr = [r["trials"] for r in ok]
print("%d of %d sessions ok; person time median %.2f min, 90th percentile %.2f min; trials median %d, 90th %d; predicted RMS median %.3f"
      % (len(ok), len(rows), statistics.median(pt), q(pt, 0.9), statistics.median(tr), q(tr, 0.9),
         statistics.median(r["predicted_rms_log10"] for r in ok)))
'
