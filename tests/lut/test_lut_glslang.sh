#!/bin/sh
# The GLSL export passes Khronos' reference compiler, glslangValidator, as a GLSL 3.30 core,
# GLSL ES 3.00 and GLSL 4.50 fragment shader, included right after #version with nothing before
# it (an ES fragment shader has no default float precision: the export sets highp itself, under
# #ifdef GL_ES), with no error and no warning, for a 2-D table and for one with a velocity axis
# (PREFIX_threshold3); the numbers themselves are checked on a GPU driver by test_lut_glsl.
set -eu
CSFCAL=$1
EX=$2/example_default_observer.csflut
command -v glslangValidator >/dev/null || { echo "FAIL: glslangValidator missing (scripts/setup.sh installs glslang-tools)"; exit 1; }
T=$(mktemp -d /tmp/csflut-glslang-XXXXXX)
trap 'rm -rf "$T"' EXIT
"$CSFCAL" lut export "$EX" --format glsl --prefix lut -o "$T/lut.glsl"
"$CSFCAL" lut export "$EX" --format glsl --prefix lut_raw --raw -o "$T/lut_raw.glsl"
BODY='
out vec4 colour;
uniform vec3 q; /* freq_cpd, ecc_deg, contrast */
void main()
{
    float t = lut_threshold(q.x, q.y) + lut_raw_threshold(q.x, q.y);
    colour = vec4(t, lut_perceptible(q.x, q.y, q.z) ? 1.0 : 0.0, 0.0, 1.0);
}'
# shader VERSION EXPORT... > file: the exports straight after #version, then the body
shader() {
    v=$1; shift
    echo "#version $v"
    cat "$@"
    echo "$BODY"
}
for v in "330 core" "300 es" "450 core"; do
    f="$T/v$(echo "$v" | tr -d ' ').frag"
    shader "$v" "$T/lut.glsl" "$T/lut_raw.glsl" >"$f"
    if ! glslangValidator "$f" >"$T/log" 2>&1; then
        echo "FAIL: glslangValidator refuses the export as GLSL $v:"; cat "$T/log"; exit 1
    fi
    if grep -q 'WARNING' "$T/log"; then
        echo "FAIL: glslangValidator warns about the export as GLSL $v:"; cat "$T/log"; exit 1
    fi
    echo "GLSL $v: ok"
done
# the precision statements are guarded, so desktop GLSL never sees them
grep -q '^#ifdef GL_ES$' "$T/lut.glsl" && grep -q '^precision highp float;$' "$T/lut.glsl" \
    || { echo "FAIL: no guarded precision statement in the export"; exit 1; }
# and they are what makes the ES shader compile: without them the validator refuses it (so the
# ES check above can fail)
for g in lut lut_raw; do
    awk '/^#ifdef GL_ES$/ {skip = 1} !skip {print} skip && /^#endif$/ {skip = 0}' "$T/$g.glsl" >"$T/$g.noprec.glsl"
done
shader "300 es" "$T/lut.noprec.glsl" "$T/lut_raw.noprec.glsl" >"$T/noprec.frag"
if glslangValidator "$T/noprec.frag" >"$T/log" 2>&1; then echo "FAIL: an ES shader without precision passed"; exit 1; fi
grep -q 'precision' "$T/log" || { echo "FAIL: the ES shader without precision failed for another reason:"; cat "$T/log"; exit 1; }
echo "ES 3.00 without the export's precision statements: refused (as it must be)"
# the validator does refuse a broken export (the check can fail)
sed 's/float r = mix(r0, r1, we);/float r = mix(r0, r1, we)/' "$T/lut.glsl" >"$T/bad.glsl"
shader "330 core" "$T/bad.glsl" "$T/lut_raw.glsl" >"$T/bad.frag"
if glslangValidator "$T/bad.frag" >/dev/null 2>&1; then echo "FAIL: a broken shader passed"; exit 1; fi
# prefixes GLSL refuses ("gl_") or reserves ("__") are refused at export; the validator agrees
# that they would be wrong: an error for gl_, a warning for __
sed 's/lut_/gl_x_/g' "$T/lut.glsl" >"$T/gl.glsl"
{ echo "#version 330 core"; cat "$T/gl.glsl"; echo 'out vec4 o; void main() { o = vec4(gl_x_threshold(1.0, 0.0)); }'; } >"$T/gl.frag"
if glslangValidator "$T/gl.frag" >"$T/log" 2>&1; then echo "FAIL: gl_ names passed the validator"; exit 1; fi
sed 's/lut_/a__b_/g' "$T/lut.glsl" >"$T/us.glsl"
{ echo "#version 330 core"; cat "$T/us.glsl"; echo 'out vec4 o; void main() { o = vec4(a__b_threshold(1.0, 0.0)); }'; } >"$T/us.frag"
glslangValidator "$T/us.frag" >"$T/log" 2>&1 || true
grep -q 'WARNING.*__' "$T/log" || { echo "FAIL: the validator did not flag __ names:"; cat "$T/log"; exit 1; }
for p in gl_x a__b; do
    if "$CSFCAL" lut export "$EX" --format glsl --prefix "$p" -o "$T/refused.glsl" >"$T/err" 2>&1; then
        echo "FAIL: --prefix $p accepted"; exit 1
    fi
    [ ! -e "$T/refused.glsl" ] || { echo "FAIL: --prefix $p wrote a file"; exit 1; }
done
# a table with a velocity axis: PREFIX_threshold3 and PREFIX_perceptible3 pass too, beside the
# 2-D functions of the same export
{ echo "freq_cpd,ecc_deg,velocity_dps,threshold"
  for v in 0 2 8; do for e in 0 10; do for f in 1 4 16; do echo "$f,$e,$v,0.0$f$v"; done; done; done; } >"$T/v.csv"
"$CSFCAL" lut import "$T/v.csv" -o "$T/v.csflut" >/dev/null
"$CSFCAL" lut export "$T/v.csflut" --format glsl --prefix lut3 -o "$T/lut3.glsl"
for v in "330 core" "300 es" "450 core"; do
    { echo "#version $v"; cat "$T/lut3.glsl"
      echo 'out vec4 colour; uniform vec4 q; /* freq_cpd, ecc_deg, vel_dps, contrast */'
      echo 'void main() { colour = vec4(lut3_threshold3(q.x, q.y, q.z) + lut3_threshold(q.x, q.y),'
      echo '    lut3_perceptible3(q.x, q.y, q.z, q.w) ? 1.0 : 0.0, 0.0, 1.0); }'; } >"$T/v.frag"
    if ! glslangValidator "$T/v.frag" >"$T/log" 2>&1 || grep -q WARNING "$T/log"; then
        echo "FAIL: glslangValidator on the velocity export as GLSL $v:"; cat "$T/log"; exit 1
    fi
    echo "GLSL $v, velocity axis: ok"
done
echo ok
