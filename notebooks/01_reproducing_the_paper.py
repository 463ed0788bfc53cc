# %% [markdown]
# # Reproducing the paper
#
# Wagner, Liebetrau, Schinowski, Wulf and de Lussanet (2012), *Spinal lordosis optimizes the requirements for a
# stable erect posture* (Theor Biol Med Model 9:13), hypothesise that "the motor system selects a configuration in
# which the required local stabilizing torques on each of the lumbar joints is minimal". They test it with a planar
# model of the five lumbar joints, three antagonistic pairs of global muscles and a point mass for the upper body,
# over two geometric parameters: the **eccentricity** $E$, "the dorsal location of the spine in the body", and the
# **lordosis** $\Lambda$, the horizontal offset of the middle of the spine, both from 0 to 8 cm.
#
# Two landscapes carry the argument:
#
# - **Figure 3**, the minimum PCSA of the global muscles that makes every joint *self-stable*, "the stable
#   performance of a musculoskeletal system without neuronal feedback", joint by joint (each CoR alone, the others
#   fixed; the paper's criterion; notebook 04 frees all five CoRs at once, the chain);
# - **Figure 4**, the norm $\|CT\|$ of the local counter torques "to guarantee for an equilibrium" at that activation;
# - and **Figure S1**, Figure 3 with a passive stiffness $K = 15$ N m/rad of the ligamentous sheath.
#
# This notebook computes all three with spinectl, marks the positions A-D, sets the paper's landmarks beside
# spinectl's, and measures what each of the three errata of the paper changes (the model page of the docs says
# why each printed formula cannot be right).

# %% tags=["parameters"]
import os

GRID = int(os.environ.get("SPINECTL_NB_GRID", "81"))  # points per axis over 0-8 cm: 81 is the paper's 1 mm step
PRESET = os.environ.get("SPINECTL_NB_PRESET", "")  # "": spinectl's default preset, the calibrated "wagner2012"

# %%
# %matplotlib inline
import time

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display

import spinectl
from spinectl import optimise
from spinectl.landscape import sweep
from spinectl.model import config, muscle
from spinectl.paper import figures, grid, landmarks, report
from spinectl.reflex import simulate
from spinectl.units import m2_to_cm2

preset = PRESET or spinectl.DEFAULT_PRESET  # the preset of every command and of spinectl.load_preset()
model = config.set_parameter(spinectl.load_preset(preset), "passive.stiffness", 0.0)  # K = 0, as in Figures 3, 4
axis = grid.paper_axis(GRID)  # E and Lambda [m], the paper's 0 to 8 cm
CM = 100.0  # cm per m, for axes and tables
print(f"preset {preset!r}; E and Lambda from 0 to 8 cm, {GRID} points each ({(axis[1] - axis[0]) * 1e3:.3g} mm apart)")

# %% [markdown]
# ## The landscapes
#
# At every grid point spinectl solves the paper's two questions as convex problems (docs: *Optimisation*): the
# least total PCSA with every joint self-stable (a linear programme; the paper "varied iteratively" the three
# pairs), then, among the activations within 0.1 % of that minimum, the one with the least $\|CT\|$. Figures 3
# and 4 have $K = 0$; Figure S1 has $K = 15$ N m/rad. The paper's eq. 2 adds $K$ in a form whose units do not
# match, so spinectl also solves $K = 15$ with the other reading of $K$ (the erratum section below).

# %%
K_PAPER = grid.PAPER_STIFFNESS  # N m/rad, the paper's ref. 26
other_convention = grid.other_convention(model)

start = time.perf_counter()
both, k15_other = grid.paper_landscapes(model, GRID)  # K = 0 and 15, and K = 15 with the other convention
k0, k15 = both.sel(K=0.0), both.sel(K=K_PAPER)
print(f"3 landscapes of {GRID}x{GRID} points in {time.perf_counter() - start:.1f} s")
print("solver statuses (K = 0):", dict(zip(*np.unique(k0["status"].values, return_counts=True), strict=True)))

# %% [markdown]
# ### Figure 3: minimum PCSA for self-stability
#
# The paper: "A situation of the coronal plane with no eccentricity and no spinal curvature requires a minimum PCSA
# of about 35 cm² (position A). Increasing the spinal curvature slightly reduces the required PCSA (position D).
# [...] increasing the eccentricity, without spinal curvature ($\Lambda = 0$), the necessary PCSA for
# self-stability is reduced (position B). Around the line $\Lambda = 1.7E$ [...] the PCSA saturates at
# approximately 40 cm²." A, B and D are corners of the figure; C is marked where Figure 3's caption and the
# Discussion place it, E ≈ 3 cm, Λ ≈ 4 cm, and the fourth corner is labelled by its coordinates, "8, 8 cm".

