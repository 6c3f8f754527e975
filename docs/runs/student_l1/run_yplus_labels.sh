#!/bin/bash
# yplus_labels.py (a diagnosis, choosing nothing): the students' distance to the y+ expert on its states and on theirs.
#   nohup bash docs/runs/student_l1/run_yplus_labels.sh > runs/yplus_labels.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
D=docs/runs/student_l1
PLAIN=allegro/student W30=$D/student_l1_s0.pt C=$D/student_l1_rep3_s0.pt F=$D/student_l1_rep3_w10_s0.pt
[ -f $D/yplus_labels_expert.json ] || python $D/yplus_labels.py allegro/rotate_y+ $D/yplus_labels_expert.json --labellers $PLAIN $W30 $C $F || exit 1
for S in shipped:$PLAIN w30:$W30 rep3:$C rep3w10:$F; do
  [ -f $D/yplus_labels_${S%%:*}.json ] || python $D/yplus_labels.py ${S#*:} $D/yplus_labels_${S%%:*}.json --labellers allegro/rotate_y+ || exit 1
done
echo DONE
