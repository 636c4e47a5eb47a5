"""Loads the paper's two-robot work cell (examples/workcell/two_robots, built as the plugin
vsd_two_robot_cell_plugin), runs it for five simulated seconds and plots both robots' joint trajectories
to a PNG with matplotlib.

    PYTHONPATH=build/python python3 examples/python/workcell_trajectory.py \\
        build/examples/vsd_two_robot_cell_plugin.so [out.png]

The cell is C++ (its plant is a scheduler task, its controls two SOML++ nets): vsd.load_plugin builds it
into a Python environment, and stepping that environment from Python runs it. A Python task of the
scheduler reads the joint positions after every step; a signal listener notes the motions the nets command.
Prints its figures and `check: ok` when the clock reached 5 s, a robot moved and the PNG is written.
"""
import os
import sys

import matplotlib

matplotlib.use("Agg")  # no display needed
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import vsd  # noqa: E402

plugin = sys.argv[1] if len(sys.argv) > 1 else os.path.join("build", "examples", "vsd_two_robot_cell_plugin.so")
out = sys.argv[2] if len(sys.argv) > 2 else "workcell_trajectory.png"

env = vsd.Environment()
info = vsd.load_plugin(plugin, env, ["--seed", "1"])  # the options of vsd_two_robot_cell
state = env.main_state
print(f"cell loaded: robots {info['robots']}, base step {info['step']} s")

# Each robot is an 8-axis arm (a linear axis and the iiwa14's 7 joints): the scene arm_a / arm_b with a
# robotics::KinematicTree extension; its σ/γ interface to the nets is the node robot_a / robot_b.
arms = {n.name: n for n in state.index("scene::Scene") if n.name in ("arm_a", "arm_b")}
trees = {name: next(e for e in arm.extensions if e.vsd_class == "robotics::KinematicTree")
         for name, arm in sorted(arms.items())}
names = vsd.robotics.joint_names(trees["arm_a"])
times, q = [], {name: [] for name in trees}


def record(t, step):
    times.append(t)
    for name, tree in trees.items():
        q[name].append(vsd.robotics.positions(tree))


env.add_task("record joints", record, phase=700)  # every step, after the cell's own tasks
moves = []  # (time, robot): a γ move_to or grasp made the robot's σ `arrived` false


def on_change(robot, prop):
    if prop == "arrived" and not robot.arrived:
        moves.append((env.time, robot.name))


listener = state.on_property_changed(on_change, "Robot")

env.run_for(5.0)  # the cell's plant, its nets, physics and collision, step by step
listener.disconnect()

outfeed = next(n for n in state.database.children if n.name == "outfeed")
conveyors = [c for c in state.index("Conveyor")]
moved = {name: float(np.abs(np.asarray(v) - v[0]).max()) for name, v in q.items()}
print(f"clock: {env.time:.2f} s in {len(times)} steps")
print(f"parts arrived at the conveyor's sensors: {sum(c.arrivals for c in conveyors)}, "
      f"handled: {len(outfeed.children)}")
print("motions commanded by the nets: " + (", ".join(f"{r} at {t:.2f} s" for t, r in moves) or "none"))
for name in trees:
    print(f"robot_{name[-1]} moved: {moved[name]:.3f} (largest joint travel, m or rad)")

fig, axes = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
for ax, (name, values) in zip(axes, q.items()):
    a = np.asarray(values)
    for j in range(a.shape[1]):
        ax.plot(times, a[:, j], label=names[j])
    ax.set_ylabel(f"{name} joints (m, rad)")
axes[0].legend(fontsize=6, ncol=4)
axes[1].set_xlabel("simulated time (s)")
fig.suptitle("two-robot work cell, seed 1: joint positions")
fig.savefig(out, dpi=80)
with open(out, "rb") as f:
    is_png = f.read(8) == b"\x89PNG\r\n\x1a\n"
ok = abs(env.time - 5.0) < 1e-6 and len(times) >= 499 and max(moved.values()) > 0.01 and is_png
print("check: " + ("ok" if ok else "FAILED"))
print(f"wrote {out}")
sys.exit(0 if ok else 1)
