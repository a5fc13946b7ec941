#!/usr/bin/env bash
# Installs every Debian 12 package csfcal needs to build, test and run (as root, or with sudo),
# then configures the build directories. Safe to run again.
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(
  meson ninja-build pkg-config gcc g++ clang libclang-rt-14-dev make clang-format clang-tidy
  libglfw3-dev libegl-dev libgl-dev libegl-mesa0 libgl1-mesa-dri libgles-dev
  libsqlite3-dev sqlite3 libcairo2-dev libpng-dev
  libopencolorio-dev opencolorio-tools liblcms2-dev liblcms2-utils
  libusb-1.0-0-dev libhidapi-dev
  xvfb xauth x11-xserver-utils xdotool libx11-dev x11-apps bsdutils
  python3 poppler-utils argyll glslang-tools libjansson-dev
  libpq-dev postgresql libssl-dev python3-pandas
)
# Optional, for the benchmarks' cross-checks only (bench/anchors, bench/quest): `setup.sh --bench`.
BENCH_PACKAGES=(octave)
[ "${1:-}" = "--bench" ] && PACKAGES+=("${BENCH_PACKAGES[@]}")

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  echo "setup: installing ${missing[*]}"
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

# udev rules for photometers and response devices (data/udev/70-csfcal.rules), so no root is
# needed to use them; only where udev runs (not in containers or CI without it).
if [ -d /etc/udev/rules.d ] && command -v udevadm >/dev/null 2>&1; then
  SUDO=""
  [ "$(id -u)" -eq 0 ] || SUDO="sudo"
  if ! cmp -s data/udev/70-csfcal.rules /etc/udev/rules.d/70-csfcal.rules; then
    $SUDO install -m 0644 data/udev/70-csfcal.rules /etc/udev/rules.d/70-csfcal.rules
    $SUDO udevadm control --reload >/dev/null 2>&1 || true
    $SUDO udevadm trigger --action=change --subsystem-match=usb --subsystem-match=hidraw >/dev/null 2>&1 || true
    echo "setup: installed /etc/udev/rules.d/70-csfcal.rules (re-plug photometers and button boxes)"
  fi
else
  echo "setup: no udev here: data/udev/70-csfcal.rules not installed (see docs/instruments.md)"
fi

# Release build for users; the test build (sanitizers, warnings as errors) lives in build-test.
[ -f build/build.ninja ] || meson setup build --buildtype=release >/dev/null
if ! ninja -C build > build/setup-build.log 2>&1; then
  tail -n 40 build/setup-build.log; echo "setup: build failed (full log: build/setup-build.log)"; exit 1
fi
echo "setup: built build/cli/csfcal"
