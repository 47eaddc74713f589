"""Variance components of the final KL-coverage of a campaign with exploration replicates.

    python3 scripts/variance_components.py RESULTS_DIR     # e.g. the noise campaign's

Per cell (env, algorithm, latent size): F repetitions (each its own data set and fitted goal
space) x E exploration replicates (`[campaign] explorations`). One-way random-effects ANOVA:
sigma_explore^2 = the mean within-repetition variance, sigma_fit^2 = (MSB - MSW) / E (0 when
negative). RGE-EFR has no fit, so its sigma_fit estimates 0: how far it lands from 0 is the
estimator's own noise at this F. Then, per pair of algorithms of one environment, the spread of
the paired differences (same repetition and replicate) against the unpaired spread.
Reads only the manifests (`summary.final_klc`, `seed`, `exploration`); numpy.
"""
import json, glob, sys, collections, itertools
import numpy as np
d = sys.argv[1]
runs = collections.defaultdict(dict)
for f in glob.glob(f"{d}/*.json"):
    if f.endswith("campaign.json"): continue
    m = json.load(open(f))
    if "summary" not in m: continue
    key = (m["env"], m["algo"], m["latents"])
    runs[key][(m["seed"], m.get("exploration", 0))] = m["summary"]["final_klc"]
print("cell  F E  mean  sd_total  sigma_fit  sigma_explore  share_fit")
comp = {}
for key in sorted(runs):
    r = runs[key]
    seeds = sorted({s for s, _ in r}); exps = sorted({e for _, e in r})
    X = np.array([[r[(s, e)] for e in exps] for s in seeds])
    F, E = X.shape
    msw = X.var(axis=1, ddof=1).mean()
    msb = E * X.mean(axis=1).var(ddof=1)
    sf2 = max((msb - msw) / E, 0.0)
    comp[key] = X
    print(key, F, E, f"{X.mean():.3f} {X.std(ddof=1):.3f} {np.sqrt(sf2):.3f} {np.sqrt(msw):.3f} {sf2/(sf2+msw):.2f}")
# pairing: learners of one env, same (seed, exploration)
for env in sorted({k[0] for k in comp}):
    ks = [k for k in comp if k[0] == env]
    for a, b in itertools.combinations(ks, 2):
        A, B = comp[a], comp[b]
        diff = (A - B).ravel()
        r = np.corrcoef(A.ravel(), B.ravel())[0, 1]
        print(f"pair {a[1]} - {b[1]} ({env}): sd(paired diff) {diff.std(ddof=1):.3f}, "
              f"sqrt(var a + var b) {np.sqrt(A.var(ddof=1) + B.var(ddof=1)):.3f}, r = {r:.2f}; "
              f"fit means r = {np.corrcoef(A.mean(1), B.mean(1))[0,1]:.2f}")
