#!/usr/bin/env bash
# Renders the synthetic datasets from datasets-synthetic/scenes/.
#   scripts/render-datasets.sh          the committed default set -> datasets-synthetic/rendered/
#                                       (noise-free, as committed; run after changing a scene)
#   scripts/render-datasets.sh --large  40 random views per scene with sensor noise (sigma 2
#                                       grey levels) -> build/datasets-large/ (not committed)
set -euo pipefail
omnical_build_kind=demo
source "$(dirname "${BASH_SOURCE[0]}")/common.sh"
prepare_demo_build
scenes="$omnical_root/datasets-synthetic/scenes"
if [ "${1:-}" = "--large" ]; then
  out="$omnical_root/build/datasets-large"
  mkdir -p "$out"
  for scene in "$scenes"/*.yaml; do
    name=$(basename "$scene" .yaml)
    # Same scene, more views and noise: the overrides go into a generated scene file.
    sed -e 's/^\(  count: \).*/\140/' -e 's/noise_sigma: 0/noise_sigma: 2/' \
        -e "s#\.\./#$scenes/../#g" "$scene" >"$out/$name.yaml"
    "$omnical" render --scene "$out/$name.yaml" --out "$out/$name"
  done
else
  out="$omnical_root/datasets-synthetic/rendered"
  for scene in "$scenes"/*.yaml; do
    name=$(basename "$scene" .yaml)
    rm -rf "$out/$name"
    "$omnical" render --scene "$scene" --out "$out/$name"
  done
  du -sh "$out"
fi
