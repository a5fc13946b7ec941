#!/usr/bin/env bash
# Runs a command against a throwaway PostgreSQL server from the Debian package:
#   pg_run.sh CMD ARGS...        initdb in a new temporary folder, start the server (unix socket
#                                in that folder, no TCP), run CMD with CSF_TEST_PG set to a
#                                libpq URI of an empty database, stop the server, remove the folder.
#   pg_run.sh stop|start|restart DIR   (for the tests: a server restart mid-session)
# Exits 77 (meson's "skipped") with a message when no server binaries are installed: the
# PostgreSQL tests are then reported as skipped, never as passed. scripts/setup.sh installs them.
# initdb refuses to run as root: as root the server runs as the 'postgres' user of the package.
set -euo pipefail

# CSF_PG_BIN overrides the search (a server built elsewhere; a missing folder checks the skip).
PG_BIN=${CSF_PG_BIN:-$(ls -d /usr/lib/postgresql/*/bin 2>/dev/null | sort -V | tail -n 1 || true)}
if [ -z "$PG_BIN" ] || [ ! -x "$PG_BIN/initdb" ] || [ ! -x "$PG_BIN/pg_ctl" ]; then
  echo "SKIP: no PostgreSQL server binaries (/usr/lib/postgresql/*/bin/initdb); install the" \
       "Debian package postgresql (scripts/setup.sh does) to run the PostgreSQL store tests" >&2
  exit 77
fi

as_pg() {
  if [ "$(id -u)" -eq 0 ]; then runuser -u postgres -- "$@"; else "$@"; fi
}

ctl() { # ctl DIR start|stop|restart
  local dir=$1 what=$2
  case $what in
    stop) as_pg "$PG_BIN/pg_ctl" -D "$dir/data" -m fast -w stop >/dev/null ;;
    *) as_pg "$PG_BIN/pg_ctl" -D "$dir/data" -l "$dir/server.log" -w -t 60 \
         -o "-k $dir -c listen_addresses= -c fsync=on -c max_connections=100" "$what" >/dev/null ;;
  esac
}

case ${1:-} in
  start|stop|restart) ctl "$2" "$1"; exit 0 ;;
esac

dir=$(mktemp -d "${TMPDIR:-/tmp}/csfpg-XXXXXX")
chmod 755 "$dir"
[ "$(id -u)" -ne 0 ] || chown postgres "$dir"
if ! as_pg test -w "$dir"; then # TMPDIR inside a folder the server's user cannot enter
  rmdir "$dir"
  dir=$(mktemp -d /tmp/csfpg-XXXXXX)
  chmod 755 "$dir"
  [ "$(id -u)" -ne 0 ] || chown postgres "$dir"
fi
cleanup() {
  ctl "$dir" stop 2>/dev/null || true
  rm -rf "$dir"
}
trap cleanup EXIT
# Local connections by the test's own superuser are trusted; the least-privilege roles of
# data/sql/roles.sql log in with a password (scram), read from a password file by libpq.
as_pg "$PG_BIN/initdb" -D "$dir/data" -U csfcal_admin --auth-local=trust --auth-host=reject \
  --no-sync >/dev/null
cat > "$dir/data/pg_hba.conf" <<'EOF'
local all csfcal_admin trust
local all all scram-sha-256
EOF
ctl "$dir" start
as_pg "$PG_BIN/createdb" -h "$dir" -U csfcal_admin csfcal
export CSF_TEST_PG="postgresql:///csfcal?host=$dir&user=csfcal_admin"
export CSF_TEST_PG_DIR="$dir"
export CSF_TEST_PG_RUN="$(cd "$(dirname "$0")" && pwd)/$(basename "$0")"
export CSF_TEST_PG_BIN="$PG_BIN"
set +e
"$@"
rc=$?
set -e
if [ $rc -ne 0 ] && [ $rc -ne 77 ]; then
  echo "--- server log (last 30 lines) ---" >&2
  tail -n 30 "$dir/server.log" >&2 || true
fi
exit $rc
