# Every ```python block of docs/python.md runs, in order, in one namespace.
import gc
import os
import re

import pytest

ROOT = os.path.join(os.path.dirname(__file__), "..", "..")


def test_docs_python_blocks(monkeypatch):
    text = open(os.path.join(ROOT, "docs", "python.md"), encoding="utf-8").read()
    blocks = re.findall(r"^```python\n(.*?)^```", text, flags=re.S | re.M)
    assert len(blocks) >= 8
    monkeypatch.setenv("VSD_SOURCE_DIR", ROOT)
    ns = {}
    for i, block in enumerate(blocks):
        try:
            exec(compile(block, f"docs/python.md block {i + 1}", "exec"), ns)
        except Exception as e:  # pragma: no cover - the message says which block
            pytest.fail(f"docs/python.md block {i + 1}: {type(e).__name__}: {e}")
    ns.clear()  # the environments go, and the SOML++ classes with them
    gc.collect()
