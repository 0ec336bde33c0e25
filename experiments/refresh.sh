#!/bin/sh
# Regenerates results/NAME from experiments/NAME.json for every experiment
# file (the seed's figures, the scene, the variance tables), in the order
# of their names, and prints each one's wall time and the total.
# Usage, from anywhere: experiments/refresh.sh [NAME ...]
set -eu
top="$(cd "$(dirname "$0")/.." && pwd)"
cd "$top"
cargo build --release --quiet
if [ "$#" -eq 0 ]; then
    set -- $(ls experiments/*.json | sed 's|experiments/||; s|\.json$||')
fi
total_start=$(date +%s)
for name in "$@"; do
    start=$(date +%s)
    ./target/release/varspec experiment "experiments/$name.json" -o "results/$name" >/dev/null
    echo "$name: $(( $(date +%s) - start )) s"
done
echo "total: $(( $(date +%s) - total_start )) s"
