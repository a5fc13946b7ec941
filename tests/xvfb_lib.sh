# Sourced by the tests that run csfcal in a window on a private Xvfb and read it back from
# screenshots (tests/emu/test_placement_xvfb.sh, tests/observer/test_screens_xvfb.sh,
# tests/stimuli/test_show_xvfb.sh). The caller sets T (its scratch folder) and `fail=0`, and its
# EXIT trap kills XPID. A missing tool or a server that does not come up skips the test (77).

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

# xvfb_start W H: a private server of W x H x 24 (the display number from -displayfd, so
# parallel tests never collide); sets XPID and exports DISPLAY and scratch XDG folders.
xvfb_start() {
    exec 3>"$T/display"
    Xvfb -displayfd 3 -noreset -screen 0 "$1x$2x24" -nolisten tcp >"$T/xvfb.log" 2>&1 &
    XPID=$!
    exec 3>&-
    wait_until 15 test -s "$T/display" || { echo "SKIP: no private Xvfb display"; exit 77; }
    DISPLAY=":$(head -n1 "$T/display")"
    export DISPLAY XDG_CONFIG_HOME="$T/cfg" XDG_DATA_HOME="$T/data"
    wait_until 10 xdotool getmouselocation >/dev/null 2>&1 || { echo "SKIP: Xvfb does not answer"; exit 77; }
}
