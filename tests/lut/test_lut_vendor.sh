#!/bin/sh
# Vendoring (issue 10 item 3): the four csflut sources and two headers, copied into one folder,
# build with no include path as C99 and C11 under gcc and clang, and a program using them works.
set -eu
SRC=$1/results
T=$(mktemp -d /tmp/csflut-vendor-XXXXXX)
trap 'rm -rf "$T"' EXIT
mkdir "$T/csflut"
cp "$SRC/csflut.h" "$SRC/csflut_internal.h" "$SRC/csflut.c" "$SRC/csflut_write.c" \
   "$SRC/csflut_csv.c" "$SRC/csflut_export.c" "$T/csflut/"
cp "$1/docs/examples/example_default_observer.csflut" "$T/"
cat >"$T/use.c" <<'C'
#include "csflut/csflut.h"
#include <stdio.h>
int main(void)
{
    csflut_table *t;
    if (csflut_open_file("example_default_observer.csflut", &t) != CSFLUT_OK) return 1;
    printf("%.6g %d\n", csflut_threshold(t, 4, 0), csflut_perceptible(t, 4, 0, 0.01));
    csflut_close(t);
    return 0;
}
C
for c in gcc clang; do
    for std in c99 c11; do
        # no -I, no -D: each file compiled from inside the folder, as a vendoring build would
        (cd "$T" && $c -std=$std -O2 -Wall -Wextra -pedantic -Werror \
            csflut/csflut.c csflut/csflut_write.c csflut/csflut_csv.c csflut/csflut_export.c \
            use.c -o use -lm) || { echo "FAIL: vendored build with $c -std=$std"; exit 1; }
        OUT=$(cd "$T" && ./use)
        [ "$OUT" = "0.004218 1" ] || { echo "FAIL: $c -std=$std: unexpected output '$OUT'"; exit 1; }
        echo "$c -std=$std: ok ($OUT)"
    done
done
echo ok
