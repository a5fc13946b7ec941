#!/usr/bin/env bash
# Study provenance and the trial export: a study's identity is the SHA-256 of its settings, its
# conditions and every image; a participant is added or resumed only when none of them changed
# (the refusal names what changed and how to start a new version); images are kept in the store;
# a report of a settings file covers exactly the sessions that ran those files; the trial export
# carries every conditions column (the user's own included) and is read back exactly by pandas.
#   usage: test_study_versions.sh CSFCAL EXAMPLES_DIR
set -u
csfcal=$1
ex=$2
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
fail=0
no() { echo "FAIL: $*"; fail=1; }
export ASAN_OPTIONS="${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0"
py=""
for p in python3 /usr/bin/python3; do
  if "$p" -c 'import pandas' 2>/dev/null; then py=$p; break; fi
done
[ -n "$py" ] || { echo "SKIP: no python3 with pandas (Debian: python3-pandas; scripts/setup.sh installs it)"; exit 77; }

# a small same/different study with columns of the user's own (a note with a comma and quotes)
d=$tmp/study
mkdir -p "$d"
cp -r "$ex/images" "$d/"
sed -e 's/^trials_per_condition = .*/trials_per_condition = 8/' -e 's/^name = .*/name = prov/' \
  "$ex/same_different.conf" > "$d/prov.conf"
cat > "$d/same_different.csv" <<'CSV'
label,stimulus,image_a,image_b,size_deg,ecc_deg,polar_deg,curve,corrAns,notes
identical,image,images/base.png,images/base_copy.png,4,0,0,baseline,same,plain
fine_detail,image,images/base.png,images/fine.png,4,0,0,imperceptible,different,"left, then ""right"""
blob,image,images/base.png,images/blob.png,4,0,0,perceptible,different,0042
CSV
st=$tmp/s.sqlite
run() { "$csfcal" study run "$d/prov.conf" --store "$st" --observer sim --headless --quiet "$@"; }

run --participant P1 >/dev/null || no "first participant refused"
# ---- an image replaced between participants: refused, naming the image and --version 2 ----
cp "$d/images/blob.png" "$tmp/blob.orig.png"
cp "$d/images/fine.png" "$d/images/blob.png"
out=$(run --participant P2 2>&1); rc=$?
[ $rc -eq 2 ] || no "a changed image was accepted (exit $rc): $out"
case "$out" in *"image images/blob.png changed"*"--version 2"*) ;; *) no "refusal does not name the image and --version 2: $out";; esac
n=$("$csfcal" sessions list --store "$st" --json | "$py" -c 'import json,sys;print(len(json.load(sys.stdin)))')
[ "$n" = 1 ] || no "the refused participant left a session ($n sessions)"
# a changed conditions file and settings file are named too
cp "$tmp/blob.orig.png" "$d/images/blob.png"
echo "# a comment is a change of the file" >> "$d/prov.conf"
out=$(run --participant P2 2>&1); rc=$?
[ $rc -eq 2 ] || no "a changed settings file was accepted (exit $rc)"
case "$out" in *"the settings file changed"*) ;; *) no "refusal does not name the settings file: $out";; esac
sed -i '$d' "$d/prov.conf"
run --participant P2 >/dev/null || no "the original files were refused"

# ---- version 2 with the new image; a resume after a change is refused, then continues ----
cp "$d/images/fine.png" "$d/images/blob.png"
run --participant P2 --version 2 >/dev/null || no "version 2 refused"
CSFCAL_TEST_KILL_AFTER=5 run --participant P3 --version 2 >/dev/null 2>&1
sed -i 's/^notes.*//' "$d/same_different.csv"
sed -i 's/,0042$/,0043/' "$d/same_different.csv"
out=$(run --participant P3 --version 2 2>&1); rc=$?
[ $rc -eq 2 ] || no "resume with a changed conditions file accepted (exit $rc)"
case "$out" in *"session"*"began with other files: the conditions file changed"*"Resume it with the files it began with"*) ;;
  *) no "resume refusal: $out";; esac
sed -i 's/,0043$/,0042/' "$d/same_different.csv"
out=$(run --participant P3 --version 2 --json) || no "resume with the original files failed"
case "$out" in *'"resumed":true'*'"version":2'*) ;; *) no "resume JSON: $out";; esac
CSFCAL_TEST_KILL_AFTER=3 run --participant P4 --version 2 >/dev/null 2>&1   # left unfinished

# ---- the images are in the store, with the hashes the sessions name ----
"$py" - "$st" <<'PY' || no "store: images and identities"
import hashlib, json, sqlite3, sys
c = sqlite3.connect(sys.argv[1])
for sid, sj in c.execute("select id, settings_json from sessions order by id"):
    s = json.loads(sj)
    ident = s["identity"]
    assert s["sha256"] == ident["sha256"] and len(ident["sha256"]) == 64, s
    imgs = {p: hashlib.sha256(b).hexdigest() for p, b in
            c.execute("select path, content from artifacts where session_id=? and kind='image'", (sid,))}
    assert imgs == {i["name"]: i["sha256"] for i in ident["images"]}, (sid, imgs, ident["images"])
    assert len(imgs) == 4, imgs
    man = "settings %s\nconditions %s\n" % (ident["settings_sha256"], ident["conditions_sha256"])
    man += "".join("image %s %s\n" % (i["sha256"], i["name"]) for i in ident["images"])
    assert hashlib.sha256(man.encode()).hexdigest() == ident["sha256"], "identity is not the manifest's hash"
