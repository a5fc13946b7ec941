#!/usr/bin/env bash
# Study designs from the command line (examples/studies/counterbalanced.conf, docs/studies.md
# "Designs"): the blocks' order follows each participant's Latin-square row, the row and the
# participant's index are kept with the session (resume keeps them) and reach the report and the
# export with the session metadata (--set experimenter=, notes=) and each trial's onset on the
# session's clock, refused metadata exits 2 with nothing stored, and a simulated person's reading
# of the instructions counts as person time.
#   usage: test_study_designs.sh CSFCAL EXAMPLES_DIR
set -u
csfcal=$1
ex=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
no() { echo "FAIL: $*"; fail=1; }
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
run() { "$csfcal" study run "$@" --observer sim --headless --quiet; }
st="$tmp/s.sqlite"

run "$ex/counterbalanced.conf" --participant P01 --store "$st" --set experimenter=AB \
  --set 'notes=pilot, room 2' >/dev/null || no "P01 run failed"
CSFCAL_TEST_KILL_AFTER=30 run "$ex/counterbalanced.conf" --participant P02 --store "$st" >/dev/null 2>&1
out=$(run "$ex/counterbalanced.conf" --participant P02 --store "$st" --set notes=other 2>&1); rc=$?
[ $rc -eq 2 ] || no "resume with other metadata: exit $rc ($out)"
case "$out" in *"--set notes: session 2 began without notes"*) ;; *) no "metadata on resume: $out";; esac
run "$ex/counterbalanced.conf" --participant P02 --store "$st" >/dev/null || no "P02 resume failed"
run "$ex/counterbalanced.conf" --participant P03 --store "$st" >/dev/null || no "P03 run failed"
"$csfcal" study export "$ex/counterbalanced.conf" --store "$st" -o "$tmp/x.csv" 2>/dev/null || no "export failed"
python3 - "$tmp/x.csv" <<'PY' || no "export: block order, rows, metadata"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1], newline="")))
by = {}
for r in rows:
    by.setdefault(r["participant"], []).append(r)
want = {"P01": ("0", "0", "low_sf"), "P02": ("1", "1", "high_sf"), "P03": ("2", "0", "low_sf")}
for p, (index, row, first) in want.items():
    rs = by[p]
    assert all(r["participant_index"] == index and r["counterbalance_row"] == row for r in rs), p
    main = [r for r in rs if r["practice"] == "0"]
    assert len(main) == 160, (p, len(main))
    # one block per sf_block value, in the row's order
    assert all(r["sf_block"] == first for r in main[:80]), p
    assert all(r["sf_block"] != first for r in main[80:]), p
    assert {r["block"] for r in main[:80]} == {"1"} and {r["block"] for r in main[80:]} == {"2"}, p
    # practice only from the named conditions
    assert {r["condition"] for r in rs if r["practice"] == "1"} <= {"f2_c4", "f8_c4"}, p
assert {r["session_experimenter"] for r in by["P01"]} == {"AB"}
assert {r["session_notes"] for r in by["P01"]} == {"pilot, room 2"}
assert {r["session_notes"] for r in by["P02"]} == {""}
assert {r["level"] for r in rows} == {"1", "2", "3", "4"}
# the plan the export rebuilds from the stored index is the one that ran: the stored stimulus
# is the condition's (8 cpd in the high_sf block), at its level outside practice
assert all(float(r["stim_freq_cpd"]) == float(r["freq_cpd"]) for r in rows)
assert all(float(r["contrast_requested"]) == float(r["contrast"]) for r in rows if r["practice"] == "0")
# onsets on the session's clock: rising by at least iti + fixation + stimulus (1.2 s) from trial
# to trial, P02's too across its kill and resume after trial 30
for p, rs in by.items():
    on = [float(r["onset_s"]) for r in sorted(rs, key=lambda r: int(r["trial"]))]
    assert on[0] >= 1.0, (p, on[0])
    gaps = [b - a for a, b in zip(on, on[1:])]
    assert min(gaps) >= 1.2 - 1e-6, (p, min(gaps), gaps.index(min(gaps)))
PY
"$csfcal" study report "$ex/counterbalanced.conf" --store "$st" --json --bootstrap 10 > "$tmp/r.json" \
  || no "report failed"
python3 - "$tmp/r.json" <<'PY' || no "report JSON: session rows"
import json, sys
s = {x["participant"]: x for x in json.load(open(sys.argv[1]))["session_list"]}
assert [s[p]["counterbalance_row"] for p in ("P01", "P02", "P03")] == [0, 1, 0], s
assert s["P01"]["experimenter"] == "AB" and s["P01"]["notes"] == "pilot, room 2", s
assert "experimenter" not in s["P02"], s
PY
out=$("$csfcal" sessions show 1 --store "$st" 2>&1)
case "$out" in *'"experimenter":"AB"'*) ;; *) no "sessions show lacks the experimenter: $out";; esac

# refused metadata: exit 2, nothing stored
for bad in "experimenter=$(printf 'A\033[2JB')" "notes=$(head -c 300 /dev/zero | tr '\0' x)" "experimenter="; do
  out=$(run "$ex/counterbalanced.conf" --participant Q1 --store "$tmp/bad.sqlite" --set "$bad" 2>&1); rc=$?
  [ $rc -eq 2 ] || no "--set ${bad:0:20}...: exit $rc"
  case "$out" in *"--set "*) ;; *) no "--set message: $out";; esac
done
[ -e "$tmp/bad.sqlite" ] && no "refused metadata created the store"

# instructions: the simulated person's reading time is person time (same trials, same answers)
grep -v '^instructions' "$ex/counterbalanced.conf" > "$tmp/plain.conf"
cp "$ex/counterbalanced.csv" "$tmp/"
sed -i 's/^name = .*/name = plain/' "$tmp/plain.conf"
cp "$tmp/plain.conf" "$tmp/read.conf"
sed -i 's/^name = .*/name = read/' "$tmp/read.conf"
grep '^instructions' "$ex/counterbalanced.conf" >> "$tmp/read.conf"
run "$tmp/plain.conf" --participant R1 --store "$tmp/t.sqlite" >/dev/null || no "plain run failed"
run "$tmp/read.conf" --participant R1 --store "$tmp/t.sqlite" >/dev/null || no "read run failed"
"$csfcal" sessions list --store "$tmp/t.sqlite" --json > "$tmp/l.json"
python3 - "$tmp/l.json" <<'PY' || no "reading time"
import json, sys
l = json.load(open(sys.argv[1]))
plain, read = (x["person_s"] for x in sorted(l, key=lambda x: x["id"]))
# 41 words at 238 words a minute is 10 s; a person reads 1.3 times faster or slower
assert 4 < read - plain < 25, (plain, read)
PY
exit $fail
