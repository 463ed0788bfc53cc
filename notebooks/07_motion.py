# %% [markdown]
# # Stability along a motion: a lift on MyoTorso
#
# The Cholewicki-McGill index (Cholewicki & McGill 1996, Clin Biomech 11:1-15) is the least eigenvalue of −K of the
# lumbar chain, evaluated frame by frame through a recorded task. This notebook writes a lift (a flexion of the
# lumbar spine and its return over 2 s) as an OpenSim `.mot` through OpenSim's own API, and follows MyoTorso through
# it with 100 N held at the thorax: the index of the free and the rhythm-constrained chain, the unstable modes and
# each muscle class's contribution d λ_min / d a_i (docs: *Stability along a recorded motion*). The command line
# does the same with `spinectl motion myotorso --coordinates lift.mot --load torso:0,0,-100 --contributions ...`.
#
# Needs `pip install 'spinectl[anatomy,opensim]'`.

# %% tags=["parameters"]
import os

GRID = int(os.environ.get("SPINECTL_NB_GRID", "21"))  # frames of the 2 s lift
STIFFNESS = 50.0  # N m/rad added at each chain joint (as in the anatomy notebook's optima)

# %%
# %matplotlib inline

import tempfile
from pathlib import Path

import numpy as np
from IPython.display import display

from spinectl import anatomy
from spinectl.anatomy.motion import motion_plot, motion_response, write_motion
from spinectl.anatomy.recordings import read_recording

torso = anatomy.load("myotorso")

# %% [markdown]
# ## The lift, written as an OpenSim `.mot`
#
# Every coordinate the model needs, at 0 except the five sagittal lumbar joints, which flex by up to 6 degrees each
# (MyoTorso's `flex_extension` is positive in extension). `write_motion` writes it with `opensim.STOFileAdapter`, so
# any OpenSim tool reads it; here into a temporary folder.

# %%
names = list(torso.posture_columns().required)
times = np.linspace(0.0, 2.0, GRID)
rows = np.zeros((times.size, len(names)))
for joint in torso.plane_joints("sagittal"):
    rows[:, names.index(joint)] = -6.0 * np.sin(np.pi * times / 2.0)  # [deg]

folder = tempfile.TemporaryDirectory()
lift = read_recording(write_motion(Path(folder.name) / "lift.mot", names, times, rows), "posture")

# %% [markdown]
# ## The index, the modes and the contributions along it
#
# At each frame: the joint-by-joint optimum (the least effort that holds the posture and the load, each joint stable
# on its own), then both chains' eigenvalues and each muscle's d λ_min / d a_i. The load is a force of 100 N down
# at the origin of the `torso` body, fixed in the ground.

# %%
load = [{"body": "torso", "force": (0.0, 0.0, -100.0), "point": (0.0, 0.0, 0.0), "frame": "ground"}]
result = motion_response(
    torso, lift, optimise="joints", joint_stiffness=STIFFNESS, loads=load, contributions=True, progress=False
)
print(result.summary())

# %%
display(motion_plot(result))

# %% [markdown]
# The Dataset holds every number (xarray; `result.dataset.to_netcdf(...)` or `spinectl motion --out` write it). The
# muscles that raise the free chain's index most per unit activation at its least stable frame:

# %%
ds = result.dataset
at = int(np.nanargmin(ds["free_index"].values))
top = ds["free_contribution"].isel(time=at).to_series().sort_values(ascending=False)
print(f"t = {float(ds['time'][at]):.2f} s, free index {float(ds['free_index'][at]):.1f} N m/rad")
top.head(8)

# %%
folder.cleanup()
