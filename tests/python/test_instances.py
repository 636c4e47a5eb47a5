import numpy as np
import pytest

import vsd


def test_create_name_and_attach(env):
    s = env.main_state
    n = s.create("Node")
    n.name = "a"
    s.database.add_child(n)
    assert isinstance(n, vsd.Node) and isinstance(n, vsd.Instance)
    assert not isinstance(n, vsd.Database)
    assert isinstance(s.database, vsd.Database) and isinstance(s.database, vsd.Node)
    assert n.parent == s.database and n.path == "/a"
    assert s.database.children == [n]
    assert s.find(n.vsd_id) == n and n.vsd_class == "Node"


def test_create_with_keywords_and_python_class(env):
    s = env.main_state
    n = s.create(vsd.Node, name="k")
    assert n.name == "k" and type(n) is vsd.Node


def test_no_direct_construction():
    with pytest.raises(TypeError, match=r"state.create\(Node"):
        vsd.Node()


def test_unknown_class_names(env):
    with pytest.raises(KeyError, match="NoSuchClass"):
        env.main_state.create("NoSuchClass")
    with pytest.raises(AttributeError, match="NoSuchClass"):
        vsd.NoSuchClass
    with pytest.raises(KeyError):
        env.main_state.index("NoSuchClass")


def test_every_kind_of_property_both_ways(grippers):
    s, left, right = grippers
    assert isinstance(left, vsd.Gripper) and isinstance(left, vsd.Node)
    assert left.width == 0.05 and right.width == 0.06
    assert left.cycles == 0 and left.flags == 3 and left.grip == 1.5 and left.closed is False
    assert left.label == "gripper" and left.force == 20.0
    left.cycles = 7
    left.flags = 255
    left.grip = 2.5
    left.closed = True
    left.label = "L"
    assert (left.cycles, left.flags, left.grip, left.closed, left.label) == (7, 255, 2.5, True, "L")
    # Eigen types as NumPy arrays
    np.testing.assert_array_equal(left.offset, [0, 0, 0])
    left.offset = np.array([1.0, 2.0, 3.0])
    np.testing.assert_array_equal(left.offset, [1, 2, 3])
    frame = np.eye(4)
    frame[:3, 3] = [4, 5, 6]
    left.frame = frame
    np.testing.assert_array_equal(left.frame, frame)
    left.turn = [0.0, 0.0, 0.0, 1.0]  # [w, x, y, z]
    np.testing.assert_array_equal(left.turn, [0, 0, 0, 1])
    # enums as Python enums, by member or by name
    Mode = type(left.mode)
    assert left.mode == Mode.Idle and Mode.__name__ == "Mode"
    left.mode = Mode.Moving
    assert left.mode is Mode.Moving
    left.mode = "Done"
    assert left.mode is Mode.Done
    # lists
    left.joints = [1.0, 2, np.float64(3)]
    left.tags = ("a", "b")
    assert left.joints == [1.0, 2.0, 3.0] and left.tags == ["a", "b"]
    # references as objects
    tool = s.create("Node", name="tool")
    left.tool = tool
    left.target = right
    left.peers = [right]
    assert left.tool == tool and left.target == right and left.peers == [right]
    assert tool.parent is None  # a ref<Node> holds, but is no child
    left.target = None
    assert left.target is None


def test_wrong_types_raise_and_change_nothing(grippers):
    s, left, _ = grippers
    cases = [("width", "x", "double"), ("cycles", 1.5, "int32"), ("closed", 1, "bool"), ("label", 3, "string"),
             ("offset", "abc", "Vector3d"), ("joints", "abc", "vector<double>"), ("tool", 3, "ref<Node>"),
             ("mode", 1.5, "Mode")]
    for prop, bad, expected in cases:
        before = getattr(left, prop)
        with pytest.raises(TypeError) as e:
            setattr(left, prop, bad)
        assert prop in str(e.value) and expected in str(e.value), str(e.value)
        after = getattr(left, prop)
        assert (before == after) if not isinstance(before, np.ndarray) else (before == after).all()
    with pytest.raises(TypeError, match=r"shape \(3,\)"):
        left.offset = [1.0, 2.0]
    with pytest.raises(ValueError, match="does not fit"):
        left.flags = 256
    with pytest.raises(ValueError, match="no value of"):
        left.mode = "Flying"
    with pytest.raises(TypeError, match="peers' element 1"):
        left.peers = [s.database, 3]
    assert left.peers == []
    with pytest.raises(AttributeError):
        left.no_such_property = 1


