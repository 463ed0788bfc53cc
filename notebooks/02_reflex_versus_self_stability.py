# %% [markdown]
# # Delayed reflex versus self-stability
#
# The paper analyses self-stability only, "the stable performance of a musculoskeletal system without neuronal
# feedback", and argues for it in the Discussion: "reflexes are delayed by up to 100 ms following a perturbation,
# and due to the electromechanical processes the force generation of the muscles takes another 50-100 ms.
# Therefore, maintaining stability with time-delayed reflexive control is challenging [...]. Reflex loops will
# increase the stability margin and thus reduce the required co-contraction [...]. If the spinal column is already
# a self-stable system, the reflex delays are much less problematic for stable control."
#
# This notebook puts numbers on that paragraph. Each lumbar joint $k$, linearised at the upright posture, is
#
# $$
# \theta_k\,\ddot\alpha = S_k\,\alpha + D_k\,\dot\alpha + u, \qquad
# T_a\,\dot u + u = -\bigl(k_p\,\alpha + k_d\,\dot\alpha\bigr)(t - \tau),
# $$
#
# with the stiffness $S_k = \partial M/\partial\alpha$ (muscles, gravity, passive $K$), the Hill damping
# $D_k = \partial M/\partial\omega \le 0$ and a delayed PD reflex whose torque builds up with the force generation
# of the muscles, a lag of time constant $T_a$ (50 ms by default; see the section on force generation). Without
# the reflex the joint is self-stable when $S_k < 0$ (paper, eq. 1). The global muscles work at an
# **activation** $a$, a fraction of the minimum stabilising PCSA of Figure 3: $a = 0$ is no co-contraction (reflex
# only), $a = 1$ is self-stable. The reflex follows spinectl's default rule: $k_p = g\max(S_k, 0)$, the stiffness
# deficit times a gain factor $g > 1$ so that some stiffness is left to spare, and $k_d$ for a given damping ratio of
# the loop without delay (docs: *Delayed reflexes*; `reflex.gain_factor`, `reflex.damping_ratio`). The **delay margin**
# $\tau_m$ is the largest delay with the loop stable for every delay below it, computed exactly from the characteristic
# quasi-polynomial; it is infinite where no delay can destabilise the joint.
#
# Every verdict here names its criterion. Most of the notebook judges **joint by joint** (each CoR alone, the others
# fixed; the paper's criterion): "the spine" then means its five joints, each judged alone, and its delay margin is the
# least of theirs. The section *The chain at the same delays* judges the **chain** (all 5 CoRs free) under the same
# reflex, which can give the opposite answer (docs: *The lumbar chain*); the last sections answer the design
# question for both criteria.

# %% tags=["parameters"]
import os

GRID = int(os.environ.get("SPINECTL_NB_GRID", "81"))  # points per axis over 0-8 cm: 81 is the paper's 1 mm step
PRESET = os.environ.get("SPINECTL_NB_PRESET", "")  # "": spinectl's default preset, the calibrated "wagner2012"

# %%
# %matplotlib inline

import control as ct
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from IPython.display import display

import spinectl
from spinectl import optimise, reflex
from spinectl.landscape import sweep
from spinectl.model import config
from spinectl.paper import grid, landmarks
from spinectl.reflex import loops, margins, simulate
from spinectl.reflex.chain_verdict import margins_with_chain
from spinectl.reflex.design import CRISCO_LOAD, REACTION_TIMES, crisco_stiffness, delay_curve, design, passive_curve
from spinectl.reflex.design_plots import delay_figure, passive_figure

preset = PRESET or spinectl.DEFAULT_PRESET  # the preset of every command and of spinectl.load_preset()
model = spinectl.load_preset(preset)
POSITION = landmarks.OPTIMUM  # (E, Lambda) [m]: the paper's optimum, E = 3 cm, Lambda = 4 cm
DELAYS = (0.05, 0.10, 0.15)  # s: the paper's "up to 100 ms", and 50 ms either side
TAU = 0.10  # s: the delay of the critical gain ranges
names = list(model.geometry.cor_names)
print(
    f"preset {preset!r}; reflex gains {model.reflex.gains!r}: gain factor g = {model.reflex.gain_factor:g}, "
    f"damping ratio {model.reflex.damping_ratio:g}; force generation lag {model.reflex.activation_time_constant:g} s"
)

# %% [markdown]
# ## Co-contraction below the self-stable minimum
#
# At $E = 3$ cm, $\Lambda = 4$ cm, the activation falls from 1 (the minimum PCSA of Figure 3) to 0. Everything
# muscular is linear in the PCSA, so the stiffness of each joint is affine in $a$, and each joint turns
# self-stable at its own activation.

