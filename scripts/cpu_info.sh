#!/usr/bin/env bash
# The CPU this machine runs on, as far as the suite's results depend on it (issue 36,
# docs/reliability.md "Tests that depend on the CPU"). Plain bash over /proc/cpuinfo, so that
# .ci/run can print it before anything is installed.
#   bash scripts/cpu_info.sh          one line: model, vendor, cores, the SIMD flags that matter,
#                                     and the path glibc's libm takes
#   bash scripts/cpu_info.sh --libm   only that path: fma, fma4 or generic
#
# glibc 2.36 (Debian 12) runs exp, log, pow, sin, cos, tan and atan through their FMA variants
# (__exp_fma, ...) when the CPU has both FMA and AVX2, through the FMA4 ones on AMD's pre-Zen
# CPUs, and through the generic code otherwise; the variants agree to an ulp, not bit for bit.
# Highway's lanes fuse a*b+c on AVX2 and AVX-512 targets and not on SSE4. The committed
# calibration and its references were made on the "fma" path (Intel Xeon and AMD EPYC, both
# with AVX-512): the checks that compare with them to 1e-14 skip, with this reason, elsewhere.
set -euo pipefail
info=/proc/cpuinfo
if [[ ! -r $info ]]; then
  [[ ${1:-} == --libm ]] && { echo unknown; exit 0; }
  echo "cpu: unknown ($info not readable), $(uname -m)"
  exit 0
fi
field() { { grep -m1 "^$1[[:space:]]*:" "$info" || true; } | cut -d: -f2- | sed 's/^ *//'; }
flags=" $(field flags) "
has() { [[ $flags == *" $1 "* ]]; }
if has fma && has avx2; then libm=fma
elif has fma4; then libm=fma4
else libm=generic; fi
if [[ ${1:-} == --libm ]]; then echo "$libm"; exit 0; fi
[[ $# -eq 0 ]] || { echo "cpu_info.sh: unknown option $1 (expected --libm)" >&2; exit 1; }
simd=""
for f in avx512f avx2 fma sse4_2; do has "$f" && simd+="$f "; done
echo "cpu: $(field 'model name') ($(field vendor_id), family $(field 'cpu family') model $(field model)," \
  "$(grep -c '^processor' "$info" || true) cores, $(uname -m)); SIMD flags: ${simd% }; glibc libm path: $libm"