def test_methods_through_vsdmetacall(grippers):
    _, left, _ = grippers
    assert left.span(1.0) == pytest.approx(1.05)
    assert left.span(2) == pytest.approx(2.05)  # an int converts
    assert left.ready() is True
    left.closed = True
    assert left.ready() is False
    left.open()
    assert left.width == 0.08 and left.closed is False
    with pytest.raises(TypeError, match="takes 1 argument"):
        left.span()
    with pytest.raises(TypeError, match="argument 1"):
        left.span("wide")


def test_vsd_errors_become_vsd_error(env):
    s = env.main_state
    with pytest.raises(vsd.Error, match="Database|root"):
        s.destroy(s.database)
    a = s.create("Node", name="a")
    s.database.add_child(a)
    with pytest.raises(vsd.Error):
        a.add_child(s.database)  # a cycle
    assert issubclass(vsd.Error, RuntimeError)


def test_dead_handles_raise(env):
    s = env.main_state
    n = s.create("Node", name="gone")
    s.destroy(n)
    assert not n.vsd_alive and "dead" in repr(n)
    with pytest.raises(vsd.DeadInstanceError, match="gone|deleted"):
        n.name
    with pytest.raises(vsd.DeadInstanceError):
        n.name = "x"
    with pytest.raises(vsd.DeadInstanceError):
        s.database.add_child(n)
    # a new instance may reuse the memory: the old handle stays dead
    m = s.create("Node", name="new")
    assert m.vsd_alive and not n.vsd_alive
    assert issubclass(vsd.DeadInstanceError, vsd.Error)


def test_removed_state_and_collected_environment():
    env = vsd.Environment()
    other = env.create_state("other")
    n = other.create("Node", name="x")
    env.remove_state(other)
    with pytest.raises(vsd.DeadInstanceError):
        n.name
    with pytest.raises(ValueError):
        other.create("Node")
    # Handles keep their environment alive: dropping the Environment object leaves them usable.
    keep = env.main_state.create("Node", name="kept")
    del env
    import gc
    gc.collect()
    assert keep.name == "kept"


def test_columns_read_and_write(env):
    s = env.main_state
    nodes = [s.create("Node", name=f"n{i}") for i in range(5)]
    names = s.column("Node", "name")
    assert sorted(names) == sorted(["", *(n.name for n in nodes)])  # the Database is a Node too
    env2 = vsd.Environment()
    s2 = env2.main_state
    vsd.soml.load(env2, s2, "g.soml", __import__("conftest").GRIPPER)
    widths = s2.column("Gripper", "width")
    assert isinstance(widths, np.ndarray) and widths.dtype == np.float64 and len(widths) == 2
    order = s2.index("Gripper")
    assert list(widths) == [g.width for g in order]
    changed = []
    with s2.on_property_changed(lambda inst, prop: changed.append((inst.name, prop)), "Gripper"):
        with s2.record() as rec:
            s2.set_column("Gripper", "width", np.array([0.5, 0.25]))
    assert [g.width for g in order] == [0.5, 0.25]
    assert sorted(changed) == sorted((g.name, "width") for g in order)
    assert len(rec.transaction) == 2
    offsets = s2.column("Gripper", "offset")
    assert offsets.shape == (2, 3)
    with pytest.raises(ValueError, match="2 instances"):
        s2.set_column("Gripper", "width", np.zeros(3))
    with pytest.raises(AttributeError):
        s2.column("Gripper", "nope")
