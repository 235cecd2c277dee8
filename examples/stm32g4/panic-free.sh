#!/usr/bin/env bash
# Checks the release firmware (build.sh's build, for the chip of .cargo/config.toml or the one
# named, g474 or g431): nothing the interrupt handlers that feed the monitor reach can panic.
# The roots are DMA1_CHANNEL1 (a DMA half buffer into `on_captures`), TIM2 (an index capture)
# and SysTick (the partial half, the standstill poll, index pulses, the log). Walks the call
# graph of the disassembly (direct calls and jumps between functions, conditional ones
# included) from them and fails if it reaches a panic routine of `core` (a bounds check, an
# unwrap, an overflow, a slice length check, a RefCell already borrowed, `panic_fmt`), the
# panic handler, or an indirect call it cannot follow. The same walk as
# examples/qemu/panic-free.sh (examples/tools/callgraph.awk), from these roots. Builds the firmware first (nothing to do
# when it is up to date).
#
# One thing is not followed, and the output says so: defmt-rtt's global logger
# (`_defmt_acquire`, `_defmt_write`, `_defmt_flush`, `_defmt_release`), the sink of the log
# lines. Its panics are guards against misuse of its own protocol (acquire taken reentrantly,
# release without acquire): acquire holds a critical section until release, so nothing can
# re-enter it on this single-core chip, and defmt's macros pair the two calls. Its writes go
# through a function pointer chosen by the RTT channel's mode (blocking or not), set by the
# probe.
#
# Needs: the rustup component llvm-tools (rustup component add llvm-tools) for llvm-objdump.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

chip="${1:-}"
case "$chip" in
"") ;;
g474 | g431) export RUSTFLAGS="--cfg chip=\"$chip\"" ;;
*)
    echo "panic-free.sh: unknown chip '$chip' (g474 or g431)" >&2
    exit 2
    ;;
esac

elf="$(cargo build --release --locked --quiet --message-format=json-render-diagnostics |
    sed -n 's/.*"executable":"\([^"]*\)".*/\1/p' | tail -n 1)"
if [ -z "$elf" ] || [ ! -f "$elf" ]; then
    echo "panic-free.sh: the build produced no executable" >&2
    exit 1
fi
source ../tools/disasm.sh
objdump="$(objdump_path)"

disassemble "$objdump" "$elf" | awk -v chip="${chip:-default}" -f ../tools/callgraph.awk -f <(cat <<'AWK'
END {
    n = 0
    split("DMA1_CHANNEL1 TIM2 SysTick", want, " ")
    for (i in want) {
        if (!(want[i] in names)) {
            print "panic-free.sh: handler " want[i] " not found in the image" > "/dev/stderr"
            exit 1
        }
        queue[n++] = want[i]
        seen[want[i]] = "(handler)"
    }
    roots = n
    # The logger's entry points are not followed (see the top of this script).
    logger = "^_defmt_(acquire|write|flush|release)$"
    stop = panic_names() "|already_borrowed|already_mutably_borrowed|HardFault"
    n = walk(n, stop, logger)
    sinks = 0
    for (i = 0; i < n; i++) if (queue[i] ~ logger) sinks++
    if (offenders(n, stop, logger, "(handler)") > 0) exit 1
    printf "panic-free (release, chip %s): %d functions reached from %d interrupt handlers, none can panic (not followed: %d entry points of the defmt-rtt logger)\n", chip, n - sinks, roots, sinks
}
AWK
)
