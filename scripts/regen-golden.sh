#!/usr/bin/env bash
# regen-golden.sh: rebuilds the golden images the tests compare against, on
# purpose only (after a change that is meant to alter them). Each golden NAME
# has tests/data/golden/NAME.args: the program (ref or snap) and the
# arguments that make it. Look at the new images and say in the commit why
# they changed.
set -euo pipefail
cd "$(dirname "$0")/.."
make --no-print-directory -j"$(nproc)" all
for args in tests/data/golden/*.args; do
    name=${args%.args}
    read -r prog rest <"$args"
    case "$prog" in
    ref) # shellcheck disable=SC2086 # the file holds a word list
        bin/photosplat-ref $rest --hdr "$name.pfm" -o "$name.png" --exposure 0.3 ;;
    snap) # shellcheck disable=SC2086
        bin/photosplat-snap $rest -o "$name.png" ;;
    *) echo "regen-golden: $args: unknown program '$prog'" >&2; exit 2 ;;
    esac
done
