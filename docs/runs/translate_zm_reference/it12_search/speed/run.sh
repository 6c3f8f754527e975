set -u  # from the repository root; writes runs/zm_speed/
base=$(cat docs/runs/translate_zm_reference/it12_search/chosen.txt)
for k in 1.0 1.15 1.3; do
  seq=$(python3 -c "
import sys
k=float(sys.argv[1]); out=[]
for part in sys.argv[2].split('+'):
    f=part.split(':'); f[2]='%.4f'%(float(f[2])*k); out.append(':'.join(f))
print('+'.join(out))" $k "$base")
  .venv/bin/unicross eval --policy "seq:$seq" --hand allegro --protocol translate --axis z- --objects train --limit 8 --trials-per-object 2 --seed 600 --workers 2 --out runs/zm_speed/x$k.json > runs/zm_speed/x$k.log 2>&1
  echo "$k $(grep -i -m1 'translate' runs/zm_speed/x$k.log)"; tail -3 runs/zm_speed/x$k.log
done
