#!/usr/bin/env bash
# csfcal study run|report from the command line: bad study files refused with exit 2 before any
# trial (nothing stored), a run killed by SIGKILL resumed to the same trials an uninterrupted
# run stores, and the report's JSON, tidy CSV and PDF.
#   usage: test_study_cli.sh CSFCAL EXAMPLES_DIR
set -u
csfcal=$1
ex=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
no() { echo "FAIL: $*"; fail=1; }
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
run() { "$csfcal" study run "$@" --observer sim --headless --quiet; }

# ---- bad study files: exit 2, message with file, line and problem, nothing stored ----
cp "$ex/contrast_2afc.conf" "$tmp/bad.conf"
sed -i 's/^conditions = .*/conditions = bad.csv/' "$tmp/bad.conf"
check_bad() { # CSV_TEXT EXPECTED_MESSAGE
  printf '%b' "$1" > "$tmp/bad.csv"
  out=$(run "$tmp/bad.conf" --participant X --store "$tmp/bad.sqlite" 2>&1); rc=$?
  [ $rc -eq 2 ] || no "expected exit 2 for [$2], got $rc: $out"
  case "$out" in *"$2"*) ;; *) no "message lacks [$2]: $out";; esac
}
check_bad 'label,freq_cpd,ecc_deg\na,2,5\n' 'bad.csv:2 (a): gabor conditions need the columns freq_cpd and contrast'
check_bad 'label,freq_cpd,contrast,ecc_deg\na,2,0.01,5\nfar,2,0.01,70\n' 'bad.csv:3 (far)'
check_bad 'label,freq_cpd,contrast,ecc_deg\nfine,50,0.01,5\n' 'Nyquist'
check_bad 'label,stimulus,image_a,image_b,size_deg,ecc_deg\np,image,missing.png,missing.png,4,5\n' 'bad.csv:2 (p): image_a'
printf 'label,freq_cpd,contrast,ecc_deg\na,2,0.01,5\n' > "$tmp/bad.csv"
sed -i 's/^stimulus_s = .*/stimulus_s = 0.004/' "$tmp/bad.conf"
out=$(run "$tmp/bad.conf" --participant X --store "$tmp/bad.sqlite" 2>&1); rc=$?
[ $rc -eq 2 ] || no "impossible timing: exit $rc"
case "$out" in *"shorter than one frame"*) ;; *) no "timing message: $out";; esac
[ -e "$tmp/bad.sqlite" ] && no "a refused study created the store"
out=$("$csfcal" study run "$ex/contrast_2afc.conf" --participant 'bad code' --store "$tmp/bad.sqlite" 2>&1); rc=$?
[ $rc -eq 2 ] || no "bad participant code: exit $rc"
# codes that name no file safely or read as an option: refused before anything is stored
for code in .. -P01 .hidden 'P..1'; do
  out=$("$csfcal" study run "$ex/contrast_2afc.conf" --participant "$code" --store "$tmp/codes.sqlite" \
        --observer sim --headless 2>&1); rc=$?
  [ $rc -eq 2 ] || no "participant code '$code': exit $rc"
  case "$out" in *"a letter or digit, then up to 62"*) ;; *) no "participant code '$code': $out";; esac
done
[ ! -e "$tmp/codes.sqlite" ] || [ "$("$csfcal" sessions list --store "$tmp/codes.sqlite" --json)" = "[]" ] \
  || no "a refused participant code left a session"
# without a display profile the run says it uses the default display model
out=$("$csfcal" study run "$ex/contrast_2afc.conf" --participant W1 --store "$tmp/warn.sqlite" \
      --observer sim --headless 2>&1 >/dev/null) || no "run for the default-model warning failed"
case "$out" in *"no --profile given: using the default display model"*) ;; *) no "no default-model warning: $out";; esac

# ---- kill and resume: the same trials as an uninterrupted run ----
run "$ex/contrast_2afc.conf" --participant K1 --store "$tmp/full.sqlite" >/dev/null || no "full run failed"
CSFCAL_TEST_KILL_AFTER=137 run "$ex/contrast_2afc.conf" --participant K1 --store "$tmp/kill.sqlite" >/dev/null 2>&1
rc=$?
[ $rc -eq 137 ] || no "the killed run exited $rc (expected 137, SIGKILL)"
n=$(python3 -c "import sqlite3,sys;c=sqlite3.connect(sys.argv[1]);print(c.execute('select count(*) from trials').fetchone()[0], c.execute('select state from sessions').fetchone()[0])" "$tmp/kill.sqlite")
[ "$n" = "137 running" ] || no "after the kill: $n (expected 137 trials, running)"
out=$(run "$ex/contrast_2afc.conf" --participant K1 --store "$tmp/kill.sqlite" --json) || no "resume failed"
case "$out" in *'"resumed":true'*'"finished":true'*) ;; *) no "resume JSON: $out";; esac
q='select seq, is_practice, signal_interval, response, contrast_requested, contrast_shown_mean, polar_deg from trials order by seq'
a=$(python3 -c "import sqlite3,sys;print(sqlite3.connect(sys.argv[1]).execute(sys.argv[2]).fetchall())" "$tmp/full.sqlite" "$q")
b=$(python3 -c "import sqlite3,sys;print(sqlite3.connect(sys.argv[1]).execute(sys.argv[2]).fetchall())" "$tmp/kill.sqlite" "$q")
[ "$a" = "$b" ] || no "the resumed session's trials differ from the uninterrupted run's"
# a finished participant is not run again
out=$(run "$ex/contrast_2afc.conf" --participant K1 --store "$tmp/kill.sqlite" 2>&1); rc=$?
[ $rc -eq 2 ] || no "finished participant: exit $rc ($out)"
# the study file's hash, the participant and the study files are in the store
python3 - "$tmp/kill.sqlite" <<'PY' || no "store contents"
import json, sqlite3, sys
c = sqlite3.connect(sys.argv[1])
s = json.loads(c.execute("select settings_json from sessions").fetchone()[0])
assert len(s["hash"]) == 16 and s["participant"] == "K1", s
assert c.execute("select count(*) from participants").fetchone()[0] == 1
kinds = sorted(r[0] for r in c.execute("select kind from artifacts"))
assert kinds == ["conditions", "study"], kinds
PY

# ---- report: JSON, CSV, PDF ----
"$csfcal" study report "$ex/contrast_2afc.conf" --store "$tmp/full.sqlite" --json --bootstrap 50 \
  -o "$tmp/r.pdf" --csv "$tmp/r.csv" > "$tmp/r.json" || no "report failed"
python3 - "$tmp/r.json" "$tmp/r.csv" <<'PY' || no "report contents"
import csv, json, sys
r = json.load(open(sys.argv[1]))
assert r["design"] == "2afc" and r["sessions"] == 1, r
assert len(r["conditions"]) == 24 and len(r["curves"]) == 4, (len(r["conditions"]), len(r["curves"]))
for c in r["curves"]:
    assert c["fitted"] and c["t_log10_ci95"][0] <= c["t_log10"] <= c["t_log10_ci95"][1], c
rows = list(csv.DictReader(open(sys.argv[2])))
assert len(rows) == 28 and {r["kind"] for r in rows} == {"condition", "curve"}
PY
head -c 5 "$tmp/r.pdf" | grep -q '%PDF-' || no "no PDF"
out=$("$csfcal" study report nosuchstudy --store "$tmp/full.sqlite" 2>&1); rc=$?
[ $rc -ne 0 ] || no "report of an unknown study succeeded"
exit $fail
