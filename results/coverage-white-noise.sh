#!/bin/sh
# z = (spatial − Var(f)/N)/stderr for white noise on disk r=0.3 at N=1024, 100 seeds,
# with --sets 16 ("fixed") and with predict's automatic count ("auto"); results/reliability.md.
# Set V to the release binary (default: target/release/varspec).
V=${V:-target/release/varspec}
for s in $(seq 1000 1099); do
  for mode in fixed auto; do
    if [ $mode = fixed ]; then extra="--sets 16"; else extra=""; fi
    $V predict --sampler random -n 1024 --integrand disk:r=0.3 --method spatial --seed $s $extra --json 2>/dev/null \
      | python3 -c "import json,sys; d=json.load(sys.stdin)['spatial']; print('$mode', (d['variance']-0.28274333882308139*(1-0.28274333882308139)/1024)/d['stderr'], d['sets'])"
  done
done
