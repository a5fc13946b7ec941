# Sourced by the tests that run csfcal in a window on a private Xvfb (tests/emu/test_placement_xvfb.sh,
# tests/observer/test_screens_xvfb.sh, tests/observer/test_human_xvfb.sh,
# tests/stimuli/test_show_xvfb.sh). xvfb_scratch sets up the scratch folder T, `fail=0` and the
# EXIT trap; xvfb_start the server (XPID). A missing tool or a server that does not come up skips
# the test (77).

# xvfb_need TOOL...: skip unless every tool is installed.
xvfb_need() {
    for p in "$@"; do
        command -v "$p" >/dev/null 2>&1 || { echo "SKIP: $p not installed"; exit 77; }
    done
}

# check WHAT CMD...: runs CMD, says ok or FAIL, and remembers a failure in fail.
check() { local what="$1"; shift; if "$@"; then echo "ok: $what"; else echo "FAIL: $what"; fail=1; fi; }

# wait_until SECONDS CMD...: polls CMD every 0.1 s until it succeeds or the time is up.
wait_until() { local n=$(($1 * 10)); shift; for _ in $(seq "$n"); do "$@" && return 0; sleep 0.1; done; return 1; }

# xvfb_scratch NAME [PIDVAR...]: the scratch folder T (/tmp/csfcal-NAME-XXXXXX), fail=0, and an
# EXIT trap that kills the processes whose pids the named variables hold (in that order, each
# empty until set), then the server, and removes T.
xvfb_scratch() {
    T=$(mktemp -d "/tmp/csfcal-$1-XXXXXX")
    shift
    XVFB_PIDVARS="$*" XPID="" fail=0
    local v
    for v in "$@"; do printf -v "$v" '%s' ""; done
    trap xvfb_cleanup EXIT
    trap 'exit 1' INT TERM
}
xvfb_cleanup() {
    local v
    for v in $XVFB_PIDVARS; do [ -n "${!v}" ] && kill "${!v}" 2>/dev/null; done
    [ -n "$XPID" ] && kill "$XPID" 2>/dev/null
    [ -n "$XPID" ] && wait "$XPID" 2>/dev/null
    rm -rf "$T"
}

# xvfb_start W H: a private server of W x H x 24, up to three attempts; sets XPID and exports
# DISPLAY and scratch XDG folders. The display number comes from -displayfd, so parallel tests
# never collide. -noreset: without it Xvfb resets whenever its last client disconnects, and every
# xdotool poll is such a client; a csfcal connecting during a reset was refused ("Failed to open
# display" in a CI run). The display is only trusted while our own server is alive and answering.
xvfb_try() {
    rm -f "$T/display"
    exec 3>"$T/display"
    Xvfb -displayfd 3 -noreset -screen 0 "$1x$2x24" -nolisten tcp >"$T/xvfb.log" 2>&1 &
    XPID=$!
    exec 3>&-
    wait_until 15 test -s "$T/display" || return 1
    DISPLAY=":$(head -n1 "$T/display")"
    export DISPLAY XDG_CONFIG_HOME="$T/cfg" XDG_DATA_HOME="$T/data"
    wait_until 10 xdotool getmouselocation >/dev/null 2>&1 && kill -0 "$XPID" 2>/dev/null
}
xvfb_start() {
    local attempt
    for attempt in 1 2 3; do
        xvfb_try "$1" "$2" && return 0
        echo "note: Xvfb attempt $attempt did not give a usable private display"
        kill "$XPID" 2>/dev/null
        wait "$XPID" 2>/dev/null
        XPID=""
        sleep 1
    done
    cat "$T/xvfb.log"
    echo "SKIP: no private Xvfb display could be started"
    exit 77
}
