#!/usr/bin/env bash
# CLI error handling of the simulator: every bad input gives a non-zero exit
# and a message naming the problem; a good run exits 0 with the metrics.
# usage: cli_bad_input.sh SIM_BINARY MACHINES_DIR
set -u
sim="$1"
mdir="$2"
m="$mdir/thesis_spmsm.ini"
tmp="$(mktemp -d)"
trap 'rm -rf "$tmp"' EXIT
fails=0

# expect_fail "description" "regex of the message" args...
expect_fail() {
  local what="$1" pat="$2"
  shift 2
  local out rc
  out="$("$sim" "$@" 2>&1)"
  rc=$?
  if [ "$rc" -eq 0 ]; then
    echo "FAIL: $what: exit status 0"; fails=$((fails + 1)); return
  fi
  if [ "$rc" -gt 125 ]; then
    echo "FAIL: $what: crashed (status $rc): $out"; fails=$((fails + 1)); return
  fi
  if ! grep -Eq -e "$pat" <<<"$out"; then
    echo "FAIL: $what: message does not match /$pat/: $out"; fails=$((fails + 1)); return
  fi
  echo "ok: $what -> $(head -n1 <<<"$out")"
}

printf '[machine]\nname = broken\npole_pairs = four\n' >"$tmp/bad.ini"
printf 'at 0 torque_ref=1\nat 0.01 torque=2\n' >"$tmp/bad_key.scn"
printf 'at 0.02 torque_ref=1\nat 0.01 torque_ref=2\n' >"$tmp/bad_order.scn"
printf 'sometime torque_ref=1\n' >"$tmp/bad_trig.scn"

expect_fail "no arguments" "usage"
expect_fail "unknown option" "unknown option '--frobnicate'" --machine "$m" --frobnicate
expect_fail "missing machine" "--machine FILE is required" --controller bst
expect_fail "machine file missing" "machine file" --machine "$tmp/none.ini" --controller bst
expect_fail "machine file malformed" "machine file.*pole_pairs" --machine "$tmp/bad.ini" --controller bst
expect_fail "unknown controller" "unknown controller 'nosuch'" --machine "$m" --controller nosuch
expect_fail "missing controller" "--controller NAME is required" --machine "$m"
expect_fail "fs out of range" "--fs 10 is out of range" --machine "$m" --controller bst --fs 10
expect_fail "fs not a number" "--fs expects a number" --machine "$m" --controller bst --fs 20k
expect_fail "duration out of range" "--duration -1 is out of range" --machine "$m" --controller bst --duration -1
expect_fail "option without value" "needs a value" --machine "$m" --controller bst --duration
expect_fail "bad window" "--window" --machine "$m" --controller bst --duration 0.1 --window 0.2:0.1
expect_fail "window beyond duration" "--window" --machine "$m" --controller bst --duration 0.1 --window 0:0.5
expect_fail "seed not integer" "--seed expects an integer" --machine "$m" --controller bst --seed 1.5
expect_fail "both references" "either --torque-ref or --speed-ref-rpm" --machine "$m" --controller bst --torque-ref 1 --speed-ref-rpm 100
expect_fail "load without free" "--load-nm needs --free" --machine "$m" --controller bst --load-nm 1
expect_fail "unknown tunable" "no tunable 'nope'" --machine "$m" --controller bst --set nope=1
expect_fail "tunable out of range" "out of range: 'h_T=-5'" --machine "$m" --controller bst --set h_T=-5
expect_fail "tunable malformed" "--set expects NAME=VALUE" --machine "$m" --controller bst --set h_T
expect_fail "scenario missing" "cannot open scenario" --machine "$m" --controller bst --scenario "$tmp/none.scn"
expect_fail "scenario unknown key" "bad_key.scn:2: unknown key" --machine "$m" --controller bst --scenario "$tmp/bad_key.scn"
expect_fail "scenario time order" "bad_order.scn:2: times must not decrease" --machine "$m" --controller bst --scenario "$tmp/bad_order.scn"
expect_fail "scenario bad trigger" "bad_trig.scn:1: expected 'at' or 'when'" --machine "$m" --controller bst --scenario "$tmp/bad_trig.scn"
expect_fail "trace not writable" "cannot write trace file" --machine "$m" --controller bst --trace "$tmp/no/dir/t.csv"
expect_fail "replay without speed" "--replay needs --speed-rpm" --machine "$m" --replay "$tmp/none.csv" --trace "$tmp/t.csv"
expect_fail "replay file missing" "replay" --machine "$m" --replay "$tmp/none.csv" --speed-rpm 100 --trace "$tmp/t.csv"
expect_fail "replay with controller" "open loop" --machine "$m" --replay "$tmp/none.csv" --controller bst --speed-rpm 1 --trace "$tmp/t.csv"

# A good short run: exit 0, metrics on stdout and in the JSON file with every key.
out="$("$sim" --machine "$m" --controller bst --speed-rpm 750 --torque-ref 1.8 --duration 0.02 \
       --window 0.01:0.02 --metrics "$tmp/m.json" --trace "$tmp/t.csv" --trace-decimation 10 2>&1)"
rc=$?
if [ "$rc" -ne 0 ] || ! grep -q "T_rip" <<<"$out"; then
  echo "FAIL: good run: status $rc: $out"; fails=$((fails + 1))
else
  for k in torque_mean_nm torque_ripple_nm flux_mean_wb flux_ripple_wb torque_sse_nm f_av_hz \
           thd_i_pct fs_hz controller window torque_ripple_ctrl_nm flux_ripple_ctrl_wb; do
    grep -q "\"$k\"" "$tmp/m.json" || { echo "FAIL: metrics key $k missing"; fails=$((fails + 1)); }
  done
  head -n1 "$tmp/t.csv" | grep -q "^t,i_a,i_b,i_c,i_d,i_q,psi_s,torque,speed_rpm,torque_ref,vec,duty" ||
    { echo "FAIL: trace header"; fails=$((fails + 1)); }
  echo "ok: good run"
fi
# Open-loop replay of two intervals: exit 0, the plant owner's trace header.
printf 't_start_s,duration_s,S1,S2,S3\n0,0.0001,1,0,0\n0.0001,0.0001,0,0,0\n' >"$tmp/rp.csv"
if "$sim" --machine "$m" --replay "$tmp/rp.csv" --speed-rpm 100 --trace "$tmp/rp_out.csv" >/dev/null 2>&1 &&
   head -n1 "$tmp/rp_out.csv" | grep -q "^t,i_a" && [ "$(wc -l <"$tmp/rp_out.csv")" -eq 3 ]; then
  echo "ok: replay"
else
  echo "FAIL: replay"; fails=$((fails + 1))
fi
# --list-controllers lists bst and fst with their default fs.
"$sim" --list-controllers | grep -Eq "^fst	20000	" || { echo "FAIL: --list-controllers"; fails=$((fails + 1)); }

echo "$fails failure(s)"
[ "$fails" -eq 0 ]
