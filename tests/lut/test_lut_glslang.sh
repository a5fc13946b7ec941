#!/bin/sh
# The GLSL export passes Khronos' reference compiler, glslangValidator, as GLSL 3.30 core,
# GLSL ES 3.00 and GLSL 4.50 (issue 10 item 4); the numbers themselves are checked on a GPU
# driver by test_lut_glsl.
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
for v in "330 core" "300 es" "450 core"; do
    f="$T/v$(echo "$v" | tr -d ' ').frag"
    {
        echo "#version $v"
        case $v in *es*) echo "precision highp float;";; esac
        cat "$T/lut.glsl" "$T/lut_raw.glsl"
        echo "$BODY"
    } >"$f"
    if ! glslangValidator "$f" >"$T/log" 2>&1; then
        echo "FAIL: glslangValidator refuses the export as GLSL $v:"; cat "$T/log"; exit 1
    fi
    echo "GLSL $v: ok"
done
# and the validator does refuse a broken export (the check can fail)
sed 's/float r = mix(r0, r1, we);/float r = mix(r0, r1, we)/' "$T/lut.glsl" >"$T/bad.glsl"
{ echo "#version 330 core"; cat "$T/bad.glsl" "$T/lut_raw.glsl"; echo "$BODY"; } >"$T/bad.frag"
if glslangValidator "$T/bad.frag" >/dev/null 2>&1; then echo "FAIL: a broken shader passed"; exit 1; fi
echo ok
