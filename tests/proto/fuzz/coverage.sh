#!/bin/sh
# Source coverage of the firmware proto files reached by a fuzz corpus.
# usage: coverage.sh OUTDIR [CLANG]   (OUTDIR as given to run_fuzz.sh, with corpus_*)
set -eu
OUT=$1
CLANG=${2:-clang-14}
V=$(echo "$CLANG" | sed -n 's/.*clang\(-[0-9]*\)$/\1/p')
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
FW=$ROOT/firmware
F="-std=c11 -O0 -g -fsanitize=fuzzer -fprofile-instr-generate -fcoverage-mapping -I$FW -I$ROOT/control -I$HERE/.."
# shellcheck disable=SC2086
$CLANG $F -o "$OUT/cov_cmd" "$HERE/fuzz_cmd.c" "$HERE/../cmd_mock.c" $FW/cmd.c $FW/cmd_num.c \
  $FW/telemetry.c $FW/telemetry_frame.c
# shellcheck disable=SC2086
$CLANG $F -o "$OUT/cov_tel" "$HERE/fuzz_tel.c" $FW/telemetry_frame.c
cd "$OUT"
LLVM_PROFILE_FILE=cmd.profraw ./cov_cmd -runs=0 corpus_cmd >/dev/null 2>&1
LLVM_PROFILE_FILE=tel.profraw ./cov_tel -runs=0 corpus_tel >/dev/null 2>&1
llvm-profdata$V merge -o cmd.profdata cmd.profraw
llvm-profdata$V merge -o tel.profdata tel.profraw
echo "== fuzz_cmd corpus"
llvm-cov$V report ./cov_cmd -instr-profile=cmd.profdata $FW/cmd.c $FW/cmd_num.c
echo "== fuzz_tel corpus"
llvm-cov$V report ./cov_tel -instr-profile=tel.profdata $FW/telemetry_frame.c
