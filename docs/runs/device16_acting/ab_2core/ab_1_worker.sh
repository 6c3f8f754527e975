#!/bin/bash
run() {
  if [ $1 = new ]; then (cd /work/main && python benchmarks/scaling.py --workers 1 --iterations 8 --env-steps 300)
  else (cd /tmp/b_base && PYTHONPATH=/tmp/base_site python scaling.py --workers 1 --iterations 8 --env-steps 300); fi 2>/dev/null | grep '^{"workers' | sed "s/^/$1 $2 /"
}
for i in 1 2 3 4 5; do if [ $((i % 2)) = 1 ]; then run new $i; run base $i; else run base $i; run new $i; fi; done
