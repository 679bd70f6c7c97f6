"""A stiffness map over cdhrm5's whole workspace, on a Dask cluster.

Samples 10**6 poses uniformly within the joint limits (seeded), evaluates each under E4's
load (5 N along +y, the tip pressing on a surface) at two tension choices (every joint at
tension level 0, the least total tension, and at level 1, the most), and writes

- an ``.npz``: the seed and sampling rule, ``q11``/``q12`` (joint 1's two angles) and, per
  choice, ``ok``, ``stable`` and ``lambda_min`` (the smallest eigenvalue of K_fd, N/m; NaN
  where unstable or failed);
- a figure: the share of unstable poses, and the distribution of λ_min(K_fd) over the
  workspace, both by joint 1's first angle.

Runs on a LocalCluster of one single-threaded worker per core by default, or on a running
cluster with ``--scheduler tcp://HOST:8786``. Needs ``pip install "./crates/sinew-py[examples]"``
(dask[array], distributed, matplotlib).

    python examples/python/workspace_map.py                      # 10**6 poses, local cluster
    python examples/python/workspace_map.py --rows 100000 --out /tmp/map
"""

import argparse
import time
from pathlib import Path

import distributed
import numpy as np

import sinew
import sinew.dask

ROOT = Path(__file__).resolve().parents[2]
E4_F0 = np.array([0.0, 5.0, 0.0, 0.0, 0.0, 0.0])
CHOICES = {"level 0 (least tension)": 0.0, "level 1 (most tension)": 1.0}


def sample(robot, rows, seed):
    """``rows`` poses uniform within the joint limits: ``lo + (hi - lo) * U[0, 1)``, with
    numpy's default generator seeded by ``seed`` (the rule the .npz records)."""
    rng = np.random.default_rng(seed)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    return lo + (hi - lo) * rng.random((rows, robot.dof))


def lambda_min(m):
    """λ_min(K_fd) per row, NaN where K_fd does not exist (failed, unstable, rank < 6)."""
    out = np.full(len(m), np.nan)
    has = m.ok & m.stable & np.isfinite(m.k_fd).all(axis=(1, 2))
    k = m.k_fd[has]
    out[has] = np.linalg.eigvalsh(0.5 * (k + k.transpose(0, 2, 1)))[:, 0]
    return out


def figure(path, q11, maps, limits):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    edges = np.linspace(limits[0], limits[1], 31)
    centres = np.degrees(0.5 * (edges[1:] + edges[:-1]))
    bins = np.clip(np.digitize(q11, edges) - 1, 0, len(edges) - 2)
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 4.8), constrained_layout=True)
    for (label, m), colour in zip(maps.items(), ["tab:red", "tab:blue"]):
        evaluated = m["ok"]
        unstable = evaluated & ~m["stable"]
        share = np.array([unstable[bins == k].sum() / max(evaluated[bins == k].sum(), 1)
                          for k in range(len(centres))])
        total = unstable.sum() / max(evaluated.sum(), 1)
        a.plot(centres, 100 * share, "o-", color=colour, ms=3,
               label=f"{label}: {100 * total:.1f} % of all poses")
        lam = m["lambda_min"]
        qs = np.array([np.nanpercentile(lam[bins == k], [10, 50, 90])
                       if np.isfinite(lam[bins == k]).any() else [np.nan] * 3
                       for k in range(len(centres))])
        b.fill_between(centres, qs[:, 0], qs[:, 2], color=colour, alpha=0.2)
        b.plot(centres, qs[:, 1], "-", color=colour,
               label=f"{label}: median, 10–90 % band")
    a.set(xlabel="joint 1 angle q₁₁ (deg)", ylabel="unstable poses (%)",
          title="Share of poses with K_q + K_W not positive definite", ylim=(0, None))
    b.set(xlabel="joint 1 angle q₁₁ (deg)", ylabel="λ_min(K_fd) (N/m)", yscale="log",
          title="Softest translational stiffness over the stable poses")
    for ax in (a, b):
        ax.grid(alpha=0.3)
        ax.legend(fontsize=8)
    rows = len(q11)
    fig.suptitle(f"cdhrm5, {rows:,} poses uniform within the limits, load 5 N along +y (E4)")
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rows", type=int, default=1_000_000)
    parser.add_argument("--seed", type=int, default=2024)
    parser.add_argument("--chunk", type=int, default=sinew.dask.DEFAULT_CHUNK)
    parser.add_argument("--scheduler", default=None,
                        help="a Dask scheduler's address (default: a LocalCluster here)")
    parser.add_argument("--model", default="decoupled", choices=["decoupled", "routed"])
    parser.add_argument("--out", default="workspace_map",
                        help="writes OUT.npz and OUT.png (default: ./workspace_map.*)")
    args = parser.parse_args()

    robot = sinew.load_robot(ROOT / "robots" / "cdhrm5")
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, args.model))
    Q = sample(robot, args.rows, args.seed)
    saved = {"seed": args.seed, "rows": args.rows, "limits": robot.limits,
             "q11": Q[:, 0], "q12": Q[:, 1], "wrench": E4_F0}
    maps = {}
    # One cluster for both maps: a LocalCluster of one single-threaded worker per core, or
    # the running one at --scheduler.
    if args.scheduler:
        client = distributed.Client(args.scheduler)
    else:
        client = distributed.Client(distributed.LocalCluster(
            threads_per_worker=1, processes=True, dashboard_address=None))
    print(f"cluster: {len(client.scheduler_info()['workers'])} workers")
    for (label, level), key in zip(CHOICES.items(), ["level0", "level1"]):
        start = time.perf_counter()
        m = sinew.dask.map_evaluate(arm, Q, wrench=E4_F0, levels=[level] * robot.joints,
                                    chunk=args.chunk, client=client)
        took = time.perf_counter() - start
        lam = lambda_min(m)
        maps[label] = {"ok": m.ok, "stable": m.stable, "lambda_min": lam}
        saved.update({f"{key}_ok": m.ok, f"{key}_stable": m.stable, f"{key}_lambda_min": lam})
        print(f"{label}: {args.rows:,} poses in {took:.1f} s "
              f"({args.rows / took / 1e3:.0f} k/s); "
              f"{int((~m.ok).sum())} failed, {int((m.ok & ~m.stable).sum())} unstable, "
              f"median λ_min(K_fd) {np.nanmedian(lam):.4g} N/m")
    client.close()
    out = Path(args.out)
    np.savez(out.with_suffix(".npz"), **saved)
    figure(out.with_suffix(".png"), Q[:, 0], maps, robot.limits[0])
    print(f"wrote {out.with_suffix('.npz')} and {out.with_suffix('.png')}")


if __name__ == "__main__":
    main()