# %%
optimum = optimise.solve_point(model, *POSITION)
coeffs = spinectl.segment_coefficients(model, *POSITION)
activation = np.linspace(0.0, 1.0, 101)
pcsa = activation[:, None] * optimum.pcsa  # (activation, muscle) [m^2]
S, D = coeffs.stiffness(pcsa), coeffs.damping(pcsa)  # (activation, segment)
theta = np.broadcast_to(coeffs.inertia, S.shape)
LAG = model.reflex.activation_time_constant  # s: force generation after the delay (see the section below)
kp, kd = reflex.resolve_gains(S, D, theta, model.reflex)
exact = reflex.delay_margin(S, D, theta, kp, kd, LAG)
kp_low, kp_high = reflex.critical_gains(S, D, theta, kd, TAU, lag=LAG)

s_none, s_full = coeffs.stiffness(0.0 * optimum.pcsa), coeffs.stiffness(optimum.pcsa)
self_stable_from = np.clip(s_none / (s_none - s_full), 0.0, None)  # the activation where S_k = 0
onsets = ", ".join(f"{name} {a:.3f}" for name, a in zip(names, self_stable_from, strict=True))
print(f"self-stable from activation a = {onsets}")

# %%
fig, axes = plt.subplots(2, 2, figsize=(11, 7.5), sharex=True, layout="constrained")
colours = plt.rcParams["axes.prop_cycle"].by_key()["color"]
for k, name in enumerate(names):
    c = colours[k]
    axes[0, 0].plot(activation, np.maximum(S[:, k], 0.0), color=c, label=name)
    axes[0, 0].plot(activation, kp[:, k], "--", color=c)
    axes[0, 1].plot(activation, kd[:, k], color=c, label=name)
    margin = np.where(np.isinf(exact.margin[:, k]), np.nan, exact.margin[:, k])
    axes[1, 0].semilogy(activation, margin, color=c, label=name)
    axes[1, 0].axvline(self_stable_from[k], color=c, ls=":", lw=1)
    axes[1, 1].plot(activation, kp_high[:, k], color=c, label=name)
    axes[1, 1].plot(activation, kp_low[:, k], ":", color=c)
    axes[1, 1].plot(activation, kp[:, k], "--", color=c)
for tau in DELAYS:
    axes[1, 0].axhline(tau, color="grey", lw=0.8)
    axes[1, 0].annotate(f"{tau * 1e3:g} ms", (0.0, tau), xytext=(2, 2), textcoords="offset points", fontsize=8)
axes[0, 0].set_title("stiffness deficit max(S, 0) (solid) and reflex gain k_p (dashed)", fontsize=10)
axes[0, 0].set_ylabel("[N m/rad]")
axes[0, 1].set_title("derivative gain k_d of the rule", fontsize=10)
axes[0, 1].set_ylabel("k_d [N m s/rad]")
axes[1, 0].set_title("delay margin τ_m; dotted: self-stable from here on, τ_m = ∞", fontsize=10)
axes[1, 0].set_ylabel("τ_m [s]")
axes[1, 1].set_title(f"stabilising k_p at τ = {TAU * 1e3:g} ms: from (dotted) to (solid); rule (dashed)", fontsize=10)
axes[1, 1].set_ylabel("k_p [N m/rad]")
for ax in axes[1]:
    ax.set_xlabel("activation a [fraction of the minimum PCSA]")
axes[0, 0].legend(fontsize=8)
plt.show()

# %% [markdown]
# The same at five activations, joint by joint: the gains the reflex needs, the delay it tolerates, and the range
# of $k_p$ that keeps the joint stable at 100 ms (its lower end is always $S_k$: the reflex must at least make up
# the deficit).

# %%
rows = []
for a in (0.0, 0.25, 0.5, 0.75, 1.0):
    i = int(np.argmin(abs(activation - a)))
    for k, name in enumerate(names):
        rows.append(
            {
                "activation": activation[i],
                "segment": name,
                "S [N m/rad]": S[i, k],
                "deficit [N m/rad]": max(S[i, k], 0.0),
                "k_p [N m/rad]": kp[i, k],
                "k_d [N m s/rad]": kd[i, k],
                "τ_m [ms]": exact.margin[i, k] * 1e3,
                "status": exact.status_names[i, k],
                f"k_p min at {TAU * 1e3:g} ms [N m/rad]": kp_low[i, k],
                f"k_p max at {TAU * 1e3:g} ms [N m/rad]": kp_high[i, k],
            }
        )
