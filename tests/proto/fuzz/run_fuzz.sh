#!/bin/sh
# Build the proto libFuzzer targets with clang and run each for SECONDS.
# usage: run_fuzz.sh OUTDIR [CLANG] [SECONDS] [extra libFuzzer args...]
# Single process, single core (no -jobs/-workers). Exit status non-zero on a
# crash or a violated invariant (the reproducer is left in OUTDIR).
set -eu
OUT=$1
CLANG=${2:-clang}
SECS=${3:-15}
shift 3 2>/dev/null || shift $#
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
FW=$ROOT/firmware/protocol
# The core's include path: every folder of control/.
CTRL_INC=$(for d in "$ROOT"/control/*/; do printf -- ' -I%s' "${d%/}"; done)
mkdir -p "$OUT"
CFLAGS="-std=c11 -g -O1 -fsanitize=fuzzer,address,undefined -fno-sanitize-recover=all
        -Wall -Wextra -Werror -I$FW $CTRL_INC -I$HERE/.."
SRC="$FW/cmd.c $FW/cmd_num.c $FW/telemetry.c $FW/telemetry_frame.c"
# shellcheck disable=SC2086
$CLANG $CFLAGS -o "$OUT/fuzz_cmd" "$HERE/fuzz_cmd.c" "$HERE/../cmd_mock.c" $SRC
# shellcheck disable=SC2086
$CLANG $CFLAGS -o "$OUT/fuzz_tel" "$HERE/fuzz_tel.c" $FW/telemetry_frame.c

# Seeds: command lines, and a recorded stream from the C encoder.
mkdir -p "$OUT/corpus_cmd" "$OUT/corpus_tel"
i=0
while IFS= read -r line; do
  i=$((i + 1))
  printf '\000%s\r\n' "$line" > "$OUT/corpus_cmd/seed$i"
done < "$HERE/cmd_seeds.txt"
# shellcheck disable=SC2086
$CLANG -std=c11 -O1 -I$FW $CTRL_INC -o "$OUT/stream_gen" "$HERE/../stream_gen.c" \
  $FW/telemetry.c $FW/telemetry_frame.c
"$OUT/stream_gen" "$OUT/corpus_tel/stream.bin" "$OUT/stream_expect.txt"
head -c 600 "$OUT/corpus_tel/stream.bin" > "$OUT/corpus_tel/stream_head.bin"

cd "$OUT"
rc=0
./fuzz_cmd -max_total_time="$SECS" -max_len=512 -dict="$HERE/cmd.dict" -print_final_stats=1 \
  -artifact_prefix="$OUT/cmd-" "$@" corpus_cmd || rc=1
./fuzz_tel -max_total_time="$SECS" -max_len=1024 -print_final_stats=1 \
  -artifact_prefix="$OUT/tel-" "$@" corpus_tel || rc=1
exit $rc
