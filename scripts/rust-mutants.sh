#!/bin/sh
# cargo-mutants over one group of the Rust that issues verdicts (`make rust-mutants`), in two
# passes, because building a mutant is most of its cost and the integration test binary is
# most of the build:
#   1. every mutant of the group, the library alone built (`--cargo-arg=--lib`) and its unit
#      tests run: a mutant a unit test fails is judged here;
#   2. only the mutants pass 1 missed (by name, `--re`), the whole package built and judged by
#      the unit tests and the group's integration tests.
# What pass 2 misses is the group's list of survivors: OUT/integration/mutants.out/missed.txt.
# Each gets the test that kills it or is shown equivalent in docs/VERIFICATION.md.
#
# Usage: rust-mutants.sh OUT SHARD TESTS [cargo-mutants options...]
#   OUT    the output folder (pass 1 in OUT/mutants.out, pass 2 in OUT/integration)
#   SHARD  K/N, a round-robin part of pass 1 (pass 2 takes what that part missed)
#   TESTS  the integration tests' modules, as a regular expression (`mult_proof|prove`)
#   the rest: the files (`-f GLOB`, `-e GLOB`) and any other cargo-mutants option
set -eu
out=$1 shard=$2 tests=$3
shift 3
cargo=${CARGO:-cargo}
common="--profile mutants --test-tool nextest"
mkdir -p "$out"  # cargo-mutants makes OUT/mutants.out, not OUT

# shellcheck disable=SC2086
$cargo mutants $common "$@" --cargo-arg=--lib --shard "$shard" --sharding round-robin \
  -o "$out" -- -E 'kind(lib)' || {
  # 2: some missed (for pass 2), 3: some timed out (a kill); anything else is an error.
  rc=$?
  test $rc -eq 2 || test $rc -eq 3 || exit $rc
}

missed="$out/mutants.out/missed.txt"
if ! test -s "$missed"; then
  echo "rust-mutants: pass 1 missed none; nothing for pass 2"
  exit 0
fi
echo "rust-mutants: pass 1 missed $(wc -l < "$missed"); pass 2 judges them with the integration tests"
# The names as one anchored alternation, each escaped (they hold `(`, `*`, `|`, ...).
re=$(python3 -c '
import sys
meta = set(r"\.+*?()|[]{}^$#&-~")
names = [l.rstrip("\n") for l in open(sys.argv[1]) if l.strip()]
print("^(" + "|".join("".join("\\" + c if c in meta else c for c in n) for n in names) + ")$")
' "$missed")
# shellcheck disable=SC2086
$cargo mutants $common "$@" --re "$re" -o "$out/integration" \
  -- -E "kind(lib) | (binary(it) & test(/^($tests)::/))"
