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


def test_physics_box_falls_onto_the_ground_and_collision_sees_it(env):
    vsd.scene.use(env)
    vsd.physics.use(env)
    vsd.collision.use(env)
    s = env.main_state
    room = s.create("scene::Scene", name="room")
    s.database.add_child(room)
    room.add_extension(s.create("physics::World"))
    ground = s.create("scene::Hull", name="ground", role="Collision",
                      geometry=s.create("scene::Geometry", kind="Plane"))
    frame = np.eye(4)
    frame[2, 3] = 0.5
    box = s.create("scene::Hull", name="box", role="Collision", frame=frame,
                   geometry=s.create("scene::Geometry", kind="Box", size=np.array([0.1, 0.1, 0.1])))
    room.add_child(ground)
    room.add_child(box)
    body = s.create("physics::RigidBody", mass=1.0)
    box.add_extension(body)
    assert list(box.extensions) == [body]
    env.run_for(1.0)
    z = box.frame[2, 3]
    assert abs(z - 0.05) < 0.01  # fell 0.45 m and lies on the ground
    contacts = vsd.collision.contacts(s)
    assert {frozenset((c["a"].name, c["b"].name)) for c in contacts} == {frozenset(("ground", "box"))}
    assert all(c["depth"] >= 0 and c["position"].shape == (3,) for c in contacts)
    d, pa, pb = vsd.collision.distance(s, box, ground)
    assert d < 0.01 and pa.shape == (3,)


def test_physics_and_collision_bad_input(env):
    s = env.main_state
    node = s.create("Node")
    with pytest.raises(ValueError, match=r"does not use the collision module \(vsd.collision.use\(env\)\)"):
        vsd.collision.contacts(s)
    vsd.collision.use(env)
    with pytest.raises(TypeError, match="collision.distance: expected a scene::Hull, got a Node"):
        vsd.collision.distance(s, node, node)
    with pytest.raises(ValueError, match="collision.use: period must be >= 0"):
        vsd.collision.use(env, -1.0)
    with pytest.raises(TypeError):
        vsd.physics.use("not an environment")
    with pytest.raises(TypeError, match="add_extension: expected an Extension, got a Node"):
        node.add_extension(s.create("Node"))
    body = s.create("physics::RigidBody")
    s.destroy(body)
    with pytest.raises(vsd.DeadInstanceError):
        node.add_extension(body)
