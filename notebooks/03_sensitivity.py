# %% [markdown]
# # Sensitivity: what moves the optimum
#
# The paper's conclusion rests on where two landscapes put their features: the local counter torques are least
# "along the angle bisector", and "the optimal combinations of eccentricity and spinal curvature are found in the
# range where the required PCSA of the global musculature is maximal", with the optimum at "$E \approx 3$ cm and
# [...] $\Lambda \approx 4$ cm". The paper does not state the upper-body mass or where the muscles attach, and
# reads the passive stiffness $K$ in a form whose units do not match. This notebook asks how much each of these
# moves
#
# - the **optimum**: the lordosis $\Lambda$ of least $\|CT\|$ at $E = 3$ cm and the slope $\Lambda/E$ of the
#   valley of $\|CT\|$; where the **minimum PCSA peaks**, at $E = 3$ cm and as the slope of its ridge;
# - the **minimum PCSA** at the positions A ($E = \Lambda = 0$) and B ($E = 8$ cm, $\Lambda = 0$) and on the
#   ridge,
#
# for the mass, $K$ (both readings), the attachment geometry and the activation mode.

# %% tags=["parameters"]
import os

GRID = int(os.environ.get("SPINECTL_NB_GRID", "81"))  # points per axis over 0-8 cm: 81 is the paper's 1 mm step
PRESET = os.environ.get("SPINECTL_NB_PRESET", "")  # "": spinectl's default preset, the calibrated "wagner2012"

# %%
# %matplotlib inline

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display

import spinectl
from spinectl.landscape import sweep
from spinectl.model import config
from spinectl.paper import grid, landmarks

preset = PRESET or spinectl.DEFAULT_PRESET  # the preset of every command and of spinectl.load_preset()
model = config.set_parameter(spinectl.load_preset(preset), "passive.stiffness", 0.0)  # K = 0, as in Figure 3
axis = grid.paper_axis(GRID)  # E and Lambda of the landscapes [m], the paper's 0 to 8 cm
E_OPT = landmarks.OPTIMUM[0]  # m: the paper's eccentricity, 3 cm
line = np.linspace(0.0, 0.08, 161)  # Lambda [m] at E = 3 cm, 0.5 mm apart: cheap, so finer than the landscapes
CM = 100.0  # cm per m
print(
    f"preset {preset!r}: mass {model.body.mass:g} kg, K convention {model.passive.convention!r}, "
    f"activation {model.optimisation.activation!r}"
)

# %% [markdown]
# One function measures a model: a landscape over $E \times \Lambda$ for A, B, the ridge and the two slopes
# (`landmarks.line_slope` fits $\Lambda = sE$ through the crest, located between grid points), and a fine
# line along $\Lambda$ at $E = 3$ cm for where the optimum and the peak sit there.


# %%
def measure(variant):
    """The optimum and the minimum PCSA of one model, as a dict of numbers with units in the keys."""
    land = sweep.sweep(variant, axis, axis)
    at_e = sweep.sweep(variant, [E_OPT], line).isel(E=0)
    ct, pcsa = at_e["counter_torque_norm_Nm"].values, at_e["min_pcsa_cm2"].values
    return {
        "min PCSA at A [cm²]": landmarks.at(land, "min_pcsa_cm2", grid.POSITIONS["A"]),
        "min PCSA at B [cm²]": landmarks.at(land, "min_pcsa_cm2", grid.POSITIONS["B"]),
        "ridge height [cm²]": float(land["min_pcsa_cm2"].max()),
        "ridge slope Λ/E [1]": landmarks.line_slope(land, "min_pcsa_cm2", "max"),
        "valley slope Λ/E [1]": landmarks.line_slope(land, "counter_torque_norm_Nm", "min"),
        "Λ of peak PCSA at E = 3 cm [cm]": line[np.nanargmax(pcsa)] * CM if np.isfinite(pcsa).any() else np.nan,
        "Λ of least ‖CT‖ at E = 3 cm [cm]": line[np.nanargmin(ct)] * CM if np.isfinite(ct).any() else np.nan,
        "least ‖CT‖ at E = 3 cm [N m]": float(np.nanmin(ct)) if np.isfinite(ct).any() else np.nan,
    }


def study(variants, name):
    """measure() of every model in ``variants`` (a dict value -> model), as a table indexed by ``name``."""
    return pd.DataFrame([measure(m) for m in variants.values()], index=pd.Index(list(variants), name=name))


