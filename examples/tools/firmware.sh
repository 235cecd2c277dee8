# The build and footprint steps both firmware examples share (sourced by examples/qemu/run.sh
# and examples/stm32g4/build.sh).
#
# Needs: GNU size (Debian: binutils).

# `release_elf SCRIPT`: builds the crate of the current folder in release (--locked) and
# prints the path of its executable; fails, naming SCRIPT, if the build made none.
release_elf() {
    local elf
    elf="$(cargo build --release --locked --message-format=json-render-diagnostics |
        sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -n 1)"
    if [ -z "$elf" ] || [ ! -f "$elf" ]; then
        echo "$1: the build produced no executable" >&2
        return 1
    fi
    echo "$elf"
}

# `footprint ELF`: its `size`, then "footprint: flash F bytes, static RAM R bytes". Berkeley
# format: text data bss. Flash holds text and the initial values of data; RAM holds data and
# bss statically, plus the stack.
footprint() {
    size "$1"
    size "$1" | awk 'NR == 2 {
        printf "footprint: flash %d bytes, static RAM %d bytes\n", $1 + $2, $2 + $3 }'
}
