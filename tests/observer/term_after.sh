# Sourced by the observer session scripts (bash).
# term_after_trials STORE SID N ERRFILE CMD...: runs CMD in the background (stderr to ERRFILE),
# sends it SIGTERM once session SID of STORE has at least N stored trials, and sets RC to its exit
# status. Progress, not a fixed delay: under ASan on a loaded 2-core machine csfcal can take
# seconds just to start, and a SIGTERM before its session exists kills it (exit 143) instead of
# pausing a session. The store is read with sqlite3 -readonly, and only once it exists (sqlite3
# would otherwise create an empty file there). After 120 s without N trials the command is
# killed and RC is 124.
term_after_trials() {
    local store="$1" sid="$2" n="$3" errf="$4"; shift 4
    "$@" 2>"$errf" &
    local pid=$! end=$((SECONDS + 120)) have
    while kill -0 "$pid" 2>/dev/null; do
        have=0
        [ -s "$store" ] && have=$(sqlite3 -readonly "$store" \
            "SELECT count(*) FROM trials WHERE session_id = $sid" 2>/dev/null)
        [ "${have:-0}" -ge "$n" ] 2>/dev/null && break
        if [ $SECONDS -ge $end ]; then
            kill -KILL "$pid" 2>/dev/null
            wait "$pid"
            RC=124
            return
        fi
        sleep 0.1
    done
    kill -TERM "$pid" 2>/dev/null
    wait "$pid"
    RC=$?
}
