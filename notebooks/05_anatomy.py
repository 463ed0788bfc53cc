# %% [markdown]
# # The paper's question on a published anatomy: MyoTorso
#
# Everything before this notebook is about the paper's abstract model. Here the same questions are asked of a
# published musculoskeletal model, MyoTorso (MyoSuite's MuJoCo port of the lumbar spine of Christophy et al. 2012,
# 210 muscles; installed as `myo-sim`), with MuJoCo as the engine (docs: *Anatomical models*):
#
# 1. which muscles are **global**, **local** or attached **between** (MyoTorso's abdomen), and what can the global
#    muscles control (their moment arms' rank)?
# 2. is the lumbar chain stable **joint by joint** (the paper's criterion) and as a **chain** (every joint free)?
# 3. what is the **least muscle effort** that holds the posture, with a stability criterion and without?
# 4. does the model's own **lordosis** sit near the least effort?
# 5. can a **delayed reflex** hold the chain at the optimum?
#
# Sign convention: K = dτ/dq, so the chain is statically stable when −K is positive definite. Needs the extra
# `pip install 'spinectl[anatomy]'`.

# %% tags=["parameters"]
import os

GRID = int(os.environ.get("SPINECTL_NB_GRID", "41"))  # postures of the lordosis curve over -20 ... +20 deg
STIFFNESS = float(os.environ.get("SPINECTL_NB_JOINT_STIFFNESS", "50"))  # N m/rad added at each joint

# %%
# %matplotlib inline

import numpy as np
import pandas as pd
from IPython.display import display

from spinectl import anatomy
from spinectl.anatomy import drawing, figures
from spinectl.anatomy.analyses import analyse
from spinectl.anatomy.optimum import lordosis_curve, optimise

torso = anatomy.load("myotorso")
print(torso.engine.source, "-", len(torso.muscles), "muscles")

# %% [markdown]
# ## 1. The muscles' classes and what the global ones control
#
# A muscle is **local** if any attachment is on a vertebra, **global** if all are on the pelvis and the thorax, and
# **between** otherwise. The global muscles' moment arms over the five flexion-extension joints have rank 3: two
# directions of the chain are out of their reach except through their lengths' curvature (docs: *The coupled
# chain*, the rank theorem).

# %%
upright = analyse(torso, activation=0.0)
cert = upright.certificate
print({k: len(v) for k, v in upright.muscles.items()})
print(f"global rank {cert.rank} of 5; singular values {np.round(cert.singular_values, 4)} m/rad")
display(figures.sagittal_figure(drawing.sagittal_projection(torso), "MyoTorso: sagittal projection"))

# %% [markdown]
# ## 2. Joint by joint and the chain, at uniform activation
#
# MyoTorso's joints have no stiffness of their own. Every muscle at the same activation:

# %%
rows = []
for a in (0.0, 0.05, 0.2):
    r = analyse(torso, activation=a)
    rows.append(
        {
            "activation": a,
            "-K_jj, joint by joint [N m/rad]": np.round(r.free.joint_stiffness, 1),
            "eigenvalues of -K, the chain (free) [N m/rad]": np.round(r.free.eigenvalues, 1),
            "the chain (free): unstable modes": int(np.sum(r.free.eigenvalues <= 0)),
            "-K_c, constrained by the rhythm": np.round(r.constrained.eigenvalues, 1),
        }
    )
display(pd.DataFrame(rows))

# %% [markdown]
# Four of five chain modes are unstable, as in the paper's model; joint by joint only L5S1 is. Each mode drawn as
# the spine bent along it:

# %%
display(figures.modes_figure(drawing.mode_shapes(torso, analyse(torso, activation=0.05).free), "activation 0.05"))

# %% [markdown]
# ## 3. The least effort that holds the posture, and the price of stability
#
# Minimise the volume-weighted $\sum_i w_i a_i^2$ (OpenSim's static-optimisation criterion) subject to equilibrium
# on the rhythm's coordinates, $0 \le a \le 1$, and: no criterion (classic), each $-K_{jj} \ge \mu$ (joint by joint)
# or $-K \succeq \mu I$ (the chain), $\mu$ = 1 N m/rad, with `STIFFNESS` added at each joint. The programme is
# `spinectl.optimise.coupled.sdp.least_quadratic_cost_sdp` on the model's `LinearChain`.