# %%
display(figures.min_pcsa_figure(k0))

# %% [markdown]
# ### Figure 4: local counter torques
#
# The paper: "the minimum counter torques were found along the angle bisector. As a comparison, the required local
# torques in position D are twice those of position C whereas in position B even they are even three times as
# high." The dashed contour is the "realistic estimate of the maximal counter torques of the local muscles",
# ±30 N m; the star is where "the simulations of the present model require an eccentricity of $E \approx 3$ cm
# and a lumbar lordosis of $\Lambda \approx 4$ cm".

# %%
display(figures.counter_torque_figure(k0, model.fibre.specific_tension))

# %% [markdown]
# ### Figure S1: with the passive stiffness of the ligamentous sheath
#
# Additional file 1: "A stiffness value of $K = 15$ N m/rad halves the minimum PCSA, i.e. the PCSA saturates at
# approximately 23 cm²", and the Results: "the addition of elastic components does not affect the relationship for
# the required PCSA qualitatively".

# %%
display(figures.min_pcsa_figure(k15))

# %% [markdown]
# ## The positions A-D
#
# The corners of the grid (the row C is the corner, 8, 8 cm) and the optimum E ≈ 3, Λ ≈ 4 cm, which Figure 3's
# caption and the Discussion call position C and the figures mark as C (spinectl's primary reading; the landmark
# table below gives the C-ratios for this reading, the corner and the ridge line). The last column converts $\|CT\|$
# as the paper does: "Assuming [...] a lever arm of 7.0 cm", a counter torque is the PCSA of a local muscle.

# %%
positions = {**grid.POSITIONS, "optimum (E 3, Λ 4 cm)": landmarks.OPTIMUM}
rows = []
for name, position in positions.items():
    ct_norm = landmarks.at(k0, "counter_torque_norm_Nm", position)
    local = landmarks.local_pcsa_equivalent(ct_norm, model.fibre.specific_tension)
    rows.append(
        {
            "position": name,
            "E [cm]": position[0] * CM,
            "Λ [cm]": position[1] * CM,
            "min PCSA, K = 0 [cm²]": landmarks.at(k0, "min_pcsa_cm2", position),
            f"min PCSA, K = {K_PAPER:g} [cm²]": landmarks.at(k15, "min_pcsa_cm2", position),
            "‖CT‖ [N m]": ct_norm,
            "‖CT‖ as local PCSA at 7 cm [cm²]": float(m2_to_cm2(local)),
        }
    )
pd.DataFrame(rows).set_index("position").round(2)

# %% [markdown]
# ## The landmarks
#
# Every number the paper reports about these figures, beside spinectl's (`spinectl.paper.landmarks`, the same table as
# in the `report.md` of `spinectl reproduce`). "About" is read as ±20 %, values being read off contour plots.

# %%
measured = landmarks.measure(landmarks.Landmarks(k0, k15, k15_other))
table = pd.DataFrame(
    {
        "paper": f"{report.RELATION[m.landmark.relation]} {m.landmark.paper:g}",
        "spinectl": m.value,
        "unit": m.landmark.unit,
        "agrees": m.agrees,
        "how spinectl measures it": m.landmark.how,
        "where the paper says it": m.landmark.where,
    }
    for m in measured
)
table.index = [m.landmark.name for m in measured]
print(f"preset {preset!r}: {table['agrees'].sum()} of {len(table)} landmarks agree")
with pd.option_context("display.max_colwidth", None):
    display(table.round(3))

# %% [markdown]
# ## The errata
#
# Three formulas of the paper cannot be right as printed. spinectl implements the corrections and keeps each
# printed form selectable (section `[errata]` and `passive.convention` of the parameters), so that what each one
# changes can be measured rather than argued.
#
# ### 1. The sign of gravity
#
# The paper prints $M_{ext} = -mg\sin(\alpha)\,r$. An upright mass above a joint is an inverted pendulum, so
# gravity must *destabilise*: $\partial M_{ext}/\partial\alpha = +mgr$. With the printed sign gravity alone
# stiffens every joint, and the symmetric spine would need no muscle at all. The optimiser asks for a small margin
# beyond mere stability (`optimisation.stability_margin`, `damping_margin`); without it, the answer is exactly zero.

