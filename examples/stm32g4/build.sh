#!/usr/bin/env bash
# Builds the STM32G4 firmware in release (--locked) and prints its flash and RAM footprint.
#
#   bash examples/stm32g4/build.sh          # the chip set in .cargo/config.toml (g474)
#   bash examples/stm32g4/build.sh g431     # another chip, without editing that line
#
# Flashing needs the board and probe-rs: `cargo run --release` in this folder (README).
# Needs: the thumbv7em-none-eabihf target (rustup target add thumbv7em-none-eabihf) and GNU
# size and nm (Debian: binutils). Installs nothing itself.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

chip="${1:-}"
case "$chip" in
"") ;;
g474 | g431)
    # RUSTFLAGS replaces the `--cfg chip` line of .cargo/config.toml (and with it the runner
    # and embassy-stm32's chip feature), exactly as editing that line would.
    export RUSTFLAGS="--cfg chip=\"$chip\""
    ;;
*)
    echo "build.sh: unknown chip '$chip' (g474 or g431)" >&2
    exit 2
    ;;
esac

missing=0
for tool in size nm; do
    if ! command -v "$tool" >/dev/null 2>&1; then
        echo "build.sh: '$tool' not found; install it with: apt-get install -y binutils" >&2
        missing=1
    fi
done
if command -v rustup >/dev/null 2>&1 &&
    ! rustup target list --installed | grep -qx thumbv7em-none-eabihf; then
    echo "build.sh: target thumbv7em-none-eabihf missing; run: rustup target add thumbv7em-none-eabihf" >&2
    missing=1
fi
[ "$missing" -eq 0 ] || exit 1

echo "== build (release, thumbv7em-none-eabihf${chip:+, chip $chip})"
source ../tools/firmware.sh
elf="$(release_elf build.sh)"
echo "ELF: $elf"

echo "== footprint"
footprint "$elf"
# The stack comes on top of the static RAM: it takes the rest of the chip's SRAM.
# The two large statics, from the symbol table: the monitor (a `DeltaMonitor<1024>` built by
# the compiler as `unconfigured()` and configured in place, in its `ConstStaticCell` with the
# cell's taken flag) and the DMA ring of captures.
static_size() {
    local hex
    hex="$(nm --print-size --demangle "$elf" | awk -v name="$1" '$NF ~ ("::" name "$") { print $2; exit }')"
    if [ -z "$hex" ]; then
        echo "build.sh: symbol $1 not found in the image" >&2
        return 1
    fi
    echo $((16#$hex))
}
monitor="$(static_size MONITOR)"
ring="$(static_size CAPTURES)"
echo "footprint: monitor static $monitor bytes, DMA ring $ring bytes"
