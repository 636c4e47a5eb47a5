"""vsd.analysis from Python: nets built by hand, read from PNML (a Model Checking Contest net with its
known state space) and from a SOML++ script; their state spaces; bad input raises with a position."""
import os

import pytest

import vsd

if not hasattr(vsd, "analysis"):
    pytest.skip("vsd::analysis is not built", allow_module_level=True)
an = vsd.analysis
DATA = os.path.join(os.path.dirname(__file__), "..", "analysis")


def mutex_by_hand():
    n = an.Net("mutex")
    for p, tokens in (("lock", 1), ("idle1", 1), ("crit1", 0), ("idle2", 1), ("crit2", 0)):
        n.add_place(p, initial=tokens)
    for k in ("1", "2"):
        enter, leave = n.add_transition("enter" + k), n.add_transition("leave" + k)
        n.add_input(enter, "lock")
        n.add_input(enter, "idle" + k)
        n.add_output(enter, "crit" + k)
        n.add_input(leave, "crit" + k)
        n.add_output(leave, "idle" + k)
        n.add_output(leave, "lock")
    return n


def test_a_net_by_hand_and_its_state_space():
    n = mutex_by_hand()
    assert repr(n) == "<vsd.analysis.Net 'mutex': 5 places, 4 transitions>"
    assert n.places[0] == ("lock", "lock", 1) and n.transitions[1] == ("leave1", "leave1")
    m = n.initial_marking()
    assert n.enabled("enter1", m) and not n.enabled("leave1", m)
    m = n.fire("enter1", m)
    assert m == [0, 0, 1, 1, 0] and not n.enabled("enter2", m)
    with pytest.raises(vsd.Error):
        n.fire("enter2", m)
    r = an.explore(n)
    assert (r["status"], r["states"], r["edges"], r["deadlock"]) == ("complete", 3, 4, False)
    assert an.explore(n, threads=2)["states"] == 3
    # The same net read back from its PNML and from its SOML++ text.
    again, notes = an.read_pnml(n.to_pnml())
    assert again.places == n.places and an.explore(again)["edges"] == 4
    from_soml, notes = an.read_soml(n.to_soml(), "mutex.soml")
    assert an.explore(from_soml)["states"] == 3


def test_a_model_checking_contest_net():
    # tests/analysis/data/expected.tsv: Philosophers-PT-000005 has 243 states, 945 edges and a deadlock.
    net, notes = an.read_pnml_file(os.path.join(DATA, "data", "Philosophers-PT-000005.pnml"))
    assert len(net.places) == 25 and len(net.transitions) == 25 and net.arc_count == 80
    r = an.explore(net, threads=2)
    assert (r["states"], r["edges"], r["deadlock"]) == (243, 945, True)
    # A dead marking is reached by the shortest trace; replaying it by hand leaves nothing enabled.
    m = net.initial_marking()
    for t in r["dead_trace"]:
        m = net.fire(t, m)
    assert not any(net.enabled(t, m) for t, _ in net.transitions)


def test_a_soml_script_notes_what_it_ignores():
    net, notes = an.read_soml_file(os.path.join(DATA, "mutex.soml"))
    assert an.explore(net)["states"] == 3
    assert any("mutex.soml:" in line and "ignored" in line for line in notes)


def test_bad_input():
    with pytest.raises(vsd.Error, match=r"bad\.pnml:\d+:\d+"):
        an.read_pnml("<pnml><net", "bad.pnml")
    with pytest.raises(vsd.Error, match="malformed.pnml"):
        an.read_pnml_file(os.path.join(DATA, "malformed.pnml"))
    with pytest.raises(vsd.Error, match=r"x\.soml:1:\d+"):
        an.read_soml("place p = ;", "x.soml")
    with pytest.raises(vsd.Error):
        an.read_pnml_file(os.path.join(DATA, "no such file.pnml"))
    n = mutex_by_hand()
    with pytest.raises(KeyError, match="no place 'nowhere'"):
        n.add_input("enter1", "nowhere")
    with pytest.raises(vsd.Error):
        n.add_place("lock")  # ids are unique
    with pytest.raises(ValueError, match="one count per place"):
        n.enabled("enter1", [1, 2])
    with pytest.raises(ValueError, match="threads"):
        an.explore(n, threads=0)
    # An unbounded net stops with the pair of markings that proves it.
    u = an.Net("grow")
    u.add_place("p", initial=1)
    t = u.add_transition("t")
    u.add_input(t, "p")
    u.add_output(t, "p", 2)
    r = an.explore(u)
    assert r["status"] == "unbounded" and r["unbounded_cycle"] == ["t"]
