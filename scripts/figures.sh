#!/usr/bin/env bash
# Regenerates docs/figures/: the seed paper's evaluation (characterize) and Fig. 15
# (parallax, n = 7 and 40) for the three shipped mirrors, with the paper's prototype
# lens (f = 11.6 mm, F = 4, 5.2 um pixels; Sec. 3.3). Everything in docs/figures comes
# from this script.
set -euo pipefail
omnical_build_kind=demo
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
prepare_demo_build
out="$omnical_root/docs/figures"
for mirror in ohte-sph ohte-edi ohte-svp; do
  sensor="$omnical_root/datasets-synthetic/sensors/$mirror.yaml"
  rm -rf "$out/$mirror" && mkdir -p "$out/$mirror"
  "$omnical" characterize --sensor "$sensor" --lens-f 11.6 --f-number 4 --pixel-um 5.2 --out "$out/$mirror"
  rm "$out/$mirror/characteristics.csv"  # large and regenerated on demand
  for n in 7 40; do
    "$omnical" parallax --sensor "$sensor" --n "$n" --out "$out/$mirror/parallax-n$n"
    rm "$out/$mirror/parallax-n$n/parallax.csv"
  done
  rm "$out/$mirror/parallax-n40/error_map.png"  # the n = 7 map shows the pattern; keeps docs/ small
done
