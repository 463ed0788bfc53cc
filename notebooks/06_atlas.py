# %% [markdown]
# # A population stability atlas: how likely is a person's spine self-stable?
#
# The paper answers for one geometry, its optimum at $E \approx 3$ cm and $\Lambda \approx 4$ cm; its discussion is
# about people ("hypo- or hyperlordosis"). This notebook draws a cohort from the eight priors of
# `examples/atlas.toml` (the lordosis angle of 627 adults, the gravity line's distance, the upper body's mass and
# its height, the passive stiffness, the reflex delay, the activation lag, the co-contraction; each row names its
# source, and five say why they are not yet cohort distributions), solves every draw joint by joint (each CoR
# alone, the others fixed: the paper's criterion) and for the chain (all CoRs free), and asks
#
# - how likely each verdict is, with Wilson intervals;
# - which parameter decides each output: Sobol' first- and total-order indices (SALib, Saltelli's design);
# - where the cohort stands on the landscape of the minimum PCSA (Figure 3), and the paper's optimum.
#
# The lordosis is an angle at the edges only: $\theta = 2\,\mathrm{atan}(3\Lambda / L)$ for the natural spline
# (docs/atlas.md, "The lordosis as an angle").

# %% tags=["parameters"]
import os

GRID = int(os.environ.get("SPINECTL_NB_GRID", "81"))  # points per axis of the landscape under the cohort
SAMPLES = 64 if GRID < 81 else 512  # Saltelli base samples N (a power of 2): N (D + 2) evaluations

# %%
# %matplotlib inline

import dataclasses
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display

import spinectl
from spinectl.landscape import atlas, atlas_report, priors
from spinectl.model import clinical

ROOT = Path(spinectl.__file__).resolve().parents[1]
spec = priors.load_atlas(ROOT / "examples" / "atlas.toml")
spec = dataclasses.replace(spec, samples=SAMPLES)  # the file's N is for the command line; smaller here
display(
    pd.DataFrame(
        [(p.parameter, p.distribution, p.bounds, p.source[:70] + "...") for p in spec.priors],
        columns=["parameter", "distribution", "bounds", "source"],
    ).set_index("parameter")
)

# %% [markdown]
# ## The lordosis in degrees
#
# The paper's optimum $\Lambda = 4$ cm is a lordosis angle near the top of the cohort's range; the cohort's mean,
# 49.8°, is $\Lambda \approx 2.7$ cm.

# %%
model = spec.model
theta = float(clinical.lordosis_angle(0.04, model))
print(f"Lambda = 4 cm is {theta:.1f} deg (spine length L = {model.geometry.spine_length} m)")
print(f"49.8 deg is Lambda = {100 * float(clinical.lordosis_from_angle(49.8, model)):.2f} cm")

# %% [markdown]
# ## The verdicts and what decides them
#
# Each probability is over the $2N$ independent draws (Saltelli's matrices A and B), with a Wilson interval.
# The Sobol' indices say which parameter's spread makes each output's spread: $S_1$ alone, $S_T$ with all its
# interactions. With a small $N$ the bootstrap intervals are wide.

# %%
result = atlas.run_atlas(spec, progress=False)  # no folder: nothing written
print(result.table())
rows = [
    {"parameter": name, **{f"ST {out}": t[name]["ST"] for out, t in result.sobol.items() if t}} for name in spec.names
]
display(pd.DataFrame(rows).set_index("parameter").round(2))

# %%
fig, ax = plt.subplots(figsize=(7, 3.4), constrained_layout=True)
outputs = [out for out, table in result.sobol.items() if table]
width = 0.8 / len(spec.names)
for i, name in enumerate(spec.names):
    st = [result.sobol[out][name]["ST"] for out in outputs]
    err = [result.sobol[out][name]["ST_conf"] for out in outputs]
    ax.bar(np.arange(len(outputs)) + i * width, st, width, yerr=err, label=name)
ax.set_xticks(np.arange(len(outputs)) + 0.4 - width / 2, outputs, rotation=12)
ax.set_ylabel("total-order index $S_T$")
ax.legend(fontsize=7)
plt.show()

# %% [markdown]
# ## The cohort on the landscape
#
# The density of the draws' $(E, \Lambda)$ over the base model's minimum PCSA, and the paper's optimum.

# %%
landscape = atlas.base_landscape(spec, result.draws, n=GRID)
display(atlas_report.density_figure(landscape, result.draws, priors.PAPER_OPTIMUM))
