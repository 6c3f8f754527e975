#!/bin/bash
# rule.txt amendment 2: seed 2's candidate (runs/tzpchain/ft_s2, from seeds.sh) against the shipped expert on
# evaluation seeds 4-7: the chain, the test cell, the unseen and --disturb cells, into runs/tzpchain/confirm/, then the
# judge. Each step is skipped when its file exists.
#   nohup bash docs/runs/translate_zp_chain/confirm.sh > runs/tzpchain/confirm.log 2>&1 &
set -x
cd "$(dirname "$0")/../../.."
source .venv/bin/activate
R=runs/tzpchain
C=$R/confirm
mkdir -p $C
[ -f $R/experts_c2/translate_z+/checkpoint.pt ] && cmp -s $R/experts_c2/translate_z+/checkpoint.pt $R/ft_s2/policy.pt \
  || { echo "run seeds.sh 2 first"; exit 1; }
for E in 4 5 6 7; do
  for who in cand shipped; do
    if [ $who = shipped ]; then X=experts:allegro P=allegro/translate_z+; else X=experts:$R/experts_c2 P=$R/ft_s2/policy.pt; fi
    [ -f $C/chain_${who}_s$E.json ] || unicross chain --policy $X --sequence grasp,relocate,translate:z+ --objects test \
      --limit 10 --trials-per-object 5 --seed $E --out $C/chain_${who}_s$E.json > $C/chain_${who}_s$E.log 2>&1 || exit 1
    for cell in "cell test" "unseen unseen" "dist test --disturb"; do
      set -- $cell
      F=$C/$1_${who}_s$E.json
      [ -f $F ] || unicross eval --policy $P --protocol translate --axis z+ --objects $2 $3 --limit 10 \
        --trials-per-object 5 --seed $E --workers 2 --out $F > ${F%.json}.log 2>&1 || exit 1
    done
  done
done
python docs/runs/translate_zm_chain/judge.py $C --mode translate_z+ --gain 3 --guard --seeds 4 5 6 7 > $C/judge.txt
echo DONE
