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
objdump="$(find "$(rustc --print sysroot)" -name llvm-objdump -type f 2>/dev/null | head -n 1)"
if [ -z "$objdump" ]; then
    echo "panic-free.sh: llvm-objdump not found; install it with: rustup component add llvm-tools" >&2
    exit 1
fi

# The linker fills the gap before an aligned function with 0xd4d4 halfwords, which
# disassemble as a branch ("bmi"); a d4d4 that no instruction follows in its function is that
# fill, not code (a conditional branch cannot end a function), and is dropped (the raw
# bytes are shown for this only).
strip_fill() {
    awk '
        fill != "" { if ($0 ~ /^ *[0-9a-f]+:/) print fill; fill = "" }
        /^ *[0-9a-f]+: d4d4 / { fill = $0; next }
        { print }
    '
}

"$objdump" -d "$elf" | strip_fill | awk -v profile="$profile" '
    # A function: "00012345 <symbol>:"
    /^[0-9a-f]+ <[^>]+>:$/ {
        cur = substr($2, 2, length($2) - 3)
        names[cur] = 1
        # A function runs up to the next one (its literal pool and padding included).
        addr = 0
        for (k = 1; k <= length($1); k++) addr = addr * 16 + index("0123456789abcdef", substr($1, k, 1)) - 1
        if (prev != "") size[prev] = addr - start[prev]
        start[cur] = addr
        prev = cur
        next
    }
    # A direct call or jump to another function: "bl 0x... <symbol+0x..>", conditional ones
    # too (a branch, or a call inside an IT block: "blne").
    cur != "" && /\t(b|bl|blx)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?(\.w|\.n)?\t|\t(cbz|cbnz)\t/ && /</ {
        t = $0
        sub(/^[^<]*</, "", t)
        sub(/>.*$/, "", t)
        sub(/\+0x[0-9a-f]+$/, "", t)
        if (t != cur) edges[cur] = edges[cur] " " t
        next
    }
    function code_size(what, configure,    i, j, f, g, out, bytes, mem) {
        m = 0
        split("", s2)
        for (f in names) if (f ~ ("12entry_points(" configure "|7on_edge17|11on_captures|8on_index|4poll)")) { q2[m++] = f; s2[f] = 1 }
        for (i = 0; i < m; i++) {
            split(edges[q2[i]], out, " ")
            for (j in out) { g = out[j]; if (g != "" && !(g in s2)) { s2[g] = 1; q2[m++] = g } }
        }
        bytes = 0
        mem = 0
        for (i = 0; i < m; i++) {
            bytes += size[q2[i]]
            # The memory routines (memcpy, memmove, memset and their aeabi entries), which any
            # Rust firmware links: shown apart.
            if (q2[i] ~ /compiler_builtins3mem|^__aeabi_mem/) mem += size[q2[i]]
        }
        printf "monitor code (%s, %s): %d bytes in %d functions (on_edge, on_captures, on_index, poll of a DeltaMonitor<1024>; %d of them the memory routines)\n", profile, what, bytes, m, mem
        # PANIC_FREE_SIZES=1: each function and its size.
        if (ENVIRON["PANIC_FREE_SIZES"] != "") for (i = 0; i < m; i++) printf "%8d %s\n", size[q2[i]], q2[i]
    }
    # An indirect call or jump (a register holds the target; "bx lr" is a return): not
    # followed, so not allowed.
    cur != "" && /\t(blx|bx)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?\t(r[0-9]+|ip|sb|sl|fp)([^0-9a-z]|$)/ { indirect[cur] = 1 }
    cur != "" && /\t(mov|ldr)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?(\.w)?\tpc,/ { indirect[cur] = 1 }
    END {
        n = 0
        for (f in names) if (f ~ /12entry_points/ && f !~ /12entry_points(17configure_monitor|12apply_config)/) { queue[n++] = f; seen[f] = "(entry)" }
        if (n == 0) { print "panic-free.sh: no entry points found in the image" > "/dev/stderr"; exit 1 }
        roots = n
        for (i = 0; i < n; i++) {
            f = queue[i]
            if (f ~ /panic|unwrap_failed|expect_failed|slice_(start|end)_index|slice_index|len_mismatch|rust_begin_unwind|index_out_of_bounds/) continue
            split(edges[f], out, " ")
            for (j in out) {
                g = out[j]
                if (g == "" || g in seen) continue
                seen[g] = f
                queue[n++] = g
            }
        }
        bad = 0
        for (i = 0; i < n; i++) {
            f = queue[i]
            why = ""
            if (f ~ /panic|unwrap_failed|expect_failed|slice_(start|end)_index|slice_index|len_mismatch|rust_begin_unwind|index_out_of_bounds/) why = "can panic"
            else if (f in indirect) why = "calls through a register"
            if (why == "") continue
            bad++
            chain = f
            for (g = seen[f]; g != "(entry)"; g = seen[g]) chain = g " -> " chain
            print "panic-free.sh: " why ": " chain > "/dev/stderr"
        }
        if (bad > 0) exit 1
        printf "panic-free (%s): %d functions reached from %d per-edge entry points, none can panic\n", profile, n, roots
        # The code of a DeltaMonitor<1024> in firmware: everything on_edge, on_captures,
        # on_index, poll and the configuration reach (not the learner or the corrected table):
        # with a configuration the compiler validated (a `const` installed by `apply`), and
        # with one validated at run time (`configure_from`, whose f64 checks bring in the
        # software floating point).
        code_size("compile-time configuration", "12apply_config")
        code_size("run-time configuration", "17configure_monitor")
    }
'
