# %% [markdown]
# # One joint at a time versus the whole chain
#
# The paper linearises each lumbar joint "assuming all other CoR to be fixed" and finds one activation of the
# global muscles that makes every joint self-stable. Its introduction knows the catch: the global muscles "can only
# control the chain, but not the individual joints". This notebook frees all five joints at once
# (docs: *The coupled chain*) and asks, at the paper's own optimum,
#
# 1. is the **chain** (all 5 CoRs free) statically and dynamically stable, although every joint is, joint by joint
#    (each CoR alone, the others fixed; the paper's criterion)?
# 2. how much **local-muscle stiffness** does it need, and where over $E \times \Lambda$ is that least, beside the
#    counter torques of Figure 4?
# 3. what would the **joint optimum** of global and local muscle use?
# 4. can a **delayed reflex** hold the chain, as the paper's Discussion hopes for a self-stable spine?
#
# With all joints free, the linearised chain is $M\ddot q = K q + D\dot q + u$ with $5 \times 5$ matrices; its
# diagonal is the per-segment model ($K[k, k] = S_k$, $D[k, k] = D_k$). The chain is statically stable when $-K$ is
# positive definite, with the smallest eigenvalue of $-K$ as its margin [N m/rad]; local muscles add a stiffness
# $k_j \ge 0$ at joint $j$.

# %% tags=["parameters"]
import os

GRID = int(os.environ.get("SPINECTL_NB_GRID", "81"))  # points per axis over 0-8 cm: 81 is the paper's 1 mm step
PRESET = os.environ.get("SPINECTL_NB_PRESET", "")  # "": the calibrated "wagner2012" if installed, else "default"

# %%
# %matplotlib inline

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display

import spinectl
from spinectl.landscape import sweep
from spinectl.optimise.coupled import coupled_stability_at, joint_optimum
from spinectl.paper import grid, landmarks
from spinectl.reflex.chain_margins import coupled_margins
from spinectl.reflex.margins import margins_report

preset = PRESET or ("wagner2012" if "wagner2012" in spinectl.list_presets() else "default")
model = spinectl.load_preset(preset)
axis = grid.paper_axis(GRID)  # E and Lambda of the landscapes [m], the paper's 0 to 8 cm
POINTS = {"A": grid.POSITIONS["A"], "optimum": landmarks.OPTIMUM}  # (E, Lambda) [m]
CM, CM2 = 100.0, 1e4  # cm per m, cm^2 per m^2
print(f"preset {preset!r}: mass {model.body.mass:g} kg, K = {model.passive.stiffness:g} N m/rad")

# %% [markdown]
# ## 1. Every joint stable alone, the chain not
#
# At the paper's optimum (the minimum-PCSA activation of each point) every $S_k$ is negative: each joint is
# self-stable alone. The eigenvalues of $-K$ tell the chain's story.

# %%
chains = {name: coupled_stability_at(model, *where) for name, where in POINTS.items()}
rows = []
for name, c in chains.items():
    rows.append(
        {
            "position": name,
            "largest S_k [N m/rad]": np.diag(c.stiffness).max(),
            "eigenvalues of -K [N m/rad]": np.round(np.linalg.eigvalsh(-c.stiffness), 1),
            "chain: unstable modes (static)": int(np.sum(np.linalg.eigvalsh(-c.stiffness) < 0)),
            "chain: growing modes (dynamic)": int(np.sum(c.eigenvalues.real > 0)),
            "chain: fastest growth [1/s]": c.eigenvalues.real.max(),
        }
    )
display(pd.DataFrame(rows).set_index("position"))

# %% [markdown]
# The unstable modes bend some joints against others. Their shapes (the eigenvectors of $-K$ at the optimum) show
# why the global muscles cannot reach them: the muscles attach to thorax and pelvis only, so their lengths change
# with at most three combinations of the joint angles.

# %%
c = chains["optimum"]
values, vectors = np.linalg.eigh(-c.stiffness)
fig, ax = plt.subplots(figsize=(6, 3))
for i, value in enumerate(values):
    ax.plot(c.segment_names, vectors[:, i], marker="o", label=f"{value:.1f} N m/rad")
ax.axhline(0, color="0.7", lw=0.8)
ax.set_ylabel("joint angle (mode shape)")
ax.set_title("modes of the chain at the optimum, eigenvalue of -K")
ax.legend(fontsize=7, ncols=2)
plt.show()

# %% [markdown]
# ## 2. The local stiffness the chain needs, over the landscape
#
# The least local stiffness $\sum_j k_j$ with $\operatorname{diag}(k) - K \succeq \mu I$ is a small semidefinite
# programme per point; `sweep(..., coupled=True)` (`spinectl sweep --coupled`) solves a chunk of points as one
# (variables `local_stiffness_total_Nm_per_rad`, beside the static `coupled_margin_Nm_per_rad`). Beside it, Figure
# 4's $\|CT\|$.

