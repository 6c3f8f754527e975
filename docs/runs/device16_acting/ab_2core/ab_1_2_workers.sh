#!/bin/bash
# A/B on 2 cores: scaling.py 1 and 2 workers, base (HEAD~1, installed in /tmp/base_site) vs new, alternating
run() {
  if [ $1 = new ]; then (cd /work/main && python benchmarks/scaling.py --workers 1 2 --iterations 6 --json /tmp/prof/ab_$1_$2.json)
  else (cd /tmp/b_base && PYTHONPATH=/tmp/base_site python scaling.py --workers 1 2 --iterations 6 --json /tmp/prof/ab_$1_$2.json); fi 2>/dev/null | grep '^{"workers' | sed "s/^/$1 $2 /"
}
run new 1; run base 1; run base 2; run new 2; run new 3; run base 3