# %%
optima = {s: optimise(torso, stability=s, joint_stiffness=STIFFNESS) for s in ("none", "joints", "chain")}
display(
    pd.DataFrame(
        {
            s: {
                "status": o.status,
                "cost": round(o.cost, 3),
                "sum of activations": round(float(np.nansum(o.activations)), 2),
                "least eigenvalue of -K [N m/rad]": round(float(o.eigenvalues[0]), 2),
            }
            for s, o in optima.items()
        }
    )
)
print(f"price of stability (the chain's cost over the classic one): {optima['chain'].cost / optima['none'].cost:.3g}")

# %% [markdown]
# ## 4. The three optima over the lordosis
#
# The FE joints moved together along the model's rhythm, their angles summing to the change shown (positive:
# MyoTorso's positive `flex_extension`, extension).

# %%
curve = lordosis_curve(torso, np.linspace(-20, 20, GRID), joint_stiffness=STIFFNESS)
display(figures.lordosis_figure(curve, f"MyoTorso, {STIFFNESS:g} N m/rad added at each joint"))
for key in ("none", "joints", "chain"):
    cost = np.array(curve[key]["cost"], float)
    best = int(np.nanargmin(cost))
    print(f"{key:>6}: least cost {cost[best]:.3g} at {curve['lordosis_deg'][best]:+.1f} deg")

# %% [markdown]
# ## 5. A delayed reflex at the classic optimum
#
# The chain's exact delay margin (`spinectl.reflex.mimo.linear_chain_delay_margin`)
# under a diagonal PD reflex at every joint,
# $k_p$ = 120 N m/rad, $k_d$ = 5 N m s/rad, its torque lagged by 50 ms, without added stiffness:

# %%
classic = optimise(torso, stability="none")
reflex = analyse(torso, activation=classic.activations, reflex=(120.0, 5.0, 0.05)).reflex
print(f"delay margin {1e3 * reflex['delay_margin_s']:.2f} ms ({reflex['delay_margin_status']})")

# %% [markdown]
# ## 6. The paper's chain replayed in MuJoCo
#
# `spinectl export` writes the paper's model at (E, Λ) = (3 cm, 4 cm) with the per-segment optimum as MJCF
# (docs: *Interchange with MuJoCo and OpenSim*). MuJoCo simulates it with the activations held (keyframe 0),
# displaced by 10⁻⁷ rad along the chain's fastest growing mode. spinectl predicts the growth $e^{\lambda t}$ with
# λ the mode's eigenvalue (`stability --coupled`); MuJoCo's simulated amplitude along the mode follows it.

# %%
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import mujoco

from spinectl.anatomy.interchange import export_model
from spinectl.model import chain
from spinectl.model.config import load_preset

paper = load_preset("wagner2012")
with tempfile.TemporaryDirectory() as folder:
    solution = export_model(paper, 0.03, 0.04, Path(folder) / "chain.xml")
    mj = mujoco.MjModel.from_xml_path(str(Path(folder) / "chain.xml"))
data = mujoco.MjData(mj)
mujoco.mj_resetDataKeyframe(mj, data, 0)
dofs = [mj.jnt_dofadr[mujoco.mj_name2id(mj, mujoco.mjtObj.mjOBJ_JOINT, j)] for j in paper.geometry.cor_names]
values, vectors = np.linalg.eig(chain.state_matrix(solution.mass, solution.stiffness, solution.damping))
top = int(np.argmax(values.real))
rate, mode = values[top].real, np.real(vectors[:, top]) / np.linalg.norm(np.real(vectors[:5, top]))
data.qpos[dofs] += 1e-7 * mode[:5]
data.qvel[dofs] += 1e-7 * mode[5:]
mj.opt.timestep = 1e-4
times, amplitude = [], []
for _ in range(1000):  # 0.1 s
    mujoco.mj_step(mj, data)
    times.append(data.time)
    amplitude.append(abs(data.qpos[dofs] @ mode[:5]))
times, amplitude = np.array(times), np.array(amplitude)
fitted = np.polyfit(times, np.log(amplitude), 1)[0]
fig, ax = plt.subplots(figsize=(6, 3.5))
ax.semilogy(1e3 * times, amplitude, label="MuJoCo (mj_step, activations held)")
ax.semilogy(1e3 * times, 1e-7 * np.exp(rate * times), "--", label=f"spinectl: $e^{{\\lambda t}}$, λ = {rate:.2f} 1/s")
ax.set_xlabel("t [ms]")
ax.set_ylabel("amplitude along the mode [rad]")
ax.set_title("The paper's chain at its per-segment optimum, in MuJoCo")
ax.legend()
plt.show()
print(f"predicted growth {rate:.3f} 1/s, simulated {fitted:.3f} 1/s ({abs(fitted / rate - 1):.1e} relative)")
