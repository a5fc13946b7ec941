#!/usr/bin/env python3
"""The display exports read back by other people's tools, compared with the profile's numbers.

OpenColorIO: ociocheck validates the exported config; ociobakelut bakes the config's display
transform and ociochecklut evaluates that bake and the clf, ctf and cube exports (forward, and the
clf inverted as a renderer uses it). Little CMS: transicc transforms device grey to PCS XYZ through
the ICC v2.4 and v4.3 exports. ArgyllCMS 2.3.1: iccdump and xicclu read the v2.4 export (Argyll
refuses v4: noted, not failed, and checked instead if a later Argyll reads it). Every check
includes drive 0, so the black level is compared too. Last, on a small tmpfs (when one can be
mounted in a private mount namespace) every format is exported onto a full disk: the command must
fail naming "No space left on device" and leave the old files intact and nothing else.

usage: test_colour_thirdparty.py CSFCAL PROFILE_EVAL
"""
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

CSFCAL, PROFILE_EVAL = os.path.abspath(sys.argv[1]), os.path.abspath(sys.argv[2])
TOOLS = ["ociocheck", "ociochecklut", "ociobakelut", "transicc", "iccdump", "xicclu"]
# not on the 4096-sample grid, plus black and white
DRIVES = [0.0, 0.02, 0.1, 0.2371, 0.3333, 0.41, 0.5, 0.618, 0.75, 0.9001, 0.97, 1.0]

failures = []


def check(cond, msg):
    if not cond:
        failures.append(msg)
        print("FAIL: " + msg)
    return cond


def run(args, stdin=None, ok=True):
    r = subprocess.run(args, input=stdin, capture_output=True, text=True)
    if ok and r.returncode != 0:
        check(False, "%s exited %d: %s%s" % (" ".join(args), r.returncode, r.stdout[-600:], r.stderr[-600:]))
    return r


