# Shared by docs/cluster/scaling.sh and docs/cluster/memory.sh (sourced, not run): demo1
# copies with more samples per dimension, timed runs, table rows. Expects $work (scratch
# folder) and $src (samples/demo1) to be set.

me=$(basename "$0")

# demo1 with N samples along each of its two dimensions, in $work/demo1-N; prints its
# scene.toml.
scene_copy() {
    local n=$1 dir="$work/demo1-$1"
    mkdir -p "$dir"
    cp "$src"/demo1.gltf "$src"/demo1.bin "$src"/*.png "$dir"/
    sed "s/^samples = 4$/samples = $n/" "$src/scene.toml" > "$dir/scene.toml"
    [ "$(grep -c "^samples = $n$" "$dir/scene.toml")" = 2 ] || { echo "$me: demo1's scene.toml no longer has two 'samples = 4' lines" >&2; exit 1; }
    echo "$dir/scene.toml"
}

# Runs "$@" under /usr/bin/time; prints "SECONDS PEAK_MIB". The command's report goes to
# the file $REPORT where set (pis-pack's lists each stage's time and peak memory).
timed() {
    local t
    t=$(mktemp)
    /usr/bin/time -f "%e %M" -o "$t" "$@" > "${REPORT:-/dev/null}" 2>> "$work/log.txt" || { echo "$me: failed: $* (see $work/log.txt)" >&2; exit 1; }
    awk '{ printf "%s %.0f\n", $1, $2 / 1024 }' "$t"
    rm -f "$t"
}

# One table row of five cells.
row() {
    printf '| %s | %s | %s | %s | %s |\n' "$1" "$2" "$3" "$4" "$5"
}
