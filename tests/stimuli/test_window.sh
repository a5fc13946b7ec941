#!/bin/sh
# Runs test_window inside its own Xvfb (1280x720, 24 bit). Skips (77) when Xvfb is missing.
command -v xvfb-run >/dev/null 2>&1 || { echo "xvfb-run not installed"; exit 77; }
unset EGL_PLATFORM
exec xvfb-run -a -s "-noreset -screen 0 1280x720x24" "$1"
