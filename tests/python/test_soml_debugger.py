# vsd.soml.Program and vsd.soml.Debugger: breakpoints, a Python stop handler reading the stack and locals
# and choosing how to go on, transition breakpoints, and bad input.
import pytest

import vsd

SCRIPT = """int fib(int n) {
  if (n < 2) return n;
  int a = fib(n - 1);
  int b = fib(n - 2);
  return a + b;
}

object cell {
  int served = 0;
  place free = 2;
  place done;
  transition go {
    when served < 2;
    do {
      int r = fib(3);
      served += 1;
    }
  }
  arrow free -> go;
  arrow go -> done;
}
"""


@pytest.fixture
def program(env):
    return vsd.soml.load(env, env.main_state, "dbg.soml", SCRIPT)


def test_load_returns_the_program(program):
    assert program.name == "dbg.soml" and repr(program) == "<vsd.soml.Program 'dbg.soml'>"
    assert isinstance(program.root, vsd.Node) and program.firings == 0


def test_line_breakpoint_stops_with_stack_and_locals(env, program):
    d = vsd.soml.Debugger(program)
    assert d.break_at("dbg.soml:5") == 1
    seen = []

    def on_stop(dbg, stop):
        assert dbg.stopped and stop["reason"] == "breakpoint" and stop["breakpoint"] == 1
        frames = " ".join(f"{f['function']}:{f['line']}" for f in dbg.call_stack())
        seen.append((frames, dbg.locals()))
        return "continue"

    d.on_stop(on_stop)
    env.step()
    assert seen[:2] == [("fib:5 fib:3 cell.go (action):15", {"n": "2", "a": "1", "b": "0"}),
                        ("fib:5 cell.go (action):15", {"n": "3", "a": "1", "b": "1"})]
    assert d.breakpoints[0]["hits"] == len(seen) and not d.stopped
    assert program.firings >= 1


def test_transition_breakpoint_then_step(env, program):
    d = vsd.soml.Debugger(program)
    d.break_on_transition("cell.go")
    stops = []

    def on_stop(dbg, stop):
        stops.append((stop["reason"], stop["transition"].name if stop["transition"] else stop["line"]))
        if stop["reason"] == "transition":
            assert "cell.free = " in dbg.marking()
            return "step"  # into the action: stop at its first line
        return None  # continue

    d.on_stop(on_stop)
    env.step()
    assert stops[:2] == [("transition", "go"), ("step", 15)]
    assert d.print("cell.served") == "cell.served = 2"  # between runs: frame 0 is the script object


def test_bad_input_is_an_exception_with_the_message(env, program, monkeypatch):
    d = vsd.soml.Debugger(program)
    with pytest.raises(vsd.Error, match=r"no code on dbg.soml:7 \(the nearest lines with code: 5 and 9\)"):
        d.break_at(7)
    with pytest.raises(vsd.Error, match="'other.soml' is not the script debugged"):
        d.break_at("other.soml:3")
    with pytest.raises(vsd.Error, match="no transition 'cell.nothing'"):
        d.break_on_transition("cell.nothing")
    with pytest.raises(TypeError, match="break_at expects a line or 'FILE:LINE'"):
        d.break_at(2.5)
    with pytest.raises(ValueError, match="line -1 is not a line"):
        d.break_at(-1)
    with pytest.raises(TypeError, match="on_stop expects a callable or None"):
        d.on_stop(3)
    with pytest.raises(vsd.Error):
        vsd.soml.Debugger(program)  # one debugger per program
    with pytest.raises(TypeError):
        vsd.soml.Debugger("dbg.soml")
    # A handler that returns nonsense or raises is reported (sys.unraisablehook); the program goes on.
    d.break_at(5)
    reported = []
    monkeypatch.setattr("sys.unraisablehook", lambda u: reported.append((type(u.exc_value), str(u.exc_value))))
    calls = []

    def bad(dbg, stop):
        calls.append(stop["line"])
        return "jump" if len(calls) == 1 else 1 / 0

    d.on_stop(bad)
    env.step()
    assert len(calls) == 4  # fib(3)'s line 5 twice per firing, two firings: every stop went on
    assert reported[0] == (ValueError, "soml debugger: on_stop returned 'jump'; expected 'continue', 'step', "
                                       "'next' or 'finish'")
    assert reported[-1][0] is ZeroDivisionError
    d.on_stop(None)
    d.detach()
    with pytest.raises(vsd.Error, match="soml debugger: detached"):
        d.break_at(5)
    assert not d.attached
    vsd.soml.Debugger(program).detach()  # the program can be debugged again


def test_a_program_of_a_removed_state_is_gone(env):
    other = env.create_state("other")
    p = vsd.soml.load(env, other, "dbg.soml", SCRIPT)
    d = vsd.soml.Debugger(p)
    env.remove_state(other)
    assert not d.attached
    with pytest.raises(vsd.Error, match="soml program 'dbg.soml': it is gone"):
        p.root
    with pytest.raises(vsd.Error):
        d.break_at(5)
