#!/bin/bash
# A/B on 2 cores: scaling.py, 2 workers, 8 iterations, base (the commit before acting_fn, installed in
# /tmp/base_site) vs new, alternating order per pair
run() {
  if [ $1 = new ]; then (cd /work/main && python benchmarks/scaling.py --workers 2 --iterations 8 --env-steps 600)
  else (cd /tmp/b_base && PYTHONPATH=/tmp/base_site python scaling.py --workers 2 --iterations 8 --env-steps 600); fi 2>/dev/null | grep '^{"workers' | sed "s/^/$1 $2 /"
}
for i in 1 2 3 4 5 6; do if [ $((i % 2)) = 1 ]; then run new $i; run base $i; else run base $i; run new $i; fi; done
