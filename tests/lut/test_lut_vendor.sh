#!/bin/sh
# Vendoring: the four csflut sources and two headers, copied into one folder, build with no
# include path and no define as C99 and C11 under gcc and clang, and a program using them works
# and sees the version its header declares. The library's numbers do not depend on the target's
# FMA instructions (-march=native), given the flag docs/csflut.md names for GCC's GNU modes. On
# Windows, csflut.h declares the API dllexport, dllimport or plain as CSFLUT_BUILD / (nothing) /
# CSFLUT_STATIC say (checked with clang's Windows targets, front end only).
set -eu
SRC=$1/results/csflut
T=$(mktemp -d /tmp/csflut-vendor-XXXXXX)
trap 'rm -rf "$T"' EXIT
mkdir "$T/csflut"
cp "$SRC"/*.h "$SRC"/*.c "$T/csflut/" # the whole folder: it is the library
cp "$1/docs/examples/example_default_observer.csflut" "$T/"
cat >"$T/use.c" <<'C'
#include "csflut/csflut.h"
#include <stdio.h>
#include <string.h>
int main(void)
{
    csflut_table *t;
    if (csflut_open_file("example_default_observer.csflut", &t) != CSFLUT_OK) return 1;
    printf("%.6g %d\n", csflut_threshold(t, 4, 0), csflut_perceptible(t, 4, 0, 0.01));
    printf("%s %d %d\n", csflut_version(), csflut_version_number(),
           strcmp(csflut_version(), CSFLUT_LIB_VERSION) == 0 &&
               csflut_version_number() == CSFLUT_LIB_VERSION_NUMBER);
    csflut_close(t);
    return 0;
}
C
# queries whose inputs involve no multiply-add of their own (exact integer -> double steps), so
# only the library's arithmetic can differ between builds
cat >"$T/many.c" <<'C'
#include "csflut/csflut.h"
#include <stdio.h>
int main(void)
{
    csflut_table *t;
    if (csflut_open_file("example_default_observer.csflut", &t) != CSFLUT_OK) return 1;
    unsigned long long x = 1;
    for (int i = 0; i < 20000; i++) {
        x = x * 6364136223846793005ULL + 1442695040888963407ULL;
        double f = (double)(x >> 50) / 256.0 + 0.25, e = (double)((x >> 20) & 0xffff) / 1400.0;
        csflut_set_conservative(t, i & 1);
        printf("%a %a\n", csflut_threshold(t, f, e), csflut_max_frequency(t, e, 0.01));
    }
    csflut_close(t);
    return 0;
}
C
HV=$(sed -n 's/^#define CSFLUT_LIB_VERSION "\(.*\)"/\1/p' "$SRC/csflut.h")
HN=$(echo "$HV" | awk -F. '{print $1 * 10000 + $2 * 100 + $3}')
LIBSRC="csflut/csflut.c csflut/csflut_write.c csflut/csflut_csv.c csflut/csflut_export.c"
for c in gcc clang; do
    for std in c99 c11; do
        # no -I, no -D: each file compiled from inside the folder, as a vendoring build would
        (cd "$T" && $c -std=$std -O2 -Wall -Wextra -pedantic -Werror $LIBSRC use.c -o use -lm) \
            || { echo "FAIL: vendored build with $c -std=$std"; exit 1; }
        OUT=$(cd "$T" && ./use)
        WANT=$(printf '0.004218 1\n%s %s 1' "$HV" "$HN")
        [ "$OUT" = "$WANT" ] || { echo "FAIL: $c -std=$std: output '$OUT', want '$WANT'"; exit 1; }
        echo "$c -std=$std: ok ($(echo "$OUT" | tr '\n' ' '))"
    done
done
# same bits with and without FMA instructions: clang by the pragma in csflut_internal.h, gcc in
# ISO C mode by default, gcc in GNU mode with -ffp-contract=off
(cd "$T" && gcc -std=c11 -O2 $LIBSRC many.c -o ref -lm && ./ref >ref.txt)
for b in "clang -std=c11 -march=native" "clang -std=gnu11 -O3 -march=native" \
         "gcc -std=c11 -march=native" "gcc -std=gnu11 -O3 -march=native -ffp-contract=off"; do
    (cd "$T" && $b -O2 -Wall -Wextra -Werror $LIBSRC many.c -o fma -lm && ./fma >fma.txt) \
        || { echo "FAIL: vendored build with $b"; exit 1; }
    cmp -s "$T/ref.txt" "$T/fma.txt" || { echo "FAIL: $b gives other numbers than the baseline build"; exit 1; }
    echo "$b: the baseline's numbers bit for bit ($(wc -l <"$T/ref.txt") queries)"
done
# Windows: what CSFLUT_API expands to, per define
cat >"$T/win.c" <<'C'
#include "csflut/csflut.h"
const char *use(void) { return csflut_version(); }
#ifdef DEFINE_IT
const char *csflut_version(void) { return "x"; }
#endif
C
win() { # win TARGET DEFINES EXPECTED-LINE [nodll]
    (cd "$T" && clang --target="$1" -std=c99 -Wall -Wextra -pedantic -Werror $2 -S -emit-llvm -o win.ll win.c) \
        || { echo "FAIL: csflut.h for $1 with '$2' does not compile"; exit 1; }
    grep -q "$3" "$T/win.ll" || { echo "FAIL: $1 '$2': no '$3' in:"; grep csflut_version "$T/win.ll"; exit 1; }
    if [ "${4:-}" = nodll ] && grep -q 'dll' "$T/win.ll"; then
        echo "FAIL: $1 '$2': dllimport/dllexport where the library is static:"; grep csflut_version "$T/win.ll"; exit 1
    fi
}
for tg in x86_64-pc-windows-msvc x86_64-w64-windows-gnu; do
    win $tg "" '^declare dllimport .*@csflut_version('
    win $tg "-DCSFLUT_BUILD -DDEFINE_IT" '^define .*dllexport .*@csflut_version('
    win $tg "-DCSFLUT_STATIC" '^declare .*@csflut_version(' nodll
    win $tg "-DCSFLUT_STATIC -DDEFINE_IT" '^define .*@csflut_version(' nodll
    echo "$tg: dllimport by default, dllexport with CSFLUT_BUILD, neither with CSFLUT_STATIC"
done
echo ok