# %%
printed_gravity = config.set_parameter(model, "errata.gravity_sign", "printed")
no_margins = config.set_parameter(printed_gravity, "optimisation.stability_margin", 0.0)
no_margins = config.set_parameter(no_margins, "optimisation.damping_margin", 0.0)
gravity_at_a = spinectl.segment_coefficients(printed_gravity, 0.0, 0.0).gravity_stiffness
print("dM_ext/dalpha at A with the printed sign [N m/rad]:", np.round(gravity_at_a, 1), "(negative: stabilising)")
gravity_lands = {
    "printed sign": sweep.sweep(printed_gravity, axis, axis),
    "printed sign, no margins": sweep.sweep(no_margins, axis, axis),
    "corrected sign": k0,
}
print("minimum PCSA over the grid (the paper: about 35 cm² at A):")
for label, land in gravity_lands.items():
    print(f"{label:>26}: {float(land.min_pcsa_cm2.min()):.3g} to {float(land.min_pcsa_cm2.max()):.3g} cm²")

# %% [markdown]
# ### 2. The Hill constant $C$
#
# The paper prints $C = (A - f_{iso})\,b$. The two branches of the force-velocity relation describe one muscle and
# must meet at $v = 0$ at the isometric force; they do only for $C = (A - f_{iso})\,B$, which also makes their
# slopes meet. Below, both curves for a fibre of the straight pair ($v$ is the shortening velocity; negative is
# lengthening).

# %%
pair = model.muscles[0]
rest_length = float(np.hypot(pair.upper[0] - pair.lower[0], pair.upper[1] - pair.lower[1]))  # l0 [m]
l_opt = model.fibre.optimal_length_ratio * rest_length
corrected = muscle.hill_constants(l_opt, model.fibre, model.errata)
printed_errata = config.set_parameter(model, "errata.eccentric_constant", "printed")
printed = muscle.hill_constants(l_opt, printed_errata.fibre, printed_errata.errata)
v_max = float(muscle.max_velocity(l_opt, model.fibre))
v = np.linspace(-0.5 * v_max, v_max, 601)

fig, ax = plt.subplots(figsize=(6.4, 3.8))
ax.plot(v, muscle.force_velocity(v, corrected), label="C = (A − f_iso) B (corrected)")
ax.plot(v, muscle.force_velocity(v, printed), "--", label="C = (A − f_iso) b (printed)")
ax.axvline(0.0, color="grey", lw=0.5)
ax.set_xlabel("shortening velocity v [m/s]")
ax.set_ylabel("f_H / f_iso [1]")
ax.set_title(f"Hill force-velocity of one fibre, l_opt = {l_opt * CM:.1f} cm")
ax.legend()
plt.show()

just_below = -1e-9 * v_max  # m/s: the lengthening side of v = 0
for label, hill in [("corrected", corrected), ("printed", printed)]:
    force = float(muscle.force_velocity(just_below, hill))
    slope_ratio = float(muscle.force_velocity_slope(just_below, hill) / muscle.force_velocity_slope(0.0, hill))
    print(f"{label:>9}: f_H(0-) = {force:.3g} f_iso; slope at 0- / slope at 0+ = {slope_ratio:.3g}")

# %% [markdown]
# The linearised analysis takes the force and the slope (the damping) at $v = 0$ from the shortening side, which
# both forms share: the minimum PCSA and the damping $\partial M/\partial\omega$ of the landscape do not change.

# %%
c_printed = sweep.sweep(printed_errata, axis, axis)
print("largest change of the minimum PCSA [cm²]:", float(abs(c_printed.min_pcsa_cm2 - k0.min_pcsa_cm2).max()))
print(
    "largest change of the damping per cm² [N m s/rad/cm²]:",
    float(abs(c_printed.damping_per_cm2 - k0.damping_per_cm2).max()),
)

# %% [markdown]
# What the printed $C$ changes is the muscle away from rest: a lengthening fibre loses force at once and then
# damps with a steeper slope. The nonlinear equation of motion shows it. One segment at the paper's optimum, that
# joint alone with the others fixed (joint by joint, the paper's criterion), with the muscles a quarter above the
# minimum PCSA (self-stable joint by joint, no reflex), released from a 1 mrad tilt (a run stops once the tilt
# exceeds `reflex.sim_divergence`):

