# Every ```python block of docs/python.md runs, in order, in one namespace — in an interpreter of its own,
# since the page loads the work cell's plugin, whose classes (Robot, Conveyor, ...) then stay in the
# Registry for the rest of the process (other tests define Python classes of those names).
import os
import re
import subprocess
import sys

import pytest

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")

RUNNER = """
import gc, re, sys
text = open(sys.argv[1], encoding="utf-8").read()
blocks = re.findall(r"^```python\\n(.*?)^```", text, flags=re.S | re.M)
print(len(blocks), "blocks")
ns = {}
for i, block in enumerate(blocks):
    try:
        exec(compile(block, f"docs/python.md block {i + 1}", "exec"), ns)
    except Exception as e:
        print(f"docs/python.md block {i + 1}: {type(e).__name__}: {e}")
        sys.exit(1)
ns.clear()  # the environments go, and the SOML++ classes with them
gc.collect()
print("ok")
"""


def test_docs_python_blocks():
    env = dict(os.environ, VSD_SOURCE_DIR=ROOT)
    r = subprocess.run([sys.executable, "-c", RUNNER, os.path.join(ROOT, "docs", "python.md")], env=env,
                       capture_output=True, text=True, timeout=120)
    if r.returncode != 0 or not r.stdout.endswith("ok\n"):
        pytest.fail(r.stdout + r.stderr)
    assert int(r.stdout.split()[0]) >= 9