# %%
land = sweep.sweep(model, axis, axis, progress=False, coupled=True)
fig, axes = plt.subplots(1, 3, figsize=(13, 3.6), constrained_layout=True)
extent = [axis[0] * CM, axis[-1] * CM, axis[0] * CM, axis[-1] * CM]
for ax, (name, title) in zip(
    axes,
    [
        ("counter_torque_norm_Nm", "||CT|| [N m] (Figure 4)"),
        ("local_stiffness_total_Nm_per_rad", "least local stiffness, total [N m/rad]"),
        ("coupled_margin_Nm_per_rad", "chain's static margin, global only [N m/rad]"),
    ],
    strict=True,
):
    image = ax.imshow(land[name].values.T, origin="lower", extent=extent, aspect="auto")
    fig.colorbar(image, ax=ax)
    ax.set(title=title, xlabel="E [cm]", ylabel="Lambda [cm]")
plt.show()

# %% [markdown]
# Does the lordosis that minimises the counter torques also minimise the local stiffness? At each eccentricity,
# the lordosis of least $\|CT\|$ and of least local stiffness:

# %%
best_ct = land["counter_torque_norm_Nm"].idxmin("Lambda")
best_local = land["local_stiffness_total_Nm_per_rad"].idxmin("Lambda")
compare = pd.DataFrame(
    {
        "E [cm]": axis * CM,
        "Lambda of least ||CT|| [cm]": best_ct.values * CM,
        "Lambda of least local stiffness [cm]": best_local.values * CM,
        "least local stiffness [N m/rad]": land["local_stiffness_total_Nm_per_rad"].min("Lambda").values,
    }
)
display(compare.iloc[:: max(1, (len(axis) - 1) // 8)].round(2).set_index("E [cm]"))
print(
    "the chain's static margin with the global muscles alone is negative everywhere: "
    f"{bool(float(land['coupled_margin_Nm_per_rad'].max()) < 0)} "
    f"(largest {float(land['coupled_margin_Nm_per_rad'].max()):.1f} N m/rad)"
)

# %% [markdown]
# ## 3. The joint optimum
#
# Global and local muscle together, each cm² costing the same (`local.cost_weight` = 1), with the local stiffness
# converted to a PCSA by the short-range-stiffness model of the docs ($q = 10$; every local PCSA scales with $1/q$).

# %%
rows = []
for name, where in POINTS.items():
    paper = chains[name]
    joint = joint_optimum(model, *where)
    rows.append(
        {
            "position": name,
            "paper: global PCSA [cm2]": paper.pcsa.sum() * CM2,
            "paper + least local: local PCSA [cm2]": paper.local.total_local_pcsa * CM2,
            "joint optimum: global [cm2]": joint.total_pcsa * CM2,
            "joint optimum: local [cm2]": joint.total_local_pcsa * CM2,
            "status": joint.status,
        }
    )
display(pd.DataFrame(rows).set_index("position").round(2))

# %% [markdown]
# ## 4. The delayed reflex: one joint at a time versus the chain
#
# `spinectl margins` closes each joint's loop alone: at half the minimum PCSA (`reflex.activation` = 0.5) every
# joint's reflex tolerates some delay. On the chain, the same idea (a diagonal PD reflex, $k_p$ from the chain's
# stiffness deficit, the least local stiffness; docs: *The delayed reflex on the chain*) meets the fast modes that
# bend joints against each other. The exact delay margin of the coupled loop:

# %%
rows = []
for name, where in POINTS.items():
    per_joint = margins_report(model, *where)
    chain_margin = coupled_margins(model, *where)
    rows.append(
        {
            "position": name,
            "joint by joint: least delay margin [ms]": min(s.delay_margin for s in per_joint.segments) * 1e3,
            "chain's delay margin [ms]": chain_margin.exact.margin * 1e3,
            "Pade estimate [ms]": chain_margin.delay_margin_pade * 1e3,
            "chain stable at 100 ms": chain_margin.stable_at_delay,
        }
    )
display(pd.DataFrame(rows).set_index("position"))

# %% [markdown]
# ## What this means for the paper
#
# - One joint at a time, the paper's optimum is self-stable everywhere; the chain is not, anywhere on the grid: the
#   global muscles leave two to three intervertebral modes without stiffness, and their compression buckles them.
# - The local muscles close the gap with a small PCSA, well inside the paper's 17 cm² limit per joint, and together
#   with the global muscles they need less muscle than the paper's optimum alone.
# - A delayed reflex cannot take the local muscles' place: the chain's delay margin is a fraction of a millisecond,
#   against reflex delays of up to 100 ms. The intervertebral modes need intrinsic stiffness.
# - The lordosis of least counter torques is not where the chain needs least local stiffness (the table of
#   section 2): that need is largest near the ridge of the minimum PCSA, on which the paper's optimum lies, and least
#   towards the edges of the grid.