def floats(text):
    return [float(x) for x in re.findall(r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?", text)]


def compare(name, got_y, white, black, lum, rel_tol, abs_tol):
    """got_y[i]: luminance relative to white read by a tool at DRIVES[i]. Above 10 % of white the
    relative error must be <= rel_tol; everywhere (black included) |error| <= abs_tol of white."""
    worst_rel = worst_abs = 0.0
    for d, y, L in zip(DRIVES, got_y, lum):
        want = L / white
        e_abs = abs(y - want)
        worst_abs = max(worst_abs, e_abs)
        if L >= 0.1 * white:
            worst_rel = max(worst_rel, e_abs / want)
    print("%-28s rel above 10%% %.3g (tol %.3g), abs %.3g of white (tol %.3g); black %.6g cd/m2 (profile %.6g)"
          % (name, worst_rel, rel_tol, worst_abs, abs_tol, got_y[0] * white, black))
    check(worst_rel <= rel_tol, "%s: relative error %.3g above 10 %% of white > %.3g" % (name, worst_rel, rel_tol))
    check(worst_abs <= abs_tol, "%s: error %.3g of white > %.3g (black %.6g cd/m2, profile %.6g)"
          % (name, worst_abs, abs_tol, got_y[0] * white, black))


def ociochecklut(path, values, inverse=False):
    out = []
    for v in values:
        args = ["ociochecklut"] + (["--inv"] if inverse else []) + [path, repr(v), repr(v), repr(v)]
        r = run(args)
        f = floats(r.stdout)
        if not check(len(f) == 3 and f[0] == f[1] == f[2], "ociochecklut %s %r: %r" % (path, v, r.stdout)):
            return None
        out.append(f[1])
    return out


def icc_header_and_lumi(path):
    """Version and luminance tag read from the bytes (ICC.1 7.2, 7.3, 10.31): Argyll refuses v4."""
    b = open(path, "rb").read()
    version = struct.unpack(">I", b[8:12])[0]
    n = struct.unpack(">I", b[128:132])[0]
    for i in range(n):
        sig, off, size = struct.unpack(">4sII", b[132 + 12 * i:144 + 12 * i])
        if sig == b"lumi":
            return version, struct.unpack(">i", b[off + 12:off + 16])[0] / 65536.0
    return version, None


def check_ocio(t, white, black, lum):
    for fmt in ["clf", "ctf", "cube", "ocio"]:
        run([CSFCAL, "display", "export", t + "/lcd.profile", "--format", fmt, "-o", "%s/disp.%s" % (t, fmt)])
    # clf/ctf: float32 samples, 4096 of them, printed to 7 digits: <= 1e-6 relative above 10 %
    for fmt in ["clf", "ctf"]:
        y = ociochecklut("%s/disp.%s" % (t, fmt), DRIVES)
        if y:
            compare("ociochecklut " + fmt, y, white, black, lum, 1e-6, 1e-6)
    # the inverse a renderer applies: drive for a wanted luminance, back to the drive it came from
    want = [L / white for d, L in zip(DRIVES, lum) if L >= 0.1 * white]
    d_in = [d for d, L in zip(DRIVES, lum) if L >= 0.1 * white]
    d_got = ociochecklut(t + "/disp.clf", want, inverse=True)
    if d_got:
        worst = max(abs(a - b) for a, b in zip(d_got, d_in))
        print("%-28s drive error %.3g (tol 1e-6)" % ("ociochecklut --inv clf", worst))
        check(worst <= 1e-6, "inverse clf: drive off by %.3g" % worst)
    # .cube: the Resolve baker writes 6 decimals (+-5e-7 of white) and ociochecklut prints 6
    # significant digits (+-5e-7 more): 1.5e-6 of white everywhere, 1.5e-5 relative at 10 %
    y = ociochecklut(t + "/disp.cube", DRIVES)
    if y:
        compare("ociochecklut cube", y, white, black, lum, 1.5e-5, 1.5e-6)
    # the config: validated by ociocheck, its display transform baked by ociobakelut
    r = run(["ociocheck", "--iconfig", t + "/disp.ocio"])
    check("** Validation **\npassed" in r.stdout and "ERROR" not in r.stdout,
          "ociocheck did not pass the config: " + r.stdout[-800:] + r.stderr[-400:])
    run(["ociobakelut", "--iconfig", t + "/disp.ocio", "--inputspace", "csfcal_display", "--outputspace", "linear",
         "--format", "resolve_cube", t + "/baked.cube"])
    y = ociochecklut(t + "/baked.cube", DRIVES)
    if y:
        compare("ociobakelut config", y, white, black, lum, 1.5e-5, 1.5e-6)


# ICC TRC: a 16-bit curv; Little CMS quantises the input to 16 bits too. One step is 1/65535 of
# white, so at 10 % of white input + output rounding reach 1.3e-4 (docs/display-profile.md,
# measured 1.2e-4); transicc prints 4 decimals of Y in 0..100 (5e-6 at 10 %).
ICC_REL_TOL = 1.5e-4
ICC_ABS_TOL = 3e-5  # of white: output step + input step on the steepest part of the curve
# v4 also has float D2B/B2D tags, which Little CMS uses: only transicc's 4 printed decimals remain
ICC4_LCMS_REL_TOL = 1e-5
ICC4_LCMS_ABS_TOL = 1e-6


def check_icc(t, version, white, black, lum):
    path = "%s/v%d.icc" % (t, version)
    run([CSFCAL, "display", "export", t + "/lcd.profile", "--format", "icc", "--icc-version", str(version), "-o", path])
    enc, lumi = icc_header_and_lumi(path)
    check(enc == (0x02400000 if version == 2 else 0x04300000), "v%d: header version 0x%08x" % (version, enc))
    if not check(lumi is not None, "v%d: no luminance tag" % version):
        return
    check(abs(lumi / white - 1) < 1e-6, "v%d: luminance tag %.6f cd/m2, white %.6f" % (version, lumi, white))
    # Little CMS: device grey (0..255 scale on input) -> PCS XYZ (Y 0..100), relative colorimetric
    stdin = "".join("%.9f %.9f %.9f\n" % (d * 255, d * 255, d * 255) for d in DRIVES)
    r = run(["transicc", "-t1", "-i", path, "-o", "*XYZ", "-n"], stdin=stdin)
    rows = [floats(line) for line in r.stdout.splitlines() if len(floats(line)) == 3]
    if check(len(rows) == len(DRIVES), "transicc v%d gave %d rows: %s" % (version, len(rows), r.stdout[-400:])):
        compare("transicc v%d (cd/m2 = Y lumi)" % version, [row[1] / 100 * lumi / white for row in rows],
                white, black, lum, ICC_REL_TOL if version == 2 else ICC4_LCMS_REL_TOL,
                ICC_ABS_TOL if version == 2 else ICC4_LCMS_ABS_TOL)
    # ArgyllCMS
    r = run(["iccdump", "-v3", "-t", "lumi", path], ok=False)
    if version == 4 and r.returncode != 0:
        refused = "V4 not supported" in r.stdout + r.stderr
        check(refused, "iccdump v4 failed for another reason: " + r.stdout + r.stderr)
        print("ArgyllCMS %s on v4: refused ('ICC V4 not supported'); Argyll checks run on v2"
              % ("iccdump", ))
        return
    check(r.returncode == 0, "iccdump v%d: %s" % (version, r.stdout + r.stderr))
    f = floats(r.stdout.split("0:")[-1]) if "0:" in r.stdout else []
    check(len(f) >= 3 and abs(f[1] / white - 1) < 1e-6, "iccdump lumi v%d: %r" % (version, r.stdout))
    if version == 2:
        r = run(["iccdump", "-v3", "-t", "bkpt", path])
        f = floats(r.stdout.split("0:")[-1]) if "0:" in r.stdout else []
        if check(len(f) >= 3, "iccdump bkpt: %r" % r.stdout):
            print("%-28s bkpt Y %.8f -> %.6f cd/m2 (profile %.6f)" % ("iccdump v2", f[1], f[1] * lumi, black))
            check(abs(f[1] * lumi - black) <= white / 65536, "bkpt Y %.8f: black %.6f cd/m2 vs %.6f"
                  % (f[1], f[1] * lumi, black))
    for intent in ["r", "a"]:
        stdin = "".join("%.9f %.9f %.9f\n" % (d, d, d) for d in DRIVES)
        r = run(["xicclu", "-v0", "-ff", "-i" + intent, "-pX", path], stdin=stdin)
        rows = [floats(line) for line in r.stdout.splitlines() if len(floats(line)) >= 3]
        if check(len(rows) == len(DRIVES), "xicclu v%d -i%s gave %r" % (version, intent, r.stdout[-400:])):
            compare("xicclu -i%s v%d" % (intent, version), [row[1] / 100 * lumi / white for row in rows],
                    white, black, lum, ICC_REL_TOL, ICC_ABS_TOL)


def check_full_disk(t):
    """Every format onto a full tmpfs: fails with the OS error, old files intact, nothing added."""
    mnt = t + "/small"
    os.mkdir(mnt)
    script = r'''
set -u
mount -t tmpfs -o size=64k tmpfs "$1" || exit 77
cd "$1"
for f in clf ctf cube icc; do echo old > disp.$f; done
echo oldlut > cfg.clf; echo old > cfg.ocio
head -c 40000 /dev/zero > filler 2>/dev/null
head -c 1000000 /dev/zero >> filler 2>/dev/null
for f in clf ctf cube icc; do
  "$2" display export "$3" --format $f -o disp.$f 2>&1 && echo "EXPORT-OK $f"
done
"$2" display export "$3" --format ocio -o cfg.ocio 2>&1 && echo "EXPORT-OK ocio"
echo "FILES:" *
for f in disp.clf disp.ctf disp.cube disp.icc cfg.ocio; do echo "$f=$(cat $f)"; done
echo "cfg.clf=$(cat cfg.clf)"
'''
    for prefix in (["unshare", "-m"], ["unshare", "-rm"]):
        r = subprocess.run(prefix + ["sh", "-c", script, "sh", mnt, CSFCAL, t + "/lcd.profile"],
                           capture_output=True, text=True)
        if r.returncode != 77 and "FILES:" in r.stdout:
            break
    else:
        print("full-disk check skipped: no tmpfs can be mounted here (%s); "
              "test_colour_export covers it with RLIMIT_FSIZE" % (r.stderr.strip()[-200:]))
        return
    out = r.stdout
    print("full tmpfs:\n  " + "\n  ".join(out.strip().splitlines()))
    check("EXPORT-OK" not in out, "an export onto a full disk reported success")
    check(out.count("No space left on device") >= 5, "not every export names 'No space left on device'")
    files = out.split("FILES:")[1].splitlines()[0].split()
    check(sorted(files) == sorted(["disp.clf", "disp.ctf", "disp.cube", "disp.icc", "cfg.ocio", "cfg.clf", "filler"]),
          "files left on the full disk: %r" % files)
    for f in ["disp.clf", "disp.ctf", "disp.cube", "disp.icc", "cfg.ocio"]:
        check("%s=old\n" % f in out, "%s not left as it was" % f)
    check("cfg.clf=oldlut" in out, "the config's LUT not left as it was")


def main():
    missing = [x for x in TOOLS if not shutil.which(x)]
    if missing:
        print("missing %s: scripts/setup.sh installs opencolorio-tools, liblcms2-utils and argyll" % missing)
        return 1
    with tempfile.TemporaryDirectory(prefix="csfcal-thirdparty-") as t:
        run([CSFCAL, "display", "calibrate", "--photometer", "sim:display=lcd", "--no-render", "--seed", "1",
             "--store", t + "/s.db", "--out", t + "/lcd.profile", "--quiet"])
        r = run([PROFILE_EVAL, t + "/lcd.profile"] + [repr(d) for d in DRIVES])
        vals = floats(r.stdout)
        if not check(len(vals) == 2 + 2 * len(DRIVES), "profile_eval: %r" % r.stdout):
            return 1
        white, black = vals[0], vals[1]
        lum = vals[3::2]
        print("profile: white %.6f cd/m2, black %.6f cd/m2" % (white, black))
        check_ocio(t, white, black, lum)
        for version in (2, 4):
            check_icc(t, version, white, black, lum)
        check_full_disk(t)
        # bad --icc-version: exit 2, the option named, nothing written
        for args, text in ((["--format", "icc", "--icc-version", "3"], "--icc-version 3"),
                           (["--format", "icc", "--icc-version", "5"], "icc-version"),
                           (["--format", "clf", "--icc-version", "4"], "--format icc only")):
            r = run([CSFCAL, "display", "export", t + "/lcd.profile", "-o", t + "/bad.out"] + args, ok=False)
            check(r.returncode == 2 and text in r.stderr and not os.path.exists(t + "/bad.out"),
                  "%r: exit %d, %r" % (args, r.returncode, r.stderr))
    print("%d failure(s)" % len(failures))
    return 1 if failures else 0


sys.exit(main())