# %%
SEGMENT = "L3L4"
optimum = optimise.solve_point(model, *landmarks.OPTIMUM)
pcsa = 1.25 * optimum.pcsa  # m² per muscle
verdicts = {}
fig, ax = plt.subplots(figsize=(6.4, 3.6))
for label, variant in [("corrected", model), ("printed", printed_errata)]:
    plant = simulate.segment_plant(variant, *landmarks.OPTIMUM, SEGMENT, pcsa)
    run = simulate.simulate(plant, 0.0, 0.0, 0.0, variant.reflex)  # kp = kd = 0: no reflex
    verdicts[label] = ("stable" if run.stable[0] else "unstable") + " joint by joint"  # this CoR alone
    ax.semilogy(run.time, np.abs(run.alpha[0]) * 1e3, label=f"{label} C ({verdicts[label]})")
ax.set_xlabel("time [s]")
ax.set_ylabel("tilt |α| [mrad]")
ax.set_title(f"{SEGMENT} alone (the others fixed), E = 3 cm, Λ = 4 cm, 1.25 × minimum PCSA, no reflex")
ax.legend()
plt.show()

# %% [markdown]
# ### 3. The passive stiffness in eq. 2
#
# Eq. 2 subtracts $K$ [N m/rad] from $\partial\dot\omega/\partial\alpha$ [1/s²]. Physically a spring adds $-K$ to
# the stiffness $\partial M/\partial\alpha$ ("physical"); read literally, the number $K$ is subtracted from the
# angular acceleration per radian, a stiffness $K\theta_k$ at joint $k$ ("paper"). The paper's landmark decides
# between them: "$K = 15$ N m/rad halves the minimum PCSA".

# %%
by_convention = {model.passive.convention: k15, other_convention: k15_other}
for convention, land in by_convention.items():
    ratio = land.min_pcsa_cm2 / k0.min_pcsa_cm2
    print(
        f"{convention:>8}: largest minimum PCSA {float(land.min_pcsa_cm2.max()):.3g} cm² "
        f"(K = 0: {float(k0.min_pcsa_cm2.max()):.3g} cm²), ratio of the maxima "
        f"{float(land.min_pcsa_cm2.max() / k0.min_pcsa_cm2.max()):.3f}; "
        f"pointwise ratio {float(ratio.min()):.3f} to {float(ratio.max()):.3f}"
    )

fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.8), layout="constrained")
left.plot(axis * CM, k0.min_pcsa_cm2.sel(Lambda=0.0), "k", label="K = 0")
for convention, land in by_convention.items():
    profile = land.min_pcsa_cm2.sel(Lambda=0.0)
    left.plot(axis * CM, profile, label=f"K = {K_PAPER:g} N m/rad, {convention}")
    right.plot(axis * CM, profile / k0.min_pcsa_cm2.sel(Lambda=0.0), label=convention)
right.axhline(0.5, color="grey", ls=":", label="the paper: halved")
left.set_ylabel("minimum PCSA [cm²]")
right.set_ylabel("min PCSA (K = 15) / min PCSA (K = 0) [1]")
for ax in (left, right):
    ax.set_xlabel("eccentricity E [cm] (Λ = 0)")
    ax.legend(fontsize=8)
plt.show()

# %% [markdown]
# Figure S1 with the other reading of $K$:

# %%
display(figures.min_pcsa_figure(k15_other))

# %% [markdown]
# ### What each erratum changes, in one table
#
# Each printed form against its correction, by what it changes: the minimum PCSA (the ridge of Figure 3), the
# nonlinear segment of the Hill-constant section, and the halving of Figure S1 (the "paper" reading of $K$ is the
# printed one).

# %%
largest = {name: float(land.min_pcsa_cm2.max()) for name, land in gravity_lands.items()}
ridge_ratio = {c: float(by_convention[c].min_pcsa_cm2.max() / k0.min_pcsa_cm2.max()) for c in by_convention}
gravity, hill, spring = "M_ext = −m g r sin α", "C = (A − f_iso) b", "K subtracted from ∂ω'/∂α"
ridge, run_alone = "largest min PCSA [cm²]", f"{SEGMENT} alone, 1.25 × min PCSA, no reflex"
errata_rows = [
    ("gravity sign", gravity, ridge, largest["printed sign"], largest["corrected sign"]),
    ("Hill constant C", hill, ridge, float(c_printed.min_pcsa_cm2.max()), largest["corrected sign"]),
    ("Hill constant C", hill, run_alone, verdicts["printed"], verdicts["corrected"]),
    ("K in eq. 2", spring, f"ridge at K = {K_PAPER:g} / at K = 0 [1]", ridge_ratio["paper"], ridge_ratio["physical"]),
]
pd.DataFrame(errata_rows, columns=["erratum", "printed form", "quantity", "printed", "corrected"]).set_index(
    ["erratum", "quantity"]
)
