# %% [markdown]
# # Sinew from Python: the E4 case table and a Fig. 5 map
#
# Notebook-style (`# %%` cells: run it as a script, or open it in Jupyter or VS Code).
# Needs the `sinew` package (`pip install ./crates/sinew-py` or `maturin develop` in
# `crates/sinew-py`) and numpy; matplotlib only for the map (skipped without it).
#
# Run from the repository root: `python examples/python/e4_and_fig5.py`.

# %%
from pathlib import Path

import numpy as np

import sinew

ROOT = Path(__file__).resolve().parents[2]
robot = sinew.load_robot(ROOT / "robots" / "cdhrm5")
print(robot)

# %% [markdown]
# ## E4: the arm at the paper's pose under 5 N along y (src/paper/experiments.rs)
#
# Cases (a)-(d): every joint at the baseline level; joint 3, joint 5, joints 3 and 5 raised to
# their highest level (joints numbered from 1 here, as in the paper; 0-based in the API).

# %%
E4_Q = np.pi * np.array([-1 / 7, -1 / 9, -1 / 9, -1 / 11, 1 / 6, 1 / 7, 1 / 8, -1 / 15, -1 / 12, -1 / 10])
E4_F0 = np.array([0.0, 5.0, 0.0, 0.0, 0.0, 0.0])
E4_CASES = [
    ("(a) every joint at the baseline level", []),
    ("(b) joint 3 at its highest level", [3]),
    ("(c) joint 5 at its highest level", [5]),
    ("(d) joints 3 and 5 at their highest levels", [3, 5]),
]

for model, baseline in [("decoupled", 0.0), ("decoupled", 0.25), ("routed", 0.0)]:
    arm = sinew.ArmStiffness(robot, sinew.load_routing(robot, model))
    print(f"\n{model} model, joints not raised at level {baseline}")
    print(f"{'case':<46} {'λ_min(K_q+K_W)':>15} {'K_fd eigenvalues (N/m)':>34}")
    for name, raised in E4_CASES:
        levels = np.full(5, baseline)
        levels[[j - 1 for j in raised]] = 1.0
        try:
            r = arm.evaluate(E4_Q, E4_F0, levels=levels)
        except sinew.InfeasibleError as e:
            print(f"{name:<46} infeasible: {e}")
            continue
        eig = "unstable: no K_fd" if r.eigenvalues is None else np.array2string(r.eigenvalues, precision=2)
        print(f"{name:<46} {r.min_eigenvalue:>15.5f} {eig:>34}")

# %% [markdown]
# ## Fig. 5: joint 1's stiffness range over its two angles (torque 0.3, 0.3 N m)

# %%
routing = sinew.load_routing(robot, "decoupled")
maps = sinew.sweep(robot, routing, 0, [0.3, 0.3], points=61)
print(f"\nFig. 5 sweep: {maps.feasible.sum()} of {maps.feasible.size} points feasible")

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
    print("matplotlib not installed: no figure (pip install matplotlib)")

if plt is not None:
    deg = np.degrees(maps.angles)
    extent = [deg[0], deg[-1], deg[0], deg[-1]]
    fig, axes = plt.subplots(1, 2, figsize=(10, 4), constrained_layout=True)
    for ax, (title, m) in zip(axes, [("ΔK_x = K_x max − K_x min", maps.k_x_max - maps.k_x_min),
                                     ("ΔK_y = K_y max − K_y min", maps.k_y_max - maps.k_y_min)]):
        # Rows are q1, columns q2: put q1 on the x axis.
        im = ax.imshow(m.T, origin="lower", extent=extent, cmap="viridis")
        ax.set(title=title, xlabel="q1 (deg)", ylabel="q2 (deg)")
        fig.colorbar(im, ax=ax, label="N m/rad")
    out = Path("fig5-joint1.png")
    fig.savefig(out, dpi=120)
    print(f"wrote {out.resolve()}")
