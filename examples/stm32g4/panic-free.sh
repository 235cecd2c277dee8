#!/usr/bin/env bash
# Checks the release firmware (build.sh's build, for the chip of .cargo/config.toml or the one
# named, g474 or g431): nothing the interrupt handlers that feed the monitor reach can panic.
# The roots are DMA1_CHANNEL1 (a DMA half buffer into `on_captures`), TIM2 (an index capture)
# and SysTick (the partial half, the standstill poll, index pulses, the log). Walks the call
# graph of the disassembly (direct calls and jumps between functions, conditional ones
# included) from them and fails if it reaches a panic routine of `core` (a bounds check, an
# unwrap, an overflow, a slice length check, a RefCell already borrowed, `panic_fmt`), the
# panic handler, or an indirect call it cannot follow. The same walk as
# examples/qemu/panic-free.sh, from these roots. Builds the firmware first (nothing to do
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

"$objdump" -d "$elf" | strip_fill | awk -v chip="${chip:-default}" '
    # A function: "00012345 <symbol>:"
    /^[0-9a-f]+ <[^>]+>:$/ {
        cur = substr($2, 2, length($2) - 3)
        names[cur] = 1
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
    # An indirect call or jump (a register holds the target; "bx lr" is a return): not
    # followed, so not allowed.
    cur != "" && /\t(blx|bx)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?\t(r[0-9]+|ip|sb|sl|fp)([^0-9a-z]|$)/ { indirect[cur] = 1 }
    cur != "" && /\t(mov|ldr)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?(\.w)?\tpc,/ { indirect[cur] = 1 }
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
        logger = "^_defmt_(acquire|write|flush|release)$"
        bad_name = "panic|unwrap_failed|expect_failed|slice_(start|end)_index|slice_index|len_mismatch|rust_begin_unwind|index_out_of_bounds|already_borrowed|already_mutably_borrowed|HardFault"
        for (i = 0; i < n; i++) {
            f = queue[i]
            if (f ~ bad_name || f ~ logger) continue
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
            if (f ~ logger) { sinks++; continue }
            why = ""
            if (f ~ bad_name) why = "can panic"
            else if (f in indirect) why = "calls through a register"
            if (why == "") continue
            bad++
            chain = f
            for (g = seen[f]; g != "(handler)"; g = seen[g]) chain = g " -> " chain
            print "panic-free.sh: " why ": " chain > "/dev/stderr"
        }
        if (bad > 0) exit 1
        printf "panic-free (release, chip %s): %d functions reached from %d interrupt handlers, none can panic (not followed: %d entry points of the defmt-rtt logger)\n", chip, n - sinks, roots, sinks
    }
'
