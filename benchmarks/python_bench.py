"""Python bindings' speed (issue 26): a vsd property read and written from Python against a plain Python
attribute and a pybind11 def_readwrite member, and a column read of 100,000 instances.

    PYTHONPATH=build/python python3 benchmarks/python_bench.py [--quick]

Goals: property get/set at most 2x the def_readwrite member; a column read at least 50 M values/s.
Each figure is the best of 5 repeats (timeit), in ns per operation.
"""
import sys
import timeit

import vsd

QUICK = "--quick" in sys.argv
N = 20_000 if QUICK else 1_000_000
COLUMN = 100_000


class Body(vsd.Node):
    mass: float = 1.0


class Plain:
    def __init__(self):
        self.mass = 1.0


def best(stmt, setup_globals, number):
    t = min(timeit.repeat(stmt, globals=setup_globals, number=number, repeat=5))
    return t / number * 1e9


def main():
    env = vsd.Environment()
    s = env.main_state
    body = s.create(Body)
    plain = Plain()
    member = vsd._core._BenchStruct()
    g = {"body": body, "plain": plain, "member": member}
    rows = []
    for what, obj in (("plain Python attribute", "plain.mass"), ("pybind11 def_readwrite", "member.x"),
                      ("vsd property (double)", "body.mass")):
        get = best(f"{obj}", g, N)
        put = best(f"{obj} = 2.0", g, N)
        rows.append((what, get, put))
    name_get = best("body.name", g, N)
    name_put = best("body.name = 'b'", g, N)

    for _ in range(COLUMN - 1):
        s.create(Body)
    reads = 5 if QUICK else 50
    t = min(timeit.repeat(lambda: s.column(Body, "mass"), number=reads, repeat=5)) / reads
    column = s.column(Body, "mass")
    assert len(column) == COLUMN and column.sum() == COLUMN - 1 + 2.0  # `body` was set to 2.0 above
    t_index = min(timeit.repeat(lambda: s.index(Body), number=1, repeat=3))

    print(f"{'':28s} {'get ns':>8s} {'set ns':>8s}")
    for what, get, put in rows:
        print(f"{what:28s} {get:8.1f} {put:8.1f}")
    print(f"{'vsd property (string name)':28s} {name_get:8.1f} {name_put:8.1f}")
    ref = rows[1]
    print(f"vsd / def_readwrite: get {rows[2][1] / ref[1]:.2f}x, set {rows[2][2] / ref[2]:.2f}x (goal <= 2x)")
    print(f"column read of {COLUMN} instances: {t * 1e3:.3f} ms = {COLUMN / t / 1e6:.0f} M values/s (goal >= 50)")
    print(f"index() of {COLUMN} instances (a Python object each): {t_index * 1e3:.1f} ms")


if __name__ == "__main__":
    main()
