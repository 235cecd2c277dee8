# The disassembly the panic-free checks read (sourced by examples/*/panic-free.sh).
#
# Needs: the rustup component llvm-tools (rustup component add llvm-tools) for llvm-objdump.

# Prints the path of llvm-objdump, or fails saying how to install it.
objdump_path() {
    local objdump
    objdump="$(find "$(rustc --print sysroot)" -name llvm-objdump -type f 2>/dev/null | head -n 1)"
    if [ -z "$objdump" ]; then
        echo "panic-free.sh: llvm-objdump not found; install it with: rustup component add llvm-tools" >&2
        return 1
    fi
    echo "$objdump"
}

# `disassemble OBJDUMP ELF`: the disassembly of ELF without the linker's fill. The linker
# fills the gap before an aligned function with 0xd4d4 halfwords, which disassemble as a
# branch ("bmi"); a run of d4d4 that no other instruction follows in its function is that
# fill, not code (a conditional branch cannot end a function), and is dropped (the raw bytes
# are shown for this only). (A gap of two halfwords left its first one in, read as a branch
# into whatever function its offset named.)
disassemble() {
    "$1" -d "$2" | awk '
        /^ *[0-9a-f]+: d4d4 / { fill = fill $0 "\n"; next }
        fill != "" { if ($0 ~ /^ *[0-9a-f]+:/) printf "%s", fill; fill = "" }
        { print }
    '
}
