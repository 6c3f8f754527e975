"""clone weights + a PPO run's normaliser statistics (and the reverse), to test whether the
statistics' drift alone moves the policy."""
import sys, torch
clone_path, run_ckpt, out_a, out_b = sys.argv[1:5]
c = torch.load(clone_path, weights_only=False)
r = torch.load(run_ckpt, weights_only=False)
norm_keys = [k for k in c["policy"] if ".norm." in k]
a = dict(c); a["policy"] = dict(c["policy"])
for k in norm_keys:
    a["policy"][k] = r["policy"][k].clone()
torch.save(a, out_a)
b = dict(c); b["policy"] = dict(r["policy"])
for k in norm_keys:
    b["policy"][k] = c["policy"][k].clone()
torch.save(b, out_b)
print("count clone", float(c["policy"][[k for k in norm_keys if k.endswith("count")][0]]),
      "run", float(r["policy"][[k for k in norm_keys if k.endswith("count")][0]]))
