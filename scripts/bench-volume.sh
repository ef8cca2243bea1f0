#!/usr/bin/env bash
# make bench-volume: renders VolPack's example MRI head (Debian libvolpack1-dev, 128x128x84)
# with rmapgen (both casters, shear-warp and ray, and shear-warp sampled finely enough to
# match the ray caster's image, --slice-samples 4 --supersample 3, "shear-4x3"; model
# shading, skipping on, --model-only, RAYON_NUM_THREADS = 1 and 2) and
# with VolPack's classified shear-warp renderer (bench/volume/volpack_bench.c, single
# threaded), same scene (bench/volume/brainsmall.toml: VolPack's example view, light,
# material and classification), at 256x256 and 512x512, in one run. Prints both median
# frame times and their ratio. A benchmark, not a test: the figures depend on the machine
# and its load (docs/PERFORMANCE.md).
set -euo pipefail
REPEAT=${REPEAT:-9}
# CASTERS: the rmapgen casters to run, a subset of the labels below (all three by default).
CASTERS=${CASTERS:-shear-warp ray shear-4x3}
BUILD=${BUILD:-build/bench-volume}
RMAPGEN=${RMAPGEN:-target/release/rmapgen}
DEN=/usr/share/doc/libvolpack1-dev/examples/brainsmall.den
[ -f /usr/include/volpack.h ] && [ -f "$DEN" ] || {
  echo "bench-volume: VolPack is missing; WITH_VOLPACK=1 scripts/install-tools.sh installs libvolpack1-dev" >&2
  exit 1
}
mkdir -p "$BUILD"
${CC:-cc} -O2 -o "$BUILD/volpack_bench" bench/volume/volpack_bench.c -lvolpack -lm
# --zoom 1.4 frames the head about as VolPack's unit window does; --ert 0.95 is VolPack's
# VP_MAX_RAY_OPACITY.
ARGS=(bench/volume/brainsmall.nhdr --scene bench/volume/brainsmall.toml --zoom 1.4 --ert 0.95)
printf '%-8s %-8s %-11s %12s %12s %8s\n' image threads caster rmapgen_ms volpack_ms ratio
# The renderer's arguments for each label.
declare -A CASTER=(
  [shear-warp]="--caster shear-warp"
  [ray]="--caster ray"
  [shear-4x3]="--caster shear-warp --slice-samples 4 --supersample 3"
)
for size in 256 512; do
  for threads in 1 2; do
    for caster in $CASTERS; do
      [ -n "${CASTER[$caster]:-}" ] || { echo "bench-volume: unknown caster $caster (CASTERS)" >&2; exit 2; }
      vp=$("$BUILD/volpack_bench" "$DEN" "$REPEAT" "$size" | awk '{print $3}')
      out="$BUILD/rmapgen-$caster-$size-$threads"
      # shellcheck disable=SC2086 # the label's arguments are words
      RAYON_NUM_THREADS=$threads "$RMAPGEN" volume "${ARGS[@]}" --size "$size" --model-only \
        ${CASTER[$caster]} --timing --repeat "$REPEAT" --out "$out" --force >/dev/null
      rm=$(sed -n '/"model_skipping_on"/,/}/s/.*"median_ms": \([0-9.e+-]*\).*/\1/p' "$out/timing.json")
      awk -v s="$size" -v t="$threads" -v c="$caster" -v r="$rm" -v v="$vp" \
        'BEGIN { printf "%-8s %-8s %-11s %12.2f %12.3f %7.1fx\n", s "x" s, t, c, r, v, r / v }'
    done
  done
done
"$BUILD/volpack_bench" "$DEN" 1 256 -ppm "$BUILD/volpack" >/dev/null
echo "bench-volume: images in $BUILD (rmapgen-CASTER-SIZE-THREADS/model.png, volpack256.pgm)"
