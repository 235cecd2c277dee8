#!/usr/bin/env bash
# Builds the example firmware in release, prints its flash and RAM footprint, and runs it under
# QEMU (mps2-an386, -icount shift=0) through the runner in .cargo/config.toml. Fails if the
# build fails, QEMU exits non-zero or times out, or the output lacks `firmware: OK`.
#
# Needs: the thumbv7em-none-eabihf target (rustup target add thumbv7em-none-eabihf),
# qemu-system-arm (Debian: qemu-system-arm) and GNU size (Debian: binutils, which gcc pulls in).
# Installs nothing itself.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

timeout_s="${FIRMWARE_TIMEOUT:-120}"

missing=0
need() {
    if ! command -v "$1" >/dev/null 2>&1; then
        echo "run.sh: '$1' not found; install it with: $2" >&2
        missing=1
    fi
}
need cargo "rustup (https://rustup.rs)"
need qemu-system-arm "apt-get install -y qemu-system-arm"
need size "apt-get install -y binutils"
need timeout "apt-get install -y coreutils"
if command -v rustup >/dev/null 2>&1 &&
    ! rustup target list --installed | grep -qx thumbv7em-none-eabihf; then
    echo "run.sh: target thumbv7em-none-eabihf missing; run: rustup target add thumbv7em-none-eabihf" >&2
    missing=1
fi
[ "$missing" -eq 0 ] || exit 1

echo "== build (release, thumbv7em-none-eabihf)"
# The instruction counts below depend on the compiler's code generation: name it.
echo "compiler: $(rustc --version)"
source ../tools/firmware.sh
elf="$(release_elf run.sh)"
echo "ELF: $elf"

echo "== footprint"
footprint "$elf"
# The stack comes on top of the static RAM: the firmware prints its peak.

echo "== run under QEMU (timeout ${timeout_s} s)"
log="$(mktemp)"
trap 'rm -f "$log"' EXIT
status=0
timeout "$timeout_s" cargo run --release --locked --quiet >"$log" 2>&1 || status=$?
cat "$log"
if [ "$status" -eq 124 ]; then
    echo "run.sh: QEMU did not finish within ${timeout_s} s" >&2
    exit 1
fi
if [ "$status" -ne 0 ]; then
    echo "run.sh: the firmware exited with status $status" >&2
    exit 1
fi
if ! grep -qx 'firmware: OK' "$log"; then
    echo "run.sh: the firmware output lacks 'firmware: OK'" >&2
    exit 1
fi
echo "run.sh: firmware passed"