pd.DataFrame(rows).set_index(["activation", "segment"]).round(2)

# %% [markdown]
# How much co-contraction does each delay need, when the reflex does the rest? Joint by joint (each CoR alone, the
# others fixed; the paper's criterion) the spine tolerates the smallest delay margin of its five joints.

# %%
spine_margin = exact.margin.min(axis=1)
for tau in DELAYS:
    enough = spine_margin > tau
    needed = f"a = {activation[np.argmax(enough)]:.2f}" if enough.any() else "none up to a = 1"
    print(f"delay {tau * 1e3:3.0f} ms: least activation, every joint stable joint by joint: {needed} (steps of 0.01)")
print(f"reflex only (a = 0), joint by joint: the spine tolerates {spine_margin[0] * 1e3:.0f} ms")
print(f"every joint self-stable alone, so any delay is tolerated joint by joint: a >= {self_stable_from.max():.3f}")

# %% [markdown]
# ## The chain at the same delays
#
# The same operating point and the same reflex rule on the whole chain, every CoR free at once
# (`spinectl margins` prints it beside the segments' verdict;
# `spinectl.reflex.chain_verdict.margins_with_chain`). The rule on the chain makes up the chain's stiffness deficit,
# the least local stiffness for static stability (docs: *The lumbar chain*), and the exact multivariable delay margin
# says which delays it holds. Side by side with the joint-by-joint verdict, at the three delays:

# %%
verdicts = []
for a in (0.0, 0.25, 0.5, 1.0):
    for tau in DELAYS:
        settings = config.set_parameters(model, {"reflex.activation": a, "reflex.delay": tau})
        both = margins_with_chain(settings, *POSITION)
        verdicts.append(
            {
                "activation": a,
                "delay [ms]": tau * 1e3,
                "joint by joint: τ_m [ms]": min(s.delay_margin for s in both.segments) * 1e3,
                "joint by joint: stable": all(s.stable_at_delay for s in both.segments),
                "chain: τ_m [ms]": both.chain.exact.margin * 1e3,
                "chain: stable": both.chain.stable_at_delay,
                "chain without reflex: growing modes": both.chain.modes.growth_times.size,
                "fastest growth [ms]": both.chain.modes.growth_times[0] * 1e3
                if both.chain.modes.growth_times.size
                else np.nan,
            }
        )
print("\n".join(both.chain.lines()))
pd.DataFrame(verdicts).set_index(["activation", "delay [ms]"]).round(3)

# %% [markdown]
# Joint by joint the spine is stable at each of these delays once the co-contraction is high enough; the chain, with
# every CoR free, is stable at none of them, at any of these activations: its delay margin is at most a fraction of a
# millisecond (0 where the rule's reflex leaves it unstable even without delay). The modes that limit it bend the
# joints against each other and grow, without reflex, within tens of milliseconds: faster than a delayed reflex can
# act. What holds them is intrinsic stiffness at each joint, the local muscles: the design question below.

# %% [markdown]
# ## Delay-margin maps over E × Λ
#
# Every sweep carries the delay margins of every joint at the model's reflex settings (`delay_margin_s`) and the
# spine's, the least over the joints (`spine_delay_margin_s`), joint by joint (each CoR alone, the others fixed; the
# paper's criterion; the chain's margin is not in these maps). The margin does not depend on the delay itself, so
# one sweep per activation answers "stable at delay $\tau$?" for every $\tau$: `spine_delay_margin_s > tau`.
# Over the grid the answer changes little with E and Λ (the table below the maps gives the share of the grid
# that tolerates each delay), so the figure below shows what does change it, the activation: for each activation
# (steps of 0.02) the spread of the spine's delay margin over the E × Λ grid (the band: least to largest; the
# line: the median), with the model's force-generation lag, against the three delays of the Discussion. Where
# the band crosses a delay, that delay becomes tolerated; everything muscular is linear in the PCSA, so one
# sweep's coefficients give the joints at every activation.

# %%
axis = grid.paper_axis(GRID)  # E and Lambda [m], the paper's 0 to 8 cm
ACTIVATIONS = (0.0, 0.25, 0.5)
maps = {a: sweep.sweep(config.set_parameter(model, "reflex.activation", a), axis, axis) for a in ACTIVATIONS}

