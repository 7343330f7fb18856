#!/usr/bin/env bash
# Runs the DEM-CFD chamber cases (docs/validation/chamber.md) side by side,
# JOBS at a time with one thread each, then writes one `domel compare`
# report over all of them, the table and the pictures.
#   scenarios/fluid/run_chamber.sh OUTDIR [JOBS] [SET]   (JOBS: default nproc)
# SET: sieve (default: the sieve, floor and spout feeds; about 1.5 hours on
# 2 cores, the two alpha = 4 runs about 45 minutes each) or heaps (issue 45
# items 3 and 4: the heap feed with gas and in still air, alpha = 4, 6, 8,
# with and without S-D, two seeds; report/heaps.md holds the claim's table).
# Runs already finished in OUTDIR (a summary.json) are kept, not redone.
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/../.." && pwd)"
out="${1:?usage: run_chamber.sh OUTDIR [JOBS]}"
jobs="${2:-$(nproc)}"
set_="${3:-sieve}"
domel="${DOMEL:-$root/build/bin/domel}"
python="/usr/bin/python3"
[ -x "$python" ] || python=python3
mkdir -p "$out"
scen="$here"
if [ "$set_" = heaps ]; then  # the heap scenarios are written, not shipped
  scen="$out/scenarios"
  "$python" "$here/make_chamber.py" --heaps "$scen" > /dev/null
fi
case "$set_" in
  sieve) runs=(a4_none a4_sd a6_none a6_sd a8_none a8_sd bottom_a4 bottom_a4_unscaled bottom_a8 spout_a8_none spout_a8_sd) ;;
  heaps) runs=()  # the cheap runs first, alpha = 4 last
         for a in 8 6 4; do for f in still heap; do for r in sd none; do for s in 1 2; do
           runs+=("${f}_a${a}_${r}_s${s}"); done; done; done; done ;;
  *) echo "run_chamber.sh: SET must be sieve or heaps, not '$set_'" >&2; exit 2 ;;
esac
for r in "${runs[@]}"; do
  # a run stopped early (SIGTERM: "status": "interrupted") is made again
  [ -f "$out/$r/summary.json" ] && ! grep -q '"status": "interrupted"' "$out/$r/summary.json" && continue
  echo "$r"
done | xargs -r -P "$jobs" -I{} sh -c '"$0" run "$1" --out "$2/{}" --overwrite --threads 1 --quiet > "$2/{}.log" 2>&1 && echo "done: {}" || { echo "FAILED: {} (see $2/{}.log)"; exit 1; }' \
  "$domel" "$scen/chamber_{}.json" "$out"
if [ "$set_" = heaps ]; then
  mkdir -p "$out/report"
  "$python" "$here/plot_chamber.py" heaps "$out" > "$out/report/heaps.md"
  pairs=()
  for r in "${runs[@]}"; do pairs+=("$r=$out/$r"); done
  "$python" "$here/plot_chamber.py" table "${pairs[@]}" > "$out/report/table.md"
  for f in heap still; do for r in sd none; do
    "$python" "$here/plot_chamber.py" profile "$out/report/profiles_${f}_${r}.png" \
      $(for a in 4 6 8; do printf '%s ' "a${a}_s1=$out/${f}_a${a}_${r}_s1"; done)
  done; done
  echo "report: $out/report/heaps.md, table: $out/report/table.md"
  exit 0
fi
args=()
for r in "${runs[@]}"; do args+=(--runs "$out/$r" --label "$r"); done
"$domel" compare "${args[@]}" --out "$out/report"
pairs=()
for r in "${runs[@]}"; do pairs+=("$r=$out/$r"); done
"$python" "$here/plot_chamber.py" table "${pairs[@]}" > "$out/report/table.md"
"$python" "$here/plot_chamber.py" profile "$out/report/heap_profiles.png" \
  $(for r in a4_none a6_none a8_none a4_sd a6_sd a8_sd; do printf '%s ' "$r=$out/$r"; done)
for r in a4_none a4_sd a8_sd; do
  "$python" "$here/plot_chamber.py" fields "$out/$r" 0.8 "$out/report/fields_${r}_0.8s.png"
  "$python" "$here/plot_chamber.py" fields "$out/$r" 2.0 "$out/report/fields_${r}_2.0s.png"
done
echo "report: $out/report/report.md, table: $out/report/table.md"
