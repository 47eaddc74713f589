#!/usr/bin/env python3
"""The table of a convolutional-network sweep (scripts/conv_sweep.sh OUT ...): one row per
trained network, from its run's manifest.

Columns: the setting, the seed, whether the network left the mean-picture plateau (the
manifest's `trained`: its loss fraction below 0.8), the loss fraction (reconstruction loss over
the mean-picture plateau), the total and sorted per-latent KL (nats), the active latents (KL above
ACTIVE_NATS), how many of them encode the ball only / the distractor only / both (per-latent
held-out R², the report's rule: one object's R² >= 0.5 and the other's < 0.1; both >= 0.1),
MIG and SAP against (ball x, y, distractor x, y).

The follow-up's acceptance (issue 44 item 3): about 4 active latents, two for the ball and two
for the distractor, and a MIG clearly above the VAE's.
"""

import json
import pathlib
import sys

ACTIVE_NATS = 0.5


def classify(ball, distractor):
    ball = ball or 0.0
    distractor = distractor or 0.0
    if ball >= 0.5 and distractor < 0.1:
        return "ball"
    if distractor >= 0.5 and ball < 0.1:
        return "distractor"
    if ball >= 0.1 and distractor >= 0.1:
        return "both"
    return "none"


def row(setting, manifest):
    q = manifest["latent_quality"]
    kl = q.get("kl_per_latent") or []
    r2 = {o["object"]: o["r2"] for o in q.get("per_latent", [])}
    active = [j for j, k in enumerate(kl) if k > ACTIVE_NATS]
    kinds = [classify(r2.get("ball", [None] * len(kl))[j], r2.get("distractor", [None] * len(kl))[j]) for j in active]
    dis = q.get("disentanglement") or {}
    ev = manifest["train"]["evidence"]
    return {
        "setting": setting,
        "seed": manifest["seed"],
        # The manifest's own verdict (loss fraction below its untrained fraction, 0.8): a
        # network on the mean-picture plateau encodes nothing, whatever its other columns say.
        "trained": "yes" if ev.get("trained") else "no",
        "loss_fraction": round(ev["loss_fraction"], 3),
        "kl_total": round(sum(kl), 2),
        "kl_sorted": " ".join(f"{k:.2f}" for k in sorted(kl, reverse=True)),
        "active": len(active),
        "ball": kinds.count("ball"),
        "distractor": kinds.count("distractor"),
        "both": kinds.count("both"),
        "mig": round(dis.get("mig", float("nan")), 3),
        "sap": round(dis.get("sap", float("nan")), 3),
    }


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: conv_sweep_summary.py SWEEP_DIR")
    root = pathlib.Path(sys.argv[1])
    rows = []
    for d in sorted(p for p in root.iterdir() if p.is_dir() and p.name != "models"):
        for f in sorted(d.glob("*.json")):
            rows.append(row(d.name, json.loads(f.read_text())))
    if not rows:
        sys.exit(f"no runs under {root}")
    cols = list(rows[0])
    print("| " + " | ".join(cols) + " |")
    print("|" + "---|" * len(cols))
    for r in rows:
        print("| " + " | ".join(str(r[c]) for c in cols) + " |")


if __name__ == "__main__":
    main()
