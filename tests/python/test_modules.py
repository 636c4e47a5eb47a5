# The modules' entry points: SOML++ markings and steps, URDF loading, kinematics — and their bad input.
import os

import numpy as np
import pytest

import vsd

URDF = os.path.join(os.path.dirname(__file__), "..", "scene", "data", "iiwa14_primitives.urdf")

NET = """
object cell {
  place a; place b;
  transition t { }
  arrow a -> t;
  arrow t -> b;
}
"""


def test_soml_marking_and_step(env):
    s = env.main_state
    vsd.soml.load(env, s, "cell.soml", NET)
    places = {p.name: p for p in s.index("soml::Place")}
    assert isinstance(places["a"], vsd.Place) and places["a"].tokens == 0
    places["a"].tokens = 2  # the marking is a property: set it, and the net fires in the next step
    env.step()
    assert (places["a"].tokens, places["b"].tokens) == (0, 2)
    assert (s.column("soml::Place", "tokens") >= 0).all()


@pytest.fixture
def robot(env):
    vsd.scene.use(env)
    vsd.robotics.use(env)
    report = vsd.scene.load_urdf(env.main_state.database, URDF, load_meshes=False)
    return report, vsd.robotics.build_kinematics(report["scene"])


def test_urdf_forward_inverse(robot, env):
    report, tree = robot
    assert report["links"] == 11 and report["joints"] >= 7
    names = vsd.robotics.joint_names(tree)
    assert len(names) == 7
    q = np.linspace(-0.5, 0.5, 7)
    vsd.robotics.set_positions(tree, q)
    np.testing.assert_allclose(vsd.robotics.positions(tree), q)
    joints = {j.name: j for j in env.main_state.index("robotics::KinematicJoint")}
    assert joints[names[0]].position == pytest.approx(-0.5)  # the same value, read as a property
    pose = vsd.robotics.forward(tree, q)
    assert pose.shape == (4, 4)
    base = vsd.robotics.forward(tree, q, body=vsd.robotics.joint_names(tree) and "iiwa_link_0")
    np.testing.assert_allclose(base, np.eye(4), atol=1e-12)
    ik = vsd.robotics.inverse(tree, pose, seed=np.zeros(7))
    assert ik["success"]
    np.testing.assert_allclose(vsd.robotics.forward(tree, ik["q"]), pose, atol=1e-5)


def test_robotics_bad_input(robot, env):
    _, tree = robot
    with pytest.raises(ValueError, match="7 joints, got 3"):
        vsd.robotics.set_positions(tree, [0.0, 0.0, 0.0])
    with pytest.raises(TypeError):
        vsd.robotics.forward(tree, "abc")
    with pytest.raises(KeyError, match="no body 'nope'"):
        vsd.robotics.forward(tree, np.zeros(7), body="nope")
    with pytest.raises(TypeError, match="4x4"):
        vsd.robotics.inverse(tree, np.eye(3))
    with pytest.raises(TypeError, match="KinematicTree"):
        vsd.robotics.positions(env.main_state.database)


def test_urdf_bad_files(env, tmp_path):
    bad = tmp_path / "bad.urdf"
    bad.write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'><parent link='nope'/>")
    with pytest.raises(vsd.Error, match="bad.urdf"):
        vsd.scene.load_urdf(env.main_state.database, str(bad))
    with pytest.raises(vsd.Error):
        vsd.scene.load_urdf(env.main_state.database, str(tmp_path / "missing.urdf"))
    assert env.main_state.database.children == []  # nothing was left behind