ds = maps[0.0]
pcsa_cm2 = ds["pcsa_cm2"].values  # (E, Lambda, muscle): the chosen activation of Figure 3
muscular = np.einsum("elkm,elm->elk", ds["stiffness_per_cm2"].values, pcsa_cm2)
damping_full = np.einsum("elkm,elm->elk", ds["damping_per_cm2"].values, pcsa_cm2)
rigid = ds["gravity_stiffness_Nm_per_rad"].values - ds["passive_stiffness_Nm_per_rad"].values
inertia = ds["inertia_kgm2"].values


def spine_margin_ms(a, reflex_settings):
    """The spine's exact delay margin [ms], joint by joint, at activation ``a`` at every grid point (inf: any delay)."""
    joints = reflex.landscape(a * muscular + rigid, a * damping_full, inertia, reflex_settings)
    return joints.delay_margin.min(axis=-1) * 1e3


def margin_band(levels, reflex_settings):
    """Least, median and largest spine delay margin [ms] over the grid, per activation level."""
    margins_ms = np.array([spine_margin_ms(a, reflex_settings) for a in levels])
    margins_ms = np.minimum(margins_ms, 1e9)  # any delay (inf) as a very long one: the quantiles stay numbers
    return (np.nanquantile(margins_ms.reshape(len(levels), -1), q, axis=1) for q in (0.0, 0.5, 1.0))


FINE = np.round(np.arange(0.0, 1.0001, 0.02), 2)
TOP = 400  # ms: the plot's top; beyond it (and where any delay is tolerated) the band is cut
fig, ax = plt.subplots(figsize=(8, 4.2), layout="constrained")
least_ms, median_ms, largest_ms = margin_band(FINE, model.reflex)
ax.fill_between(FINE, least_ms, np.minimum(largest_ms, TOP), alpha=0.3, label="spread over the E × Λ grid")
ax.plot(FINE, np.where(median_ms < TOP, median_ms, np.nan), label="median over the grid")
for tau in DELAYS:
    ax.axhline(tau * 1e3, color="grey", lw=0.8, ls="--")
    ax.annotate(f"τ = {tau * 1e3:g} ms", (FINE[-1], tau * 1e3), ha="right", va="bottom", fontsize=8, color="grey")
ax.set(xlabel="activation a (fraction of the minimum stabilising PCSA)", ylabel="spine τ_m, joint by joint [ms]")
ax.set_ylim(0, TOP)
ax.set_title(f"force-generation lag T_a = {model.reflex.activation_time_constant * 1e3:g} ms", fontsize=10)
ax.legend(loc="upper left")
plt.show()

# %% [markdown]
# The same sweeps as continuous maps: the spine's delay margin, joint by joint, with the three delays as contours.

# %%
fig, axes = plt.subplots(1, len(ACTIVATIONS), figsize=(12, 3.9), sharey=True, layout="constrained")
for ax, (a, ds) in zip(axes, maps.items(), strict=True):
    margin_ms = ds["spine_delay_margin_s"].transpose("Lambda", "E").values * 1e3
    filled = ax.contourf(axis * 100, axis * 100, np.ma.masked_invalid(margin_ms), levels=12, cmap="viridis")
    fig.colorbar(filled, ax=ax, label="spine delay margin, joint by joint [ms]")
    if np.nanmin(margin_ms) < max(DELAYS) * 1e3 and np.nanmax(margin_ms) > min(DELAYS) * 1e3:
        lines = ax.contour(axis * 100, axis * 100, margin_ms, levels=[t * 1e3 for t in DELAYS], colors="white")
        ax.clabel(lines, fmt="%g ms", fontsize=8)
    ax.set_title(f"activation a = {a:g}", fontsize=10)
    ax.set_xlabel("eccentricity E [cm]")
    ax.set_aspect("equal")
axes[0].set_ylabel("lordosis Λ [cm]")
plt.show()

# %%
pd.DataFrame(
    {
        "spine τ_m, least [ms]": [float(ds.spine_delay_margin_s.min()) * 1e3 for ds in maps.values()],
        "spine τ_m, largest [ms]": [float(ds.spine_delay_margin_s.max()) * 1e3 for ds in maps.values()],
        **{
            f"stable joint by joint at {tau * 1e3:g} ms [% of grid]": [
                100 * float((ds.spine_delay_margin_s > tau).mean()) for ds in maps.values()
            ]
            for tau in DELAYS
        },
    },
    index=pd.Index(ACTIVATIONS, name="activation"),
).round(1)

