# Translation from each grasp expert's grasps (2026-11-27, fifteenth session, commit adaf037; ~1 min per line on 2 cores).
# runs/grasp_K_grasps.pt: the datasets of section 4 (first 20 training objects per group, 2 grasps each; sidecars in ..).
D=docs/runs/gait_search/thumb_grasps/grasp_seeds/translate
SPEC="seq:index:2:0.1:0:1000+ring:2:0.05:@index:0.9+middle:2:0.05:@ring:0.9"   # the relay the shipped z- clone imitates
for s in shipped s0 s1 s2; do
  unicross eval --policy "$SPEC" --protocol translate --axis z- --objects train --limit 20 --trials-per-object 2 --seed 0 --workers 2 --grasps runs/grasp_${s}_grasps.pt --out $D/zm_relay_$s.json
  unicross eval --policy allegro/translate_z+ --protocol translate --axis z+ --objects train --limit 20 --trials-per-object 2 --seed 0 --workers 2 --grasps runs/grasp_${s}_grasps.pt --out $D/zp_$s.json
done
