#!/usr/bin/env bash
# Checks the firmware (release build, or with `dev` the debug build, overflow checks and
# library precondition checks on): nothing the core's per-edge entry points
# (src/entry_points.rs) reach can panic. Walks the call graph of the disassembly (direct calls
# and jumps between functions, conditional ones included) from those functions and fails if it
# reaches a panic routine of `core` (a bounds check, an unwrap, an overflow, a slice length
# check, a failed precondition, `panic_fmt`) or an indirect call it cannot follow. Builds the
# firmware first (nothing to do when it is up to date).
#
# Needs: the rustup component llvm-tools (rustup component add llvm-tools) for llvm-objdump.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")"

profile="${1:-release}"
case "$profile" in
release) elf=target/thumbv7em-none-eabihf/release/drive-monitor-firmware
    cargo build --release --quiet ;;
dev) elf=target/thumbv7em-none-eabihf/debug/drive-monitor-firmware
    cargo build --quiet ;;
*) echo "usage: panic-free.sh [release|dev]" >&2; exit 2 ;;
esac
source ../tools/disasm.sh
objdump="$(objdump_path)"

disassemble "$objdump" "$elf" | awk -v profile="$profile" -f ../tools/callgraph.awk -f <(cat <<'AWK'
# The code of a DeltaMonitor<1024> in firmware: what the entry points named by `roots` (a
# pattern of names in entry_points.rs) and the configuration entry point `configure` reach,
# with its size.
function code_size(what, configure, roots,    i, f, m, bytes, mem) {
    split("", queue)
    split("", seen)
    m = 0
    for (f in names) if (f ~ ("12entry_points(" configure "|" roots ")")) { queue[m++] = f; seen[f] = "(entry)" }
    m = walk(m, "^$", "")
    bytes = 0
    mem = 0
    for (i = 0; i < m; i++) {
        bytes += size[queue[i]]
        # The memory routines (memcpy, memmove, memset and their aeabi entries), shown apart.
        if (queue[i] ~ /compiler_builtins3mem|^__aeabi_mem/) mem += size[queue[i]]
    }
    printf "monitor code (%s, %s): %d bytes in %d functions (%d of them the memory routines)\n", profile, what, bytes, m, mem
    # PANIC_FREE_SIZES=1: each function and its size.
    if (ENVIRON["PANIC_FREE_SIZES"] != "") for (i = 0; i < m; i++) printf "%8d %s\n", size[queue[i]], queue[i]
}
END {
    n = 0
    for (f in names) if (f ~ /12entry_points/ && f !~ /12entry_points(17configure_monitor|12apply_config)/) { queue[n++] = f; seen[f] = "(entry)" }
    if (n == 0) { print "panic-free.sh: no entry points found in the image" > "/dev/stderr"; exit 1 }
    roots = n
    n = walk(n, panic_names(), "")
    if (offenders(n, panic_names(), "", "(entry)") > 0) exit 1
    printf "panic-free (%s): %d functions reached from %d per-edge entry points, none can panic\n", profile, n, roots
    # The code of a DeltaMonitor<1024> in firmware (not the learner or the corrected
    # table): everything on_edge, on_captures, on_index, poll and the configuration reach,
    # with a configuration the compiler validated (a `const` installed by `apply`) and with
    # one validated at run time (`configure_from`, whose f64 checks bring in the software
    # floating point); then what firmware fed edge by edge from a capture interrupt links
    # (no on_captures), and what firmware fed by DMA links (no on_edge).
    all = "7on_edge17|11on_captures|8on_index|4poll"
    code_size("compile-time configuration, every entry point", "12apply_config", all)
    code_size("run-time configuration, every entry point", "17configure_monitor", all)
    code_size("compile-time configuration, fed edge by edge", "12apply_config", "7on_edge17|8on_index|4poll")
    code_size("compile-time configuration, fed by DMA", "12apply_config", "11on_captures|8on_index|4poll")
}
AWK
)
