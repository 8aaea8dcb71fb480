#!/usr/bin/env bash
# regen-golden.sh: rebuilds the golden images the tests compare against, on
# purpose only (after a change that is meant to alter them). Each golden NAME
# has tests/data/golden/NAME.args, the photosplat-ref arguments that make it.
# Look at the new image and say in the commit why it changed.
set -euo pipefail
cd "$(dirname "$0")/.."
make --no-print-directory -j"$(nproc)" all
for args in tests/data/golden/*.args; do
    name=${args%.args}
    # shellcheck disable=SC2046 # the file holds a word list
    bin/photosplat-ref $(cat "$args") --hdr "$name.pfm" -o "$name.png" --exposure 0.3
done
