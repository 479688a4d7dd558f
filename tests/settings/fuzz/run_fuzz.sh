#!/bin/sh
# Build the settings loader's libFuzzer target with clang and run it for SECONDS.
# usage: run_fuzz.sh OUTDIR [CLANG] [SECONDS] [extra libFuzzer args...]
# Seeds: valid records (tests/settings/settings_gen.h). Single process. Exit
# status non-zero on a crash or a violated invariant (reproducer in OUTDIR).
set -eu
OUT=$1
CLANG=${2:-clang}
SECS=${3:-15}
shift 3 2>/dev/null || shift $#
HERE=$(cd "$(dirname "$0")" && pwd)
ROOT=$(cd "$HERE/../../.." && pwd)
SET=$ROOT/firmware/settings
mkdir -p "$OUT/corpus"
CFLAGS="-std=c11 -g -O1 -fno-sanitize-recover=all -Wall -Wextra -Werror -I$SET -I$HERE/.."
SRC="$SET/settings.c $SET/settings_store.c $SET/settings_flash_model.c"
# shellcheck disable=SC2086
$CLANG $CFLAGS -fsanitize=fuzzer,address,undefined -o "$OUT/fuzz_settings" "$HERE/fuzz_settings.c" $SRC
# shellcheck disable=SC2086
$CLANG $CFLAGS -o "$OUT/seed_gen" "$HERE/seed_gen.c" $SRC
"$OUT/seed_gen" "$OUT/corpus"
cd "$OUT"
./fuzz_settings -max_total_time="$SECS" -max_len=1200 -print_final_stats=1 \
  -artifact_prefix="$OUT/settings-" "$@" corpus