def plot_study(table, xlabel, title, through_origin=False):
    """Three panels against the varied parameter: minimum PCSA, positions at E = 3 cm, slopes.

    ``through_origin``: also the lines from the origin through the last points of the first panel.
    """
    fig, axes = plt.subplots(1, 3, figsize=(12, 3.6), layout="constrained")
    x = table.index.values
    for column in ("min PCSA at A [cm²]", "min PCSA at B [cm²]", "ridge height [cm²]"):
        axes[0].plot(x, table[column], "o-", label=column.split(" [")[0])
        if through_origin:
            axes[0].plot([0, x[-1]], [0, table[column].iloc[-1]], ":", color="grey")
    if through_origin:
        axes[0].set_xlim(left=0)
        axes[0].set_ylim(bottom=0)
        axes[0].plot([], [], ":", color="grey", label="proportional (through 0)")
    for column in ("Λ of least ‖CT‖ at E = 3 cm [cm]", "Λ of peak PCSA at E = 3 cm [cm]"):
        axes[1].plot(x, table[column], "o-", label=column.split(" at E")[0])
    for column in ("valley slope Λ/E [1]", "ridge slope Λ/E [1]"):
        axes[2].plot(x, table[column], "o-", label=column.split(" Λ/E")[0])
    for ax, ylabel in zip(axes, ("minimum PCSA [cm²]", "Λ at E = 3 cm [cm]", "slope Λ/E [1]"), strict=True):
        ax.set_xlabel(xlabel)
        ax.set_ylabel(ylabel)
        ax.legend(fontsize=8)
    fig.suptitle(title)
    plt.show()


baseline = measure(model)
pd.Series(baseline, name=preset).round(3).to_frame()

# %% [markdown]
# ## The mass
#
# With $K = 0$ every term of the problem scales with the mass $m$: gravity's destabilising stiffness
# $\partial M_{ext}/\partial\alpha = mgr$ and its torque are proportional to $m$, and the muscles' stiffness and
# torque to their PCSA. So if $x^*$ is the optimum for $m$, $\lambda x^*$ is the optimum for $\lambda m$: the
# minimum PCSA and the counter torques scale exactly with $m$, and the optimum does not move. Exactly, that is,
# up to the solver's small stability and damping margins, which do not scale; with the margins set to zero the
# deviation from proportionality is rounding. A passive stiffness $K$ does not scale with $m$, and breaks it.
# Below, the largest deviation over the grid and the masses, relative to the largest value.

# %%
MASSES = model.body.mass * np.array([0.5, 0.75, 1.0, 1.25, 1.5])  # kg


def with_mass(variant, mass):
    return config.set_parameter(variant, "body.mass", float(mass))


no_margins = config.set_parameter(model, "optimisation.stability_margin", 0.0)
no_margins = config.set_parameter(no_margins, "optimisation.damping_margin", 0.0)
settings = {
    "K = 0, no margins": no_margins,
    "K = 0, default margins": model,
    f"K = {grid.PAPER_STIFFNESS:g} N m/rad": config.set_parameter(
        model, "passive.stiffness", grid.PAPER_STIFFNESS
    ),
}


def largest_relative_change(field, reference, scale):
    """max |field - scale reference| / max |scale reference| over the grid [1]."""
    return float(abs(field - scale * reference).max() / abs(scale * reference).max())


deviations = {}
for label, variant in settings.items():
    lands = {mass: sweep.sweep(with_mass(variant, mass), axis, axis) for mass in MASSES}
    reference = lands[variant.body.mass]
    deviations[label] = {
        name: max(
            largest_relative_change(land[name], reference[name], m / variant.body.mass) for m, land in lands.items()
        )
        for name in ("min_pcsa_cm2", "counter_torque_Nm")
    }
pd.DataFrame(deviations).T.rename(
    columns={
        "min_pcsa_cm2": "min PCSA: largest deviation from proportional [1]",
        "counter_torque_Nm": "CT: largest deviation from proportional [1]",
    }
).map("{:.1e}".format)

# %%
mass_table = study({mass: with_mass(model, mass) for mass in MASSES}, "mass [kg]")
plot_study(mass_table, "upper-body mass m [kg]", "The mass (K = 0)", through_origin=True)
mass_table.round(3)

# %% [markdown]
# ## The passive stiffness $K$
#
# The ligamentous sheath as a spring at every joint, in both readings of eq. 2: "physical" adds $-K$ to the
# stiffness $\partial M/\partial\alpha$; "paper" subtracts the number $K$ from $\partial\dot\omega/\partial\alpha$,
# a stiffness $K\theta_k$ that grows with the distance from the joint to the mass.

# %%
STIFFNESSES = np.array([0.0, 5.0, 10.0, 15.0, 20.0, 30.0])  # N m/rad
k_tables = {}
for convention in ("physical", "paper"):
    variant = config.set_parameter(model, "passive.convention", convention)
    k_tables[convention] = study(
        {k: config.set_parameter(variant, "passive.stiffness", float(k)) for k in STIFFNESSES}, "K [N m/rad]"
    )

fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained")
for convention, table in k_tables.items():
    style = "-" if convention == "physical" else "--"
    for column in ("min PCSA at A [cm²]", "min PCSA at B [cm²]"):
        axes[0].plot(table.index, table[column], "o" + style, label=f"{column.split(' [')[0]}, {convention}")
    ratio = table["ridge height [cm²]"] / table["ridge height [cm²]"].iloc[0]
    axes[1].plot(table.index, ratio, "o" + style, label=convention)
axes[1].axhline(0.5, color="grey", ls=":", label="the paper at K = 15: halved")
axes[0].set_ylabel("minimum PCSA [cm²]")
axes[1].set_ylabel("ridge height / ridge height at K = 0 [1]")
for ax in axes:
    ax.set_xlabel("passive stiffness K [N m/rad]")
    ax.legend(fontsize=8)
plt.show()
pd.concat(k_tables, names=["convention"]).round(3)

# %%
for convention, table in k_tables.items():
    plot_study(table, "passive stiffness K [N m/rad]", f"K, {convention} reading")

# %% [markdown]
# ## The attachment geometry
#
# The paper gives no attachment coordinates; spinectl's are anatomical estimates (`muscles.N.upper`, `.lower`).
# Two changes, each to all three pairs through `config.set_parameter`: the **lever arms**, scaling the horizontal
# distance of every attachment from the symmetry axis, and the **height** of the thoracic attachments.


# %%
def scale_lever_arms(variant, factor):
    """Every attachment's x times ``factor`` (both ends, every pair)."""
    for i, pair in enumerate(variant.muscles):
        variant = config.set_parameter(variant, f"muscles.{i}.upper", [pair.upper[0] * factor, pair.upper[1]])
        variant = config.set_parameter(variant, f"muscles.{i}.lower", [pair.lower[0] * factor, pair.lower[1]])
    return variant


def raise_upper(variant, shift):
    """Every thoracic (upper) attachment ``shift`` [m] higher."""
    for i, pair in enumerate(variant.muscles):
        variant = config.set_parameter(variant, f"muscles.{i}.upper", [pair.upper[0], pair.upper[1] + shift])
    return variant


FACTORS = np.array([0.8, 0.9, 1.0, 1.1, 1.2])  # 1
lever_table = study({f: scale_lever_arms(model, f) for f in FACTORS}, "lever-arm factor [1]")
plot_study(lever_table, "lever-arm factor (x of every attachment) [1]", "Lever arms")
lever_table.round(3)

# %%
SHIFTS = np.array([-0.04, -0.02, 0.0, 0.02, 0.04])  # m
height_table = study({s * CM: raise_upper(model, s) for s in SHIFTS}, "upper attachments raised by [cm]")
plot_study(height_table, "thoracic attachments raised by [cm]", "Attachment heights")
height_table.round(3)

# %% [markdown]
# ## The activation mode
#
# With `paired` activation both muscles of a pair have one PCSA, a co-contraction; the muscles' net force is then
# vertical and has no moment about the symmetry axis, so the counter torques are the CoRs' horizontal positions
# times one number, and the valley of $\|CT\|$ is set mostly by the CoR heights and the spine's shape (docs:
# *Optimisation*). With `independent` activation each muscle has its own PCSA: more freedom, so never more PCSA,
# and the counter torques are no longer tied to the positions of the CoRs.

# %%
modes = {mode: config.set_parameter(model, "optimisation.activation", mode) for mode in ("paired", "independent")}
mode_table = study(modes, "activation")
display(mode_table.round(3))

fig, axes = plt.subplots(1, 2, figsize=(11, 3.8), layout="constrained")
for mode, variant in modes.items():
    at_e = sweep.sweep(variant, [E_OPT], line).isel(E=0)
    axes[0].plot(line * CM, at_e["min_pcsa_cm2"], label=mode)
    axes[1].plot(line * CM, at_e["counter_torque_norm_Nm"], label=mode)
axes[1].axhline(landmarks.CT_LIMIT, color="grey", ls=":", label=f"±{landmarks.CT_LIMIT:g} N m limit")
axes[0].set_ylabel("minimum PCSA [cm²]")
axes[1].set_ylabel("‖CT‖ [N m]")
for ax in axes:
    ax.set_xlabel(f"lordosis Λ [cm] at E = {E_OPT * CM:g} cm")
    ax.legend(fontsize=8)
plt.show()

# %% [markdown]
# ## All factors at a glance
#
# Each factor's range of the optimum and of the minimum PCSA over the values tried above (largest minus smallest).

# %%
tables = {
    "mass": mass_table,
    "K, physical": k_tables["physical"],
    "K, paper": k_tables["paper"],
    "lever arms": lever_table,
    "attachment heights": height_table,
    "activation mode": mode_table,
}
spread = pd.DataFrame({name: table.max() - table.min() for name, table in tables.items()}).T
spread.columns = [f"range of {c}" for c in spread.columns]
spread.round(3)
