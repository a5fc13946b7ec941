#!/bin/sh
# `csfcal devices --json` against a fake /sys and /dev (CSFCAL_DEVICES_ROOT): a ColorCAL MkII with
# cdc_acm bound, a ColorHug2 another program holds, a HID button box, a USB keyboard, an FTDI serial
# port and the ColorCAL's own tty, a gamepad's event node. As root every node opens; as an
# unprivileged user (setpriv) the 0600 nodes are reported unusable with the reason. spotread is
# found on PATH, or reported missing. The JSON is read back with python3's json module.
set -u
exe="$1"
rules="$2"
fail=0
t=$(mktemp -d)
trap 'rm -rf "$t"' EXIT
S="$t/sys/bus/usb/devices"
mkdir -p "$S" "$t/sys/bus/usb/drivers/cdc_acm" "$t/sys/bus/usb/drivers/usbfs" "$t/sys/bus/usb/drivers/usbhid" \
  "$t/sys/class/tty" "$t/dev/bus/usb/001" "$t/dev/input/by-id"
usbdev() { # name vid pid devnum product iface-class iface-proto driver mode
  d="$S/$1"; mkdir -p "$d/$1:1.0"
  printf '%s\n' "$2" >"$d/idVendor"; printf '%s\n' "$3" >"$d/idProduct"
  echo 1 >"$d/busnum"; echo "$4" >"$d/devnum"; printf '%s\n' "$5" >"$d/product"
  printf '%s\n' "$6" >"$d/$1:1.0/bInterfaceClass"; printf '%s\n' "$7" >"$d/$1:1.0/bInterfaceProtocol"
  [ -n "$8" ] && ln -s "../../../drivers/$8" "$d/$1:1.0/driver"
  n=$(printf '%s/dev/bus/usb/001/%03d' "$t" "$4"); : >"$n"; chmod "$9" "$n"
}
usbdev 1-1 0861 1001 5 "ColorCAL MkII" 02 00 cdc_acm 600
usbdev 1-2 273f 1004 6 "ColorHug2" 03 00 usbfs 666
usbdev 1-3 1b4f 9206 7 "Button Box" 03 00 usbhid 666
usbdev 1-4 046d c31c 8 "USB Keyboard" 03 01 usbhid 600
usbdev 1-5 0403 6001 9 "FT232R USB UART" ff 00 "" 666
mkdir -p "$S/1-5/1-5:1.0/ttyUSB0" "$t/sys/class/tty/ttyUSB0" "$t/sys/class/tty/ttyACM0"
ln -s ../../../bus/usb/devices/1-5/1-5:1.0/ttyUSB0 "$t/sys/class/tty/ttyUSB0/device"
ln -s ../../../bus/usb/devices/1-1/1-1:1.0 "$t/sys/class/tty/ttyACM0/device"
: >"$t/dev/ttyUSB0"; chmod 600 "$t/dev/ttyUSB0"; : >"$t/dev/ttyACM0"
: >"$t/dev/input/event3"; chmod 600 "$t/dev/input/event3"
ln -s ../event3 "$t/dev/input/by-id/usb-Logitech_Gamepad_F310-event-joystick"
chmod -R a+rX "$t"
chmod 600 "$t/dev/input/event3" "$t/dev/ttyUSB0" "$t/dev/bus/usb/001/005" "$t/dev/bus/usb/001/008"

check() { # label python-assertions (d = the list, by = name -> entry)
  python3 -c '
import json, sys
d = json.load(open(sys.argv[1]))
assert isinstance(d, list) and d, "not a non-empty array"
for x in d:
    for k in ("kind", "name", "spec", "status", "detail"):
        assert isinstance(x.get(k), str), (k, x)
    assert x["status"] in ("ok", "simulated", "unusable"), x
    assert (x["status"] == "unusable") == bool(x.get("why")), ("unusable entries say why", x)
by = {x["name"]: x for x in d}
'"$2" "$t/out.json" || { echo "FAIL: $1"; cat "$t/out.json"; fail=1; return; }
  echo "ok: $1"
}