# %% [markdown]
# ## Force generation: how the activation lag moves the regimes
#
# The Discussion adds that "the force generation of the muscles takes another 50-100 ms". spinectl models it as
# a first-order lag $1/(T_a s + 1)$ between the delayed reflex command and the torque
# (`reflex.activation_time_constant`, default 50 ms; 0 is the pure delay above). For every point of the grid:
# the least activation $a$ (in steps of 0.05) at which every joint is stable with a 100 ms delay and the lag
# $T_a$, joint by joint (each CoR alone, the others fixed; the paper's criterion). Where it is 0 the reflex alone
# suffices; where it reaches the activation at which every joint is self-stable, only self-stability works. The
# figure shows the spine's delay margin against the activation for each lag, as a band over the grid; the table
# counts the regimes.

# %%
LEVELS = np.round(np.arange(0.0, 1.0001, 0.05), 2)
LAGS = (0.0, 0.05, 0.10)  # s
TAU_LAG = 0.10  # s: the delay of the regime maps
self_stable_at = np.full(rigid.shape[:2], np.nan)
for a in LEVELS[::-1]:
    self_stable_at = np.where(np.all(a * muscular + rigid < 0, axis=-1), a, self_stable_at)
least = {}
fig, ax = plt.subplots(figsize=(8, 4.2), layout="constrained")
for lag in LAGS:
    settings = config.set_parameter(model, "reflex.activation_time_constant", lag).reflex
    settings = config.set_parameter(model.replace(reflex=settings), "reflex.delay", TAU_LAG).reflex
    found = np.full(rigid.shape[:2], np.nan)
    for a in LEVELS[::-1]:  # from the top down: the last level that holds is the least
        joints = reflex.landscape(a * muscular + rigid, a * damping_full, inertia, settings)
        found = np.where(np.all(joints.stable_at_delay, axis=-1), a, found)
    least[lag] = found
    low_ms, _, high_ms = margin_band(FINE, settings)
    ax.fill_between(FINE, low_ms, np.minimum(high_ms, TOP), alpha=0.35, label=f"T_a = {lag * 1e3:g} ms")
ax.axhline(TAU_LAG * 1e3, color="grey", lw=0.8, ls="--")
ax.annotate(f"τ = {TAU_LAG * 1e3:g} ms", (FINE[-1], TAU_LAG * 1e3), ha="right", va="bottom", fontsize=8, color="grey")
ax.set(xlabel="activation a (fraction of the minimum stabilising PCSA)", ylabel="spine τ_m, joint by joint [ms]")
ax.set_ylim(0, TOP)
ax.set_title("spread of the spine's delay margin (joint by joint) over the E × Λ grid, by lag", fontsize=10)
ax.legend(loc="upper left")
plt.show()

# %%
pd.DataFrame(
    {
        "reflex alone suffices [% of grid]": [100 * np.mean(f == 0) for f in least.values()],
        "needs co-contraction [% of grid]": [100 * np.mean((f > 0) & (f < self_stable_at)) for f in least.values()],
        "only self-stable [% of grid]": [100 * np.mean(f >= self_stable_at) for f in least.values()],
        "median least activation": [float(np.nanmedian(f)) for f in least.values()],
    },
    index=pd.Index([lag * 1e3 for lag in LAGS], name="activation lag T_a [ms]"),
).round(2)

# %% [markdown]
# Joint by joint: with the pure delay the reflex alone holds the spine at 100 ms wherever its margin is just above
# 100 ms; 50 ms of force generation lowers the reflex-only margin by about a third, so the reflex-only regime shrinks
# or vanishes, co-contraction is needed instead, and the least activation grows with the lag. The self-stable
# activation does not depend on the lag: the closer the needed activation comes to it, the more the paper's
# argument holds, that a self-stable spine makes the reflex delays "much less problematic".

# %% [markdown]
# ## Time-domain responses
#
# The nonlinear equation of motion of one joint (paper, Methods) with the reflex and its true delay, released from
# a small tilt, that joint alone with the others fixed (the paper's criterion). At half the minimum PCSA, the joint with
# the least delay margin. Left: below self-stability, with
# the reflex at 0.8 $\tau_m$ and at 1.2 $\tau_m$, and without it. Right: the same joint with the muscles a quarter
# above the self-stable minimum, with the same reflex at the longer delay, and without it.

# %%
HALF = 0.5  # activation [fraction of the minimum PCSA]
report = margins.margins_report(config.set_parameter(model, "reflex.activation", HALF), *POSITION)
limiting = min(report.segments, key=lambda s: s.delay_margin)
tau_m = limiting.delay_margin
low_plant = simulate.segment_plant(model, *POSITION, limiting.name, report.point.pcsa)
high_plant = simulate.segment_plant(model, *POSITION, limiting.name, 1.25 * optimum.pcsa)
gains = ([limiting.kp, limiting.kp, 0.0], [limiting.kd, limiting.kd, 0.0])
low = simulate.simulate(low_plant, *gains, [0.8 * tau_m, 1.2 * tau_m, 0.0], model.reflex)
high = simulate.simulate(high_plant, limiting.kp, limiting.kd, [1.2 * tau_m, 0.0], model.reflex)
high_no_reflex = simulate.simulate(high_plant, 0.0, 0.0, 0.0, model.reflex)

