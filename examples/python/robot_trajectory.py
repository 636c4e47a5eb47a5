"""Loads a URDF robot (the KUKA iiwa 14 of the scene tests), drives its joints from a Python task of
the scheduler for five simulated seconds, and plots the joint trajectory and the tool's height to a PNG.

    PYTHONPATH=build/python python3 examples/python/robot_trajectory.py [robot.urdf] [out.png]

The two-robot work cell is a C++ program (examples/workcell) and not reachable from Python yet, so this
example builds its own cell from a URDF file.
"""
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import vsd  # noqa: E402

here = os.path.dirname(os.path.abspath(__file__))
urdf = sys.argv[1] if len(sys.argv) > 1 else os.path.join(here, "..", "..", "tests", "scene", "data",
                                                          "iiwa14_primitives.urdf")
out = sys.argv[2] if len(sys.argv) > 2 else "robot_trajectory.png"

env = vsd.Environment()
vsd.scene.use(env)
vsd.robotics.use(env)  # joint positions move their links in every step
state = env.main_state
report = vsd.scene.load_urdf(state.database, urdf, load_meshes=False)
tree = vsd.robotics.build_kinematics(report["scene"])
names = vsd.robotics.joint_names(tree)
print(f"{os.path.basename(urdf)}: {report['links']} links, {len(names)} joints: {', '.join(names)}")

# Each joint swings around zero at its own frequency, within 40 % of its limits.
joints = {j.name: j for j in state.index("robotics::KinematicJoint")}
amplitude = [0.4 * min(abs(joints[n].lower), abs(joints[n].upper)) if joints[n].has_limits else 0.5
             for n in names]
times, trajectory, height = [], [], []


def drive(t, step):
    q = [a * math.sin(2 * math.pi * (0.2 + 0.05 * i) * t) for i, a in enumerate(amplitude)]
    vsd.robotics.set_positions(tree, q)  # recorded and signalled, like any change
    times.append(t)
    trajectory.append(vsd.robotics.positions(tree))
    height.append(vsd.robotics.forward(tree, q)[2, 3])


env.add_task("python driver", drive, period=0.01, phase=100)  # the controllers' phase
env.run_for(5.0)
trajectory = np.array(trajectory)
print(f"simulated {env.time:.2f} s in {len(times)} steps; tool height {min(height):.3f} .. {max(height):.3f} m")

fig, (top, bottom) = plt.subplots(2, 1, sharex=True, figsize=(8, 6))
for i, n in enumerate(names):
    top.plot(times, trajectory[:, i], label=n)
top.set_ylabel("joint position [rad]")
top.legend(fontsize="small", ncol=4)
bottom.plot(times, height)
bottom.set_ylabel("tool height [m]")
bottom.set_xlabel("simulated time [s]")
fig.suptitle(f"{os.path.basename(urdf)} driven from Python for 5 s")
fig.savefig(out, dpi=80)
print(f"wrote {out}")