CSFCAL_DEVICES_ROOT="$t" "$exe" devices --json --headless >"$t/out.json" || { echo "FAIL: devices --json"; fail=1; }
check "root: devices and their specs" '
cc = by["CRS ColorCAL MkII"]
assert cc["status"] == "ok" and cc["spec"] == "colorcal2" and cc["vid"] == 0x0861 and cc["pid"] == 0x1001, cc
assert "cdc_acm" in cc["detail"] and cc["path"] == "/dev/bus/usb/001/005", cc
ch = by["Hughski ColorHug2"]
assert ch["status"] == "unusable" and "another program holds it" in ch["why"], ch
box = by["Button Box"]
assert box["kind"] == "responder" and box["spec"] == "hid:1b4f:9206" and box["status"] == "ok", box
assert by["USB Keyboard"]["spec"] == "keyboard", by["USB Keyboard"]
ser = [x for x in d if x["name"].startswith("serial port /dev/ttyUSB0")][0]
assert ser["status"] == "ok" and "ls100:/dev/ttyUSB0" in ser["spec"] and ser["vid"] == 0x0403, ser
acm = [x for x in d if x["name"] == "serial port /dev/ttyACM0"][0]
assert acm["spec"] == "colorcal2", acm
pad = by["usb-Logitech_Gamepad_F310"]
assert pad["kind"] == "responder" and pad["status"] == "ok", pad
assert by["simulated photometer"]["status"] == "simulated"
' 
if command -v spotread >/dev/null 2>&1; then have=1; else have=0; fi
python3 - "$t/out.json" "$have" <<'PY' || { echo "FAIL: spotread on PATH is found"; fail=1; }
import json, sys
sp = [x for x in json.load(open(sys.argv[1])) if x["name"] == "ArgyllCMS spotread"][0]
assert (sp["status"] == "ok") == (sys.argv[2] == "1"), sp
PY
# no spotread on PATH: named as the reason
PATH=/nonexistent CSFCAL_DEVICES_ROOT="$t" "$exe" devices --json --headless >"$t/out.json" 2>/dev/null
check "no spotread on PATH" '
sp = by["ArgyllCMS spotread"]
assert sp["status"] == "unusable" and "no spotread on PATH" in sp["why"] and "argyll" in sp["why"], sp
'
# an unprivileged user: the 0600 nodes are not accessible, and the reason names the fix
if [ "$(id -u)" -eq 0 ] && command -v setpriv >/dev/null 2>&1; then
  env HOME="$t" XDG_CONFIG_HOME="$t/cfg" CSFCAL_DEVICES_ROOT="$t" setpriv --reuid=65534 --regid=65534 --clear-groups "$exe" devices --json --headless \
    >"$t/out.json" 2>"$t/err" || { echo "FAIL: devices as nobody: $(cat "$t/err")"; fail=1; }
  check "unprivileged: permission problems named" '
cc = by["CRS ColorCAL MkII"]
assert cc["status"] == "unusable" and "permission denied" in cc["why"] and "udev" in cc["why"], cc
ser = [x for x in d if x["name"].startswith("serial port /dev/ttyUSB0")][0]
assert ser["status"] == "unusable" and "dialout" in ser["why"], ser
pad = by["usb-Logitech_Gamepad_F310"]
assert pad["status"] == "unusable" and "uaccess" in pad["why"], pad
assert by["Button Box"]["status"] == "ok"
'
else
  echo "SKIP (part): not root or no setpriv: the unprivileged listing was not checked"
fi
# the shipped udev rules cover the USB photometers csfcal recognises (what the fake tree holds)
for id in 0861:1001 273f:1004 273f:1001; do
  v=${id%:*}; p=${id#*:}
  grep -Eq "^SUBSYSTEM==\"usb\", ATTRS\{idVendor\}==\"$v\", ATTRS\{idProduct\}==\"$p\", TAG\+=\"uaccess\"" "$rules" \
    || { echo "FAIL: $rules has no uaccess rule for $id"; fail=1; }
done
# observer calibrate refuses a bad responder spec before the first trial (exit 2, names it)
for spec in "hid:zz:1" "gamepad:99" "hid:1b4f:9206,map=jump:1" "joystick"; do
  "$exe" observer calibrate --headless --observer sim --out "$t/x.csflut" --store "$t/s.sqlite" \
    --responder "$spec" >/dev/null 2>"$t/err"
  rc=$?
  { [ $rc -eq 2 ] && grep -q "responder" "$t/err"; } || { echo "FAIL: --responder $spec: exit $rc: $(cat "$t/err")"; fail=1; }
  [ -e "$t/x.csflut" ] && { echo "FAIL: --responder $spec: a table was written"; fail=1; }
done
"$exe" observer calibrate --headless --observer sim --out "$t/x.csflut" --store "$t/s.sqlite" \
  --set responder=hid:1b4f >/dev/null 2>"$t/err"
[ $? -eq 2 ] || { echo "FAIL: --set responder=hid:1b4f accepted"; fail=1; }
# the table says why too
CSFCAL_DEVICES_ROOT="$t" "$exe" devices --headless >"$t/out.txt"
grep -q "why: another program holds it" "$t/out.txt" || { echo "FAIL: table without why"; cat "$t/out.txt"; fail=1; }
exit $fail
