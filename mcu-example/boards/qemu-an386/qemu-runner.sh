#!/bin/sh
# cargo's runner for this board (`cargo run --release` here): boots the ELF in QEMU against the
# simulated chassis and decodes its defmt log, through `cargo xtask qemu`. It runs xtask from
# the repository root, where this board's target setting does not apply.
set -e
elf="$(cd "$(dirname "$1")" && pwd)/$(basename "$1")"
shift
cd "$(dirname "$0")/../../.."
exec cargo xtask qemu "$elf" "$@"
