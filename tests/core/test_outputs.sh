#!/bin/sh
# Every output option of csfcal (-o, --out, --plot, --csv) against what may already be at the
# path: a character device made with mknod (root only: `mknod n c 1 3; csfcal ... -o n` must not
# turn n into a regular file), a FIFO with a reader, a symbolic link to a file (its target is
# replaced, the link stays), a link to nothing (refused, nothing created), and file modes under
# umask 077 (a new file 0600; a replaced one keeps its mode, the .csflut included).
set -u
CSFCAL=$1
EXAMPLES=$2
T=$(mktemp -d /tmp/csf-outputs-XXXXXX)
trap 'rm -rf "$T"' EXIT
fail=0
ok() { echo "ok: $1"; }
bad() { echo "FAIL: $1"; fail=1; }
is_chr() { [ -c "$1" ] && [ ! -L "$1" ]; }
mode() { stat -c %a "$1"; }

# A store with a display session and an observer session to export and report from.
"$CSFCAL" display calibrate --photometer sim:display=lcd --out "$T/p.profile" --store "$T/s.sqlite" \
    --seed 1 --quiet >"$T/log" 2>&1 || { bad "display calibrate"; cat "$T/log"; }
"$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$T/a.csflut" >"$T/log" 2>&1 \
    || { bad "lut import"; cat "$T/log"; }

# Each command writes to the path given as its last argument.
run_to() { # run_to PATH: every output-writing command, each aimed at PATH (suffixes added)
    p=$1
    "$CSFCAL" lut export "$T/a.csflut" --format csv -o "$p" || return 1
    "$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$p" || return 2
    "$CSFCAL" sessions export 1 --format csv --store "$T/s.sqlite" -o "$p" || return 3
    "$CSFCAL" display export "$T/p.profile" --format icc -o "$p" || return 4
    return 0
}

if [ "$(id -u)" -eq 0 ]; then
    for f in n n.pdf n.png n.csflut; do mknod "$T/$f" c 1 3; done
    run_to "$T/n" >"$T/log" 2>&1 && ok "outputs to a character device succeed" \
        || { bad "outputs to a character device (step $?)"; cat "$T/log"; }
    "$CSFCAL" report 1 --store "$T/s.sqlite" -o "$T/n.pdf" >"$T/log" 2>&1 || { bad "report -o device"; cat "$T/log"; }
    "$CSFCAL" display calibrate --photometer sim:display=lcd --out "$T/n" --store "$T/s2.sqlite" \
        --seed 1 >"$T/log" 2>&1 || { bad "display calibrate --out device"; cat "$T/log"; }
    "$CSFCAL" observer calibrate --observer sim --profile "$T/p.profile" --store "$T/s2.sqlite" \
        --trials 24 --seed 2 --out "$T/n.csflut" --plot "$T/n.png" >"$T/log" 2>&1 \
        || { bad "observer calibrate --out/--plot device"; cat "$T/log"; }
    all=1
    for f in n n.pdf n.png n.csflut; do is_chr "$T/$f" || { bad "$f is no longer a character device"; all=0; }; done
    [ $all = 1 ] && ok "character devices stay character devices"
else
    echo "SKIP part: mknod of a character device needs root (running as uid $(id -u))"
fi

# /dev/null by name, only where a regression could not replace the machine's own (not root);
# as root the node of the same device above stands in for it.
if [ "$(id -u)" -ne 0 ]; then
    "$CSFCAL" lut export "$T/a.csflut" --format json -o /dev/null >"$T/log" 2>&1 && is_chr /dev/null \
        && ok "-o /dev/null" || { bad "-o /dev/null"; cat "$T/log"; }
fi

# A FIFO: a reader gets the whole export, and the FIFO stays a FIFO.
mkfifo "$T/fifo"
cat "$T/fifo" >"$T/fifo.out" &
reader=$!
"$CSFCAL" lut export "$T/a.csflut" --format csv -o "$T/fifo" >"$T/log" 2>&1 || { bad "export to FIFO"; cat "$T/log"; }
wait $reader
"$CSFCAL" lut export "$T/a.csflut" --format csv -o "$T/direct.csv" 2>/dev/null
cmp -s "$T/fifo.out" "$T/direct.csv" && [ -p "$T/fifo" ] && ok "FIFO gets the bytes and stays a FIFO" \
    || bad "FIFO gets the bytes and stays a FIFO"

# Standard output: "-" and /dev/stdout, appending to a log through the shell's >>.
echo "first line" >"$T/append.log"
"$CSFCAL" lut export "$T/a.csflut" --format csv -o /dev/stdout >>"$T/append.log" 2>"$T/log"
head -n 1 "$T/append.log" | grep -q "first line" && [ "$(wc -c <"$T/append.log")" -gt 100 ] \
    && ok "-o /dev/stdout appends under >>" || { bad "-o /dev/stdout appends under >>"; cat "$T/log"; }
"$CSFCAL" lut export "$T/a.csflut" --format csv -o - 2>"$T/log" | cmp -s - "$T/direct.csv" \
    && ok "-o - writes to standard output" || { bad "-o - writes to standard output"; cat "$T/log"; }

# A link to a file: the target replaced, the link kept.
echo old >"$T/target.csv"
ln -s target.csv "$T/link.csv"
"$CSFCAL" lut export "$T/a.csflut" --format csv -o "$T/link.csv" >"$T/log" 2>&1
[ -L "$T/link.csv" ] && cmp -s "$T/target.csv" "$T/direct.csv" && ok "link followed, kept" \
    || { bad "link followed, kept"; cat "$T/log"; }

# A link to nothing: refused with a message, and nothing is created where it points.
ln -s "$T/planted" "$T/dangling.csv"
if "$CSFCAL" lut export "$T/a.csflut" --format csv -o "$T/dangling.csv" >"$T/log" 2>&1; then
    bad "dangling link refused"
else
    grep -q "symbolic link to a file that does not exist" "$T/log" && [ ! -e "$T/planted" ] \
        && ok "dangling link refused" || { bad "dangling link refused"; cat "$T/log"; }
fi

# Modes under umask 077: new files 0600 (the .csflut too); a replaced 0640 file stays 0640.
(
    umask 077
    "$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$T/m.csflut" >/dev/null 2>&1
    "$CSFCAL" lut export "$T/a.csflut" --format csv -o "$T/m.csv" >/dev/null 2>&1
)
[ "$(mode "$T/m.csflut")" = 600 ] && [ "$(mode "$T/m.csv")" = 600 ] && ok "umask 077: new files 0600" \
    || bad "umask 077: new files 0600 (csflut $(mode "$T/m.csflut"), csv $(mode "$T/m.csv"))"
"$CSFCAL" lut import "$EXAMPLES/example_default_observer.csv" -o "$T/m.csflut" >/dev/null 2>&1
[ "$(mode "$T/m.csflut")" = 600 ] && ok "re-export over a 0600 table keeps 0600" \
    || bad "re-export over a 0600 table keeps 0600 (got $(mode "$T/m.csflut"))"
chmod 640 "$T/m.csv"
"$CSFCAL" lut export "$T/a.csflut" --format csv -o "$T/m.csv" >/dev/null 2>&1
[ "$(mode "$T/m.csv")" = 640 ] && ok "replaced 0640 file keeps 0640" || bad "replaced 0640 file keeps 0640"

[ $fail = 0 ] && echo "all output checks passed"
exit $fail