labels = [f"reflex, τ = 0.8 τ_m = {0.8 * tau_m * 1e3:.0f} ms", f"reflex, τ = 1.2 τ_m = {1.2 * tau_m * 1e3:.0f} ms"]
fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4), sharey=True, layout="constrained")
for i, label in enumerate([*labels, "no reflex"]):
    left.plot(low.time, low.alpha[i] * 1e3, label=f"{label} ({'stable' if low.stable[i] else 'unstable'} alone)")
right.plot(high.time, high.alpha[1] * 1e3, label=f"{labels[1]} ({'stable' if high.stable[1] else 'unstable'} alone)")
right.plot(
    high_no_reflex.time,
    high_no_reflex.alpha[0] * 1e3,
    label=f"no reflex ({'stable' if high_no_reflex.stable[0] else 'unstable'} alone)",
)
limit = 3 * model.reflex.sim_perturbation * 1e3
left.set_title(f"{limiting.name}, a = {report.point.activation:g}: τ_m = {tau_m * 1e3:.0f} ms", fontsize=10)
right.set_title(f"{limiting.name}, 1.25 × minimum PCSA (self-stable)", fontsize=10)
left.set_ylabel("tilt α [mrad]")
for ax in (left, right):
    ax.set_ylim(-limit, limit)
    ax.set_xlabel("time [s]")
    ax.legend(fontsize=8, loc="lower right")
plt.show()

# %% [markdown]
# ## The loop in the frequency domain
#
# The same joint as a python-control system: the loop $L(s) = (k_p + k_d s)\,e^{-s\tau}\,G(s)/(T_a s + 1)$ with the
# delay as a Padé approximant, at the model's delay and activation lag. Below self-stability $G$ has a pole in the
# right half plane, so by the Nyquist criterion the closed loop is stable when the curve circles $-1$ once
# counter-clockwise; a longer delay turns the curve further, until at $\tau_m$ it passes through $-1$.

# %%
delay = model.reflex.delay
loop = loops.loop_transfer(
    limiting.stiffness,
    limiting.damping,
    limiting.inertia,
    limiting.kp,
    limiting.kd,
    delay,
    model.reflex.pade_order,
    model.reflex.activation_time_constant,
)
bode = ct.bode_plot(loop, omega_limits=(0.1, 100.0), title=f"{limiting.name}: L(jω), τ = {delay * 1e3:g} ms")
bode.axes[0, 0].set_ylabel("|L(jω)| [1]")
plt.show()
nyquist = ct.nyquist_plot(loop, title=f"{limiting.name}: Nyquist plot of L, τ = {delay * 1e3:g} ms")
nyquist.axes[0, 0].set_xlabel("Re L(jω) [1]")
nyquist.axes[0, 0].set_ylabel("Im L(jω) [1]")
plt.show()

# %% [markdown]
# Every joint's margins at this configuration, joint by joint (`spinectl margins` prints the same, and the chain's
# verdict beside them): the exact delay margin and its
# Padé estimate, the phase margin at the delay, the range of a common factor on both gains that keeps the loop
# stable (python-control's gain margins, read for an open-loop unstable plant), and the stabilising $k_p$.

# %%
pd.DataFrame(
    {
        "S [N m/rad]": s.stiffness,
        "D [N m s/rad]": s.damping,
        "θ [kg m²]": s.inertia,
        "k_p [N m/rad]": s.kp,
        "k_d [N m s/rad]": s.kd,
        "τ_m [ms]": s.delay_margin * 1e3,
        "τ_m, Padé [ms]": s.delay_margin_pade * 1e3,
        f"phase margin at {delay * 1e3:g} ms [°]": s.phase_margin_deg,
        "gain factor, lower [1]": s.gain_margin_lower,
        "gain factor, upper [1]": s.gain_margin,
        f"k_p range at {delay * 1e3:g} ms [N m/rad]": f"{s.kp_min:.1f} to {s.kp_max:.1f}",
        "stable at τ, joint by joint": s.stable_at_delay,
    }
    for s in report.segments
).set_index(pd.Index(names, name="segment")).round(3)

