#!/usr/bin/env bash
# make slurm-test: `rmapgen prove --slurm` through a real (one-node) Slurm cluster, started
# here by scripts/slurm-cluster.sh and stopped on the way out, whatever happens. Usage:
# slurm-test.sh RMAPGEN DIR. Four runs of a G = 8 design in four shards:
#   1. the design as generated: PASSED, exit 0;
#   2. a planted fault (bit 8 of one reciprocal-ROM entry flipped): FAILED through Slurm,
#      exit 1, naming a shard that found it;
#   3. task 2 of the array cancelled (scancel) while it waits: FAILED, exit 1, naming shard 2/4
#      as cancelled;
#   4. rmapgen interrupted (SIGINT) while its jobs wait: exit 130, and every job it submitted
#      gone from the queue.
# Exit 0 when every run did what it must; the first that did not is one line, exit 1.
set -euo pipefail
rmapgen=$(realpath "$1"); dir=$2
rm -rf "$dir"; mkdir -p "$dir"; dir=$(cd "$dir" && pwd)
cluster=$dir/cluster
trap 'scripts/slurm-cluster.sh stop "$cluster" >/dev/null 2>&1 || true' EXIT
scripts/slurm-cluster.sh start "$cluster" | sed -n 1p
export SLURM_CONF=$cluster/slurm.conf

fail() { echo "slurm-test: FAILED: $1" >&2; [ -f "${2:-}" ] && sed 's/^/  | /' "$2" >&2; exit 1; }

"$rmapgen" generate --grad-bits 8 --red-bits 6 --out "$dir/good" 2>/dev/null >/dev/null
"$rmapgen" generate --grad-bits 8 --red-bits 6 --out "$dir/fault" 2>/dev/null >/dev/null
# Bit 8 of the fifth entry of the reciprocal ROM (the file's third line is the first entry).
python3 - "$dir/fault/recip_rom.hex" <<'EOF'
import sys
p = sys.argv[1]
lines = open(p).read().split("\n")
lines[6] = format(int(lines[6], 16) ^ 0x100, "03x")
open(p, "w").write("\n".join(lines))
EOF

prove() { "$rmapgen" prove --slurm --shards 4 --build "$dir/build" "$@"; }

# 1. As generated.
t0=$(date +%s.%N)
status=0; prove "$dir/good" > "$dir/good.out" 2>&1 || status=$?
t1=$(date +%s.%N)
[ $status = 0 ] || fail "the generated design: exit $status, not 0" "$dir/good.out"
grep -q '^PROVEN: ' "$dir/good.out" || fail "the generated design: no PROVEN line" "$dir/good.out"
grep -q '^slurm: PASSED: build, 4 shards and merge' "$dir/good.out" || fail "the generated design: no PASSED line" "$dir/good.out"
echo "slurm-test: the generated design PROVEN through Slurm in 4 shards, $(awk "BEGIN { printf \"%.1f\", $t1 - $t0 }") s wall"

# 2. A planted fault.
status=0; prove "$dir/fault" > "$dir/fault.out" 2>&1 || status=$?
[ $status = 1 ] || fail "the planted fault: exit $status, not 1" "$dir/fault.out"
grep -q '^FAILED' "$dir/fault.out" || fail "the planted fault: the merge said no FAILED" "$dir/fault.out"
grep -Eq '^  shard [1-4]/4 \(task [0-9]+_[1-4]\) found inputs where the design differs' "$dir/fault.out" \
  || fail "the planted fault: no shard named" "$dir/fault.out"
echo "slurm-test: the planted fault FAILED through Slurm: $(grep -c '^  shard' "$dir/fault.out") shard(s) named"

# Starts a run in the background; waits for its submission line; sets pid and the shards job.
start() {
  "$rmapgen" prove --slurm --shards 4 --build "$dir/build" "$dir/good" > "$1" 2>&1 &
  pid=$!
  for _ in $(seq 200); do
    grep -q '^slurm: submitted' "$1" && break
    kill -0 $pid 2>/dev/null || fail "rmapgen ended before it submitted" "$1"
    sleep 0.1
  done
  line=$(grep '^slurm: submitted' "$1") || fail "no submission within 20 s" "$1"
  build=$(echo "$line" | sed -E 's/.*build job ([0-9]+),.*/\1/')
  shards=$(echo "$line" | sed -E 's/.*shards job ([0-9]+) .*/\1/')
  merge=$(echo "$line" | sed -E 's/.*merge job ([0-9]+);.*/\1/')
}

# 3. One task cancelled while it waits for the build.
start "$dir/cancel.out"
scancel "${shards}_2"
status=0; wait $pid || status=$?
[ $status = 1 ] || fail "a cancelled task: exit $status, not 1" "$dir/cancel.out"
grep -q "^  shard 2/4 (task ${shards}_2) was cancelled or killed before it ended" "$dir/cancel.out" \
  || fail "a cancelled task: shard 2/4 not named as cancelled" "$dir/cancel.out"
echo "slurm-test: a cancelled task FAILED the verdict, naming shard 2/4"

# 4. rmapgen interrupted: its jobs go with it.
start "$dir/interrupt.out"
kill -INT $pid
status=0; wait $pid || status=$?
[ $status = 130 ] || fail "an interrupt: exit $status, not 130" "$dir/interrupt.out"
left=
for _ in $(seq 50); do
  left=$(squeue --noheader --format %i --jobs "$build,$shards,$merge" 2>/dev/null || true)
  [ -z "$left" ] && break
  sleep 0.2
done
[ -z "$left" ] || fail "an interrupt left jobs in the queue: $(echo $left)" "$dir/interrupt.out"
echo "slurm-test: an interrupt cancelled all three jobs (exit 130)"
echo "slurm-test: passed"
