import gc

import numpy as np
import pytest

import vsd


def build(s):
    a = s.create("Node", name="a")
    s.database.add_child(a)
    a.add_child(s.create("Node", name="b"))
    return a


def test_transactions_record_apply_invert_bytes(env):
    s = env.main_state
    replica = env.create_state("replica")
    with s.record() as rec:
        a = build(s)
        a.name = "A"
    t = rec.transaction
    assert len(t) > 0 and "Set" in t.describe() or "set" in t.describe().lower()
    data = t.bytes()
    assert isinstance(data, bytes) and data[:4] == b"VSDT"
    replica.apply(vsd.Transaction.from_bytes(data))
    assert s.equals(replica)[0], s.equals(replica)[1]
    assert replica.database.children[0].name == "A"
    replica.apply(t.inverted())
    assert replica.database.children == []
    with pytest.raises(vsd.Error):
        vsd.Transaction.from_bytes(b"nonsense")
    with pytest.raises(vsd.Error):
        replica.apply(data[:-3] + b"\xff\xff\xff")  # a broken bundle changes nothing
    assert replica.database.children == []


def test_python_classes_replicate_through_bundles(env):
    # A class defined in Python is a run-time vsd class like any other: its instances and their changes
    # travel in recorded bundles (what vsd::dist sends) to a state of another environment.
    class Feeder(vsd.Node):
        rate: float = 1.5
        lane: int = 2

    s = env.main_state
    with s.record() as rec:
        f = s.create(Feeder, name="f1")
        s.database.add_child(f)
        f.rate = 3.25
    other = vsd.Environment()
    replica = other.main_state
    replica.apply(vsd.Transaction.from_bytes(rec.transaction.bytes()))
    (copy,) = replica.index(Feeder)
    assert type(copy) is Feeder and copy.name == "f1" and copy.rate == 3.25 and copy.lane == 2
    with s.record() as rec:
        f.lane = 5
    replica.apply(vsd.Transaction.from_bytes(rec.transaction.bytes()))
    assert copy.lane == 5
    replica.apply(rec.transaction.inverted())
    assert copy.lane == 2


def test_io_save_and_load(env, tmp_path):
    s = env.main_state
    build(s)
    for name in ("state.vsd", "state.json"):
        path = str(tmp_path / name)
        assert vsd.io.save(s, path) >= 3
        other = vsd.Environment()
        vsd.io.load(other.main_state, path)
        assert other.main_state.database.children[0].children[0].name == "b"
    bad = tmp_path / "bad.vsd"
    bad.write_bytes(b"not a vsd file")
    with pytest.raises(vsd.Error, match="bad.vsd"):
        vsd.io.load(vsd.Environment().main_state, str(bad))
    with pytest.raises(vsd.Error):
        vsd.io.load(vsd.Environment().main_state, str(tmp_path / "missing.vsd"))


def test_signals_on_the_stepping_thread(env):
    s = env.main_state
    created, changed, deleted, ticks = [], [], [], []
    c1 = s.on_created(lambda i: created.append(i.vsd_class))
    c2 = s.on_property_changed(lambda i, p: changed.append(p))
    c3 = s.on_deleted(lambda i: deleted.append(i.name))
    n = s.create("Node", name="n")
    env.add_task("py", lambda t, step: (ticks.append(step), setattr(n, "name", f"n{step}")), period=0.0)
    env.run_for(0.05)
    assert ticks == [1, 2, 3, 4, 5] and n.name == "n5"
    assert created == ["Node"] and changed.count("name") == 6
    s.destroy(n)
    assert deleted == ["n5"]
    for c in (c1, c2, c3):
        c.disconnect()
    s.create("Node")
    assert created == ["Node"]


def test_a_raising_listener_does_not_break_the_step(env):
    s = env.main_state
    n = s.create("Node", name="n")

    def bad(i, p):
        raise RuntimeError("listener failed")

    seen = []
    import sys
    old = sys.unraisablehook
    sys.unraisablehook = lambda u: seen.append(str(u.exc_value))
    try:
        with s.on_property_changed(bad):
            n.name = "m"
    finally:
        sys.unraisablehook = old
    assert n.name == "m" and seen == ["listener failed"]


def test_python_classes_become_vsd_classes(env, tmp_path):
    class Conveyor(vsd.Node):
        belt_speed: float = 0.2
        items: int = 3
        label: str = "belt"

        def doubled(self):
            return 2 * self.belt_speed

    assert "Conveyor" in vsd.class_names()
    s = env.main_state
    c = s.create(Conveyor, name="c1")
    assert type(c) is Conveyor and isinstance(c, vsd.Node)
    assert c.belt_speed == 0.2 and c.items == 3 and c.label == "belt" and c.doubled() == 0.4
    c.belt_speed = 0.5
    with pytest.raises(TypeError, match="belt_speed"):
        c.belt_speed = "fast"
    s.database.add_child(c)
    assert s.index(Conveyor) == [c]
    path = str(tmp_path / "cell.json")
    vsd.io.save(s, path)
    other = vsd.Environment()
    vsd.io.load(other.main_state, path)
    (loaded,) = other.main_state.index("Conveyor")
    assert type(loaded) is Conveyor and loaded.belt_speed == 0.5
    # SOML++ sees it like any class
    vsd.soml.load(env, s, "uses.soml", "class FastConveyor : Conveyor { double boost = 2.0; }\n"
                                       "object fc : FastConveyor {}\n")
    (fc,) = [x for x in s.index(Conveyor) if x.name == "fc"]
    assert isinstance(fc, Conveyor) and fc.belt_speed == 0.2 and fc.boost == 2.0
    with pytest.raises(TypeError, match="annotation"):
        class Bad(vsd.Node):
            thing: dict = {}


def test_stubs(tmp_path):
    import vsd.stubs
    text = vsd.stubs.generate()
    assert "class Node(NamedModelInstance):" in text
    assert "children: list[Node]" in text
    out = tmp_path / "vsd.pyi"
    vsd.stubs.main(["stubs", str(out)])
    compile(out.read_text(), str(out), "exec")  # the stub is valid Python


def test_soml_load_errors(env):
    with pytest.raises(vsd.Error, match="bad.soml"):
        vsd.soml.load(env, env.main_state, "bad.soml", "class {")
    gc.collect()


def test_python_class_annotations(env):
    class Holder(vsd.Node):
        target: vsd.Node
        samples: "vector<double>" = [1.0, 2.0]
        on: bool = True

    s = env.main_state
    h = s.create(Holder)
    assert h.target is None and h.samples == [1.0, 2.0] and h.on is True
    other = s.create("Node", name="o")
    h.target = other
    assert h.target == other
    s.destroy(other)
    assert h.target is None  # a shared reference is nulled when its target dies
    with pytest.raises(vsd.Error, match="defined already"):
        class Holder(vsd.Node):  # noqa: F811  (the same name, other properties)
            something_else: int = 1