# %% [markdown]
# ## The design question: how much intrinsic stiffness does a delay need?
#
# `spinectl design` (`spinectl.reflex.design.design`) answers it at one point for both criteria: joint by joint, the
# least co-contraction (a fraction of the minimum stabilising PCSA) for which every joint's exact delay margin is at
# least the delay; for the chain, at the model's global activation, the least local stiffness per joint for which the
# chain under the delayed reflex is stable at the delay, with its certificate (the exact multivariable delay margin
# at the design and the rightmost characteristic root at the delay). At the paper's optimum, for 40 ms and 120 ms:

# %%
answers = {tau: design(config.set_parameter(model, "reflex.delay", tau), *POSITION) for tau in (0.04, 0.12)}
for answer in answers.values():
    print(answer.table(), end="\n\n")
pd.DataFrame(
    {
        "status": [d.status for d in answers.values()],
        "joint by joint: least activation": [d.activation for d in answers.values()],
        "joint by joint: PCSA [cm²]": [d.pcsa * 1e4 for d in answers.values()],
        "chain: local stiffness, total [N m/rad]": [float(np.sum(d.chain.local_stiffness)) for d in answers.values()],
        "chain: × least for static stability": [d.chain.fraction for d in answers.values()],
        "chain: τ_m at the design [ms]": [d.chain.delay_margin * 1e3 for d in answers.values()],
        "chain: rightmost root [1/s]": [d.chain.max_root_real for d in answers.values()],
    },
    index=pd.Index([tau * 1e3 for tau in answers], name="delay [ms]"),
).round(4)

# %% [markdown]
# Joint by joint, the longer delay needs more co-contraction: the reflex does less and the muscles more. For the
# chain the answer is of another kind: a fraction of the least local stiffness for static stability (the column
# "× least for static stability"), the stiffness that the global muscles cannot give. The local muscles damp
# what they stiffen (docs: *The lumbar chain*, "Local muscles as joint stiffness and damping"), so part of that
# stiffness can be left to the delayed reflex; how much shrinks as the delay grows, and the fraction rises
# towards the static least. Without the local damping (`local.damping = 0`) the chain needed practically all of
# it at either delay.

# %% [markdown]
# ## The design curve: against the delay and the lag
#
# The same two answers at every delay from 0 to 200 ms, for three force-generation lags $T_a$ (none, the default
# 50 ms, the Discussion's 100 ms): `spinectl.reflex.design.delay_curve` computes, `design_plots.delay_figure`
# draws (the command line: `spinectl design --delays 0:0.2:41 --lags 0,0.05,0.1 --plot DIR`). Top, joint by joint
# (each CoR alone, the others fixed; the paper's criterion): the least co-contraction for which every joint's exact
# delay margin is at least the delay. Bottom, the chain (all 5 CoRs free), at the model's global activation: the
# least local stiffness, summed over the joints, for which the chain under the delayed reflex is stable at the delay.
# The dashed lines are the trunk muscles' reaction times after a sudden load release measured by Radebold et al.
# (2000), the library's marks (`REACTION_TIMES`).

# %%
CURVE_DELAYS = np.linspace(0.0, 0.2, 41 if GRID >= 81 else 21)  # s: 5 ms steps (10 ms on a coarse test grid)
CURVE_LAGS = (0.0, 0.05, 0.10)  # s: T_a
curve = delay_curve(model, *POSITION, CURVE_DELAYS, lags=CURVE_LAGS)
display(delay_figure(curve))

# %% [markdown]
# The figure read with its numbers; at the reaction times, the joint-by-joint answer computed there (not read
# between the curve's delays):

# %%
ms = curve.delays * 1e3
REACTION = [t for t, _ in REACTION_TIMES]  # s
at_reaction = delay_curve(model, *POSITION, REACTION, lags=CURVE_LAGS)
rows = {}
for i, lag in enumerate(curve.lags):
    joint, fraction, total = curve.activation[i], curve.local_fraction[i], curve.local_stiffness[i].sum(axis=1)
    free = ms[joint == 0]  # the delays that need no co-contraction, joint by joint
    delayed = curve.delays > 0
    rows[lag * 1e3] = {
        "joint: reflex alone up to [ms]": free.max() if free.size else np.nan,
        **{f"joint: activation at {t * 1e3:.0f} ms": at_reaction.activation[i, j] for j, t in enumerate(REACTION)},
        **{f"joint: activation at {d:.0f} ms": joint[np.isclose(ms, d)][0] for d in (120, 200)},
        "chain: sum of local k, least [N m/rad]": total[delayed].min(),
        "chain: sum of local k, largest [N m/rad]": total[delayed].max(),
        "chain: × k*, least": fraction[delayed].min(),
        "chain: × k*, largest": fraction[delayed].max(),
        "chain: τ_m at the design / delay, least": np.min(curve.chain_margin[i][delayed] / ms[delayed] * 1e3),
    }
