#!/bin/bash
# rule.txt screen L: `run_l.sh SEED` runs K's stage with env.chain_repeats={rotate_x+: 1, translate_z-: 3} from K's
# initial student (runs/student_pre_k.pt, the allegro/student of commit 06e213f^) on one training seed: the export
# (tag _chz), the report's cells, x+ on the 120 held-out trials (common.sh rep_screen), the rotate cells and the long
# horizon under evaluation seeds 1-3. Judged by judge_i.py L (L3). Each step is skipped when its file exists.
#   nohup bash -c 'for s in 13 14 15; do bash docs/runs/student_l1/run_l.sh $s || exit 1; done' > runs/student_l1_l.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
source docs/runs/student_l1/common.sh
S=$1
[ -f runs/student_pre_k.pt ] || git show 06e213f^:unicross/checkpoints/allegro/student.pt > runs/student_pre_k.pt || exit 1
rep_screen runs/l1rep3chz_s$S _chz $S --set "optim.mode_weights={rotate_x+: 5}" \
  --set model.init_policy=runs/student_pre_k.pt --set 'env.chain_repeats={rotate_x+: 1, translate_z-: 3}' || exit 1
seed_evals _chz $S || exit 1
echo DONE
