# The call graph of a Thumb-2 firmware image, for the panic-free checks of the example
# firmware (examples/qemu/panic-free.sh, examples/stm32g4/panic-free.sh). Input: the output of
# `llvm-objdump -d` with the linker's fill dropped (examples/tools/disasm.sh). Each script adds
# its own END, which picks the roots and calls the functions below.
#
# After the input: names[f] for every function f; size[f], its bytes up to the next function
# (literal pool and padding included); edges[f], the functions f calls or jumps to directly
# (space-separated, conditional branches included); indirect[f] when f calls or jumps through
# a register, which no walk can follow.

# A function: "00012345 <symbol>:"
/^[0-9a-f]+ <[^>]+>:$/ {
    cur = substr($2, 2, length($2) - 3)
    names[cur] = 1
    addr = 0
    for (k = 1; k <= length($1); k++) addr = addr * 16 + index("0123456789abcdef", substr($1, k, 1)) - 1
    if (prev != "") size[prev] = addr - start[prev]
    start[cur] = addr
    prev = cur
    next
}
# A direct call or jump to another function: "bl 0x... <symbol+0x..>", conditional ones too
# (a branch, or a call inside an IT block: "blne").
cur != "" && /\t(b|bl|blx)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?(\.w|\.n)?\t|\t(cbz|cbnz)\t/ && /</ {
    t = $0
    sub(/^[^<]*</, "", t)
    sub(/>.*$/, "", t)
    sub(/\+0x[0-9a-f]+$/, "", t)
    if (t != cur) edges[cur] = edges[cur] " " t
    next
}
# An indirect call or jump (a register holds the target; "bx lr" is a return).
cur != "" && /\t(blx|bx)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?\t(r[0-9]+|ip|sb|sl|fp)([^0-9a-z]|$)/ { indirect[cur] = 1 }
cur != "" && /\t(mov|ldr)(eq|ne|cs|cc|hs|lo|mi|pl|vs|vc|hi|ls|ge|lt|gt|le|al)?(\.w)?\tpc,/ { indirect[cur] = 1 }

# The names of core's panic routines (a bounds check, an unwrap, an overflow, a slice length
# check, a failed precondition, `panic_fmt`, the panic handler).
function panic_names() {
    return "panic|unwrap_failed|expect_failed|slice_(start|end)_index|slice_index|len_mismatch|rust_begin_unwind|index_out_of_bounds"
}

# Breadth-first from queue[0 .. n-1] (each root with seen[root] = label): queue[] and seen[]
# (the caller of each function reached) grow; the walk does not go on past functions named
# by `stop` or `skip` (regular expressions). Returns the number of functions reached.
function walk(n, stop, skip,    i, j, f, g, out) {
    for (i = 0; i < n; i++) {
        f = queue[i]
        if (f ~ stop || (skip != "" && f ~ skip)) continue
        split(edges[f], out, " ")
        for (j in out) {
            g = out[j]
            if (g == "" || g in seen) continue
            seen[g] = f
            queue[n++] = g
        }
    }
    return n
}

# Prints, for each function of queue[0 .. n-1] named by `stop` ("can panic") or calling
# through a register, the chain of calls from its root (whose seen[] is `label`). Functions
# named by `skip` are not judged. Returns how many there are.
function offenders(n, stop, skip, label,    i, f, g, why, chain, bad) {
    bad = 0
    for (i = 0; i < n; i++) {
        f = queue[i]
        if (skip != "" && f ~ skip) continue
        why = ""
        if (f ~ stop) why = "can panic"
        else if (f in indirect) why = "calls through a register"
        if (why == "") continue
        bad++
        chain = f
        for (g = seen[f]; g != label; g = seen[g]) chain = g " -> " chain
        print "panic-free.sh: " why ": " chain > "/dev/stderr"
    }
    return bad
}