v = {json.loads(sj)["version"]: json.loads(sj)["identity"] for (sj,) in c.execute("select settings_json from sessions")}
b1 = [i for i in v[1]["images"] if i["name"] == "images/blob.png"][0]["sha256"]
b2 = [i for i in v[2]["images"] if i["name"] == "images/blob.png"][0]["sha256"]
assert b1 != b2, "the two versions' blob.png have one hash"
PY

# ---- report: exactly the sessions of the file given; the others named ----
"$csfcal" study report "$d/prov.conf" --store "$st" --json --bootstrap 0 --csv "$tmp/r.csv" > "$tmp/r.json" \
  || no "report of version 2's files failed"
"$py" - "$tmp/r.json" "$tmp/r.csv" <<'PY' || no "report contents"
import json, sys, pandas as pd
r = json.load(open(sys.argv[1]))
assert r["version"] == 2 and len(r["sha256"]) == 64, r["version"]
got = sorted((x["participant"], x["version"], x["finished"]) for x in r["session_list"])
assert got == [("P2", 2, True), ("P3", 2, True), ("P4", 2, False)], got
assert "version 1" in r["other_versions"], r["other_versions"]
t = pd.read_csv(sys.argv[2])
assert {"version", "session", "finished"} <= set(t.columns), t.columns
assert set(t["version"]) == {2}
p4 = t[t["scope"] == "P4"]
assert len(p4) and (p4["finished"] == 0).all(), p4
assert (t[t["scope"] == "P2"]["finished"] == 1).all()
PY
out=$("$csfcal" study report prov --store "$st" --bootstrap 0 2>&1); rc=$?
[ $rc -eq 2 ] || no "report by name with two versions: exit $rc"
case "$out" in *"several versions"*"version 1"*"version 2"*) ;; *) no "versions not listed: $out";; esac
"$csfcal" study report prov --version 1 --store "$st" --json --bootstrap 0 | "$py" -c '
import json, sys
r = json.load(sys.stdin)
assert [x["participant"] for x in r["session_list"]] == ["P1", "P2"], r["session_list"]' \
  || no "report --version 1"

# ---- the trial export, read by pandas exactly ----
"$csfcal" study export "$d/prov.conf" --store "$st" -o "$tmp/t.csv" --per-participant "$tmp/pp" 2>/dev/null \
  || no "export failed"
"$py" - "$tmp/t.csv" "$tmp/pp" "$st" <<'PY' || no "export contents"
import csv, os, sqlite3, sys, pandas as pd
path, pp, store = sys.argv[1:4]
header = next(csv.reader(open(path)))
t = pd.read_csv(path, keep_default_na=True)
assert list(t.columns) == header and len(set(header)) == len(header), header
for col in ("corrAns", "notes", "label", "image_a", "study", "version", "participant", "session", "block",
            "trial", "condition", "response", "correct", "rt_s", "image_first", "image_first_sha256", "flags"):
    assert col in t.columns, col
c = sqlite3.connect(store)
sessions = [s for (s,) in c.execute("select id from sessions where json_extract(settings_json,'$.version')=2")]
n = c.execute("select count(*) from trials where session_id in (%s)" % ",".join(map(str, sessions))).fetchone()[0]
assert len(t) == n, (len(t), n)
for col, kind in (("trial", "i"), ("session", "i"), ("block", "i"), ("response", "i"), ("rt_s", "f"),
                  ("contrast_requested", "if"), ("participant", "O"), ("notes", "O"), ("corrAns", "O")):
    assert t[col].dtype.kind in kind, (col, t[col].dtype)
notes = dict(zip(t["condition"], t["notes"]))
assert notes["fine_detail"] == 'left, then "right"' and notes["identical"] == "plain", notes
# every stored value comes back exactly
db = {(s, q): (r, rt, cr) for s, q, r, rt, cr in
      c.execute("select session_id, seq, response, rt_s, contrast_requested from trials")}
for row in t.itertuples():
    r, rt, cr = db[(row.session, row.trial)]
    assert row.response == r and row.contrast_requested == cr, row
    assert (pd.isna(row.rt_s) and rt is None) or row.rt_s == rt, (row.rt_s, rt)
assert set(t["version"]) == {2} and set(t["participant"]) == {"P2", "P3", "P4"}
assert set(t[t["practice"] == 1]["block"]) == {0} and set(t[t["practice"] == 0]["block"]) == {1, 2}
blob = t[t["condition"] == "blob"]
assert blob["image_first_sha256"].str.len().eq(64).all()
files = sorted(os.listdir(pp))
assert files == ["P2.csv", "P3.csv", "P4.csv"], files
parts = [pd.read_csv(os.path.join(pp, f)) for f in files]
assert sum(len(p) for p in parts) == len(t) and all(len(set(p["participant"])) == 1 for p in parts)
PY

# ---- columns of the user's own: names that would clash or are a known column mistyped ----
for col in Contrast response 'my col'; do
  sed "1s/,notes$/,$col/" "$d/same_different.csv" > "$tmp/bad.csv"
  sed 's/^conditions = .*/conditions = bad.csv/' "$d/prov.conf" > "$tmp/bad.conf"
  cp -r "$d/images" "$tmp/" 2>/dev/null
  out=$("$csfcal" study run "$tmp/bad.conf" --participant X --store "$tmp/bad.sqlite" --observer sim --headless 2>&1); rc=$?
  [ $rc -eq 2 ] || no "column '$col' accepted (exit $rc)"
  case "$out" in *"bad.csv:1: column '$col'"*) ;; *) no "column '$col': $out";; esac
done
exit $fail
