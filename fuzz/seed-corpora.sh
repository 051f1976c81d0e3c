#!/bin/sh
# Seeds the corpus of every fuzz target (fuzz/corpus/<target>/, not committed) from the
# repository's fixtures and the few seeds in fuzz/seeds/. Files are named by their SHA-1, as
# libFuzzer names them, so running this twice adds nothing.
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(dirname "$here")

add() { # add TARGET FILE...
    target=$1
    shift
    mkdir -p "$here/corpus/$target"
    for f in "$@"; do
        cp "$f" "$here/corpus/$target/$(sha1sum <"$f" | cut -c1-40)"
    done
}

gltf=$(find "$root/fixtures" "$here/seeds" -name '*.gltf' | sort)
glb=$(find "$root/fixtures" "$here/seeds" -name '*.glb' | sort)
# shellcheck disable=SC2086 # the lists are split on purpose (fixture paths have no spaces)
{
    add load_gltf $gltf
    add load_glb $glb
    add validate $gltf $glb
    add migrate $gltf
    add bake $gltf $glb
    add tape $gltf
    add fix $gltf
}
for target in load_gltf load_glb validate migrate bake tape fix; do
    printf '%s: %s inputs\n' "$target" "$(ls "$here/corpus/$target" | wc -l)"
done
