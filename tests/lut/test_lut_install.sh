#!/bin/sh
# csflut installs as a library with its header and a pkg-config file: install the build into a
# scratch DESTDIR, then compile and run a small program against it through pkg-config only.
set -eu
BUILD=$1
T=$(mktemp -d /tmp/csflut-install-XXXXXX)
trap 'rm -rf "$T"' EXIT
meson install -C "$BUILD" --no-rebuild --destdir "$T/root" >"$T/install.log" 2>&1 || { cat "$T/install.log"; exit 1; }
PC=$(find "$T/root" -name csflut.pc | head -1)
[ -n "$PC" ] || { echo "FAIL: no csflut.pc installed"; exit 1; }
PREFIX=$(sed -n 's/^prefix=//p' "$PC")
export PKG_CONFIG_PATH=$(dirname "$PC")
CFLAGS=$(pkg-config --define-variable=prefix="$T/root$PREFIX" --cflags csflut)
LIBS=$(pkg-config --define-variable=prefix="$T/root$PREFIX" --libs csflut)
cat >"$T/use.c" <<'C'
#include <csflut.h>
#include <stdio.h>
int main(int argc, char **argv)
{
    csflut_table *t;
    csflut_status st = csflut_open_file(argv[1], &t);
    if (st != CSFLUT_OK) { fprintf(stderr, "%s\n", csflut_strerror(st)); return 1; }
    printf("%.6g %d\n", csflut_threshold(t, 4, 0), csflut_perceptible(t, 4, 0, 0.01));
    csflut_close(t);
    return 0;
}
C
# plain cc, as a renderer outside csfcal would build; a sanitizer build of csfcal installs an
# instrumented library, which needs the sanitizer runtime in the program too
SAN=
LIBSO=$(pkg-config --define-variable=prefix="$T/root$PREFIX" --variable=libdir csflut)/libcsflut.so
if nm -D "$LIBSO" 2>/dev/null | grep -q __asan_init; then SAN=-fsanitize=address,undefined; fi
cc -std=c11 -Wall -Werror $SAN $CFLAGS "$T/use.c" -o "$T/use" $LIBS -lm
LIBDIR=$(pkg-config --define-variable=prefix="$T/root$PREFIX" --variable=libdir csflut)
OUT=$(LD_LIBRARY_PATH="$LIBDIR" "$T/use" "$2/docs/examples/example_default_observer.csflut")
echo "installed library says: $OUT"
[ "$OUT" = "0.004218 1" ] || { echo "FAIL: unexpected output"; exit 1; }
LD_LIBRARY_PATH="$LIBDIR" ldd "$T/use" | grep -q "$LIBDIR/libcsflut.so" || { echo "FAIL: not linked to the installed library"; exit 1; }
# The shared library exports the public API and nothing else, and carries one
# version (pkg-config, the file name, CSFLUT_LIB_VERSION in the header).
HDR=$(find "$T/root" -name csflut.h | head -1)
nm -D --defined-only "$LIBSO" | awk '$2 ~ /^[TDBR]$/ {print $3}' | grep -v '^_' | sort >"$T/exported"
sed -n 's/^CSFLUT_API [^(]*[ *]\(csflut_[a-z0-9_]*\)(.*/\1/p' "$HDR" | sort >"$T/public"
if ! cmp -s "$T/exported" "$T/public"; then
    echo "FAIL: exported symbols differ from the public API (< exported, > declared):"
    diff "$T/exported" "$T/public" || true
    exit 1
fi
echo "exports: $(wc -l <"$T/exported") symbols, exactly the public API"
PCV=$(pkg-config --define-variable=prefix="$T/root$PREFIX" --modversion csflut)
HV=$(sed -n 's/^#define CSFLUT_LIB_VERSION "\(.*\)"/\1/p' "$HDR")
[ -e "$(dirname "$LIBSO")/libcsflut.so.$PCV" ] || { echo "FAIL: pkg-config says $PCV but no libcsflut.so.$PCV"; ls "$(dirname "$LIBSO")"; exit 1; }
[ "$PCV" = "$HV" ] || { echo "FAIL: pkg-config says $PCV, csflut.h says $HV"; exit 1; }
echo "version: $PCV everywhere"
echo ok