reading = pd.DataFrame(rows).rename_axis(columns="activation lag T_a [ms]")
print("joint: joint by joint (each CoR alone, the others fixed; the paper's criterion); chain: all 5 CoRs free")
for t, label in REACTION_TIMES:
    print(f"{t * 1e3:.0f} ms: {label}")
LAG_READ = CURVE_LAGS.index(0.05)  # the default lag's curve, read aloud below
lag_50 = reading.iloc[:, LAG_READ]
print(
    f"joint by joint, T_a = 50 ms: the reflex alone holds every joint up to "
    f"{lag_50['joint: reflex alone up to [ms]']:.0f} ms on the curve; at 120 ms it needs "
    f"{lag_50['joint: activation at 120 ms']:.3f} of the minimum PCSA "
    f"({curve.pcsa[LAG_READ][np.isclose(ms, 120)][0] * 1e4:.1f} cm²)"
)
print(
    f"the chain, all lags: {reading.loc['chain: sum of local k, least [N m/rad]'].min():.1f} to "
    f"{reading.loc['chain: sum of local k, largest [N m/rad]'].max():.1f} N m/rad of local stiffness in all at "
    f"every delay from {ms[1]:g} ms to {ms[-1]:g} ms, at global activation {curve.chain_activation:g}"
)
display(reading.round(4))

# %% [markdown]
# Joint by joint, the delay and the lag both matter: the reflex alone suffices up to a delay that the lag
# shortens, and beyond it the co-contraction grows with the delay, and more with a longer lag; the table gives it at
# Radebold et al.'s reaction times for each lag. The chain's answer hardly moves with either: from the first delay
# above zero it needs close to the least local stiffness for static stability $k^*$ (the `× k*` row), the stiffness
# that the global muscles cannot give; its delay margin at the design is at least the delay everywhere (the
# certificate, the last row: at least 1). The chain's need is set by the intervertebral modes, which grow faster
# than any reflex acts, not by the delay.
#
# ## The chain's verdict against the passive stiffness
#
# That need is a function of the joints' own passive stiffness $K$, which the paper leaves open
# (`spinectl design --passive 0:80:41`; docs: *The lumbar chain*). `passive_curve` gives, for the chain (all 5 CoRs
# free, static stability), the least global PCSA that alone stabilises it at each $K$ and the least local stiffness
# at the paper's minimum PCSA held fixed; `passive_figure` draws both, with the stiffness at which the passive chain
# buckles under the 88 N that Crisco et al. (1992) measured for the ligamentous lumbar spine, computed from the
# model's geometry by `crisco_stiffness`, and the paper's $K = 15$ N m/rad.

# %%
passive = passive_curve(model, *POSITION, np.linspace(0.0, 80.0, 41))  # K per joint [N m/rad], physical convention
crisco = crisco_stiffness(model, *POSITION)  # the passive_curve's mark: the same function
display(passive_figure(passive))
no_local = passive.passive_stiffness[passive.local_stiffness.sum(axis=1) == 0]
print(
    f"Crisco et al.: {CRISCO_LOAD:g} N buckles the passive chain at K = {crisco:.2f} N m/rad per joint; "
    f"there global muscles alone stabilise the chain with {passive.crisco_global_pcsa * 1e4:.2f} cm²"
)
print(f"the chain, global muscles alone: stable from K = {passive.threshold:.2f} N m/rad per joint")
alone = "stabilise" if passive.threshold <= crisco else "do not stabilise"
print(f"so at Crisco et al.'s K the global muscles alone {alone} the chain (statically, all 5 CoRs free)")
print(
    f"the chain at the paper's minimum ({passive.paper_pcsa * 1e4:.1f} cm² held fixed): "
    f"{passive.local_stiffness[0].sum():.1f} N m/rad of local stiffness in all at K = 0, none from "
    + (f"K = {no_local.min():g} N m/rad on this scan" if no_local.size else "no K on this scan")
)

# %% [markdown]
# "Global muscles alone cannot stabilise the chain" holds below the printed threshold only, and the local muscles'
# share at the paper's minimum PCSA falls with $K$ to nothing; whether Crisco et al.'s measurement puts these joints
# above or below the threshold is the printed verdict. The chain's verdict is a function of the passive stiffness one
# assumes, not a property of the spine's geometry alone.
