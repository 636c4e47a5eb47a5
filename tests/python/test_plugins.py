# vsd.load_plugin (include/vsd/python/plugin.hpp): a C++ library that builds into an environment — the
# test plugin (python/plugin/test_plugin.cpp), its errors, and the two-robot work cell's plugin.
import os
import subprocess
import sys

import pytest

import vsd

PLUGIN = os.environ.get("VSD_TEST_PLUGIN", "")
WRONG_ABI = os.environ.get("VSD_TEST_PLUGIN_WRONG_ABI", "")
CELL = os.environ.get("VSD_CELL_PLUGIN", "")
needs_plugins = pytest.mark.skipif(not os.path.isfile(PLUGIN), reason="the test plugins are built by CMake (ctest)")


@needs_plugins
def test_plugin_builds_into_the_environment_and_its_task_runs(env):
    info = vsd.load_plugin(PLUGIN, env, ["counter"])
    assert info == {"node": "counter"}
    s = env.main_state
    (node,) = [n for n in s.database.children]
    assert node.name == "counter"
    env.step()
    env.step()
    assert node.name == "steps 2"  # the plugin's task, through the object the environment keeps
    # A second load into another environment: the library is loaded once, each build is its own.
    other = vsd.Environment()
    vsd.load_plugin(PLUGIN, other, ["second"])
    other.step()
    assert [n.name for n in other.main_state.database.children] == ["steps 1"]
    assert node.name == "steps 2"


@needs_plugins
def test_plugin_errors_are_exceptions_with_their_message(env, tmp_path):
    with pytest.raises(vsd.Error, match=r"load_plugin: .*vsd_test_plugin.*: asked to fail"):
        vsd.load_plugin(PLUGIN, env, ["fail"])
    with pytest.raises(vsd.Error, match="expects one argument, the node's name"):
        vsd.load_plugin(PLUGIN, env)
    with pytest.raises(FileNotFoundError, match="load_plugin: no file /nonexistent/plugin.so"):
        vsd.load_plugin("/nonexistent/plugin.so", env)
    text = tmp_path / "not_a_library.so"
    text.write_text("hello")
    with pytest.raises(ImportError, match="load_plugin: cannot load .*not_a_library.so: "):
        vsd.load_plugin(str(text), env)
    # A shared library that is no plugin: the module's own.
    with pytest.raises(ImportError, match="is not a vsd Python plugin: it has no symbol vsd_python_plugin_abi"):
        vsd.load_plugin(vsd._core.__file__, env)
    with pytest.raises(ImportError, match=r"was built for another ABI \('vsd-python-plugin 0; another compiler'\); "
                                          r"this module is 'vsd-python-plugin 1; "):
        vsd.load_plugin(WRONG_ABI, env)
    with pytest.raises(TypeError):
        vsd.load_plugin(PLUGIN, "not an environment", ["x"])
    with pytest.raises(TypeError):
        vsd.load_plugin(PLUGIN, env, "not a list")
    assert list(env.main_state.database.children) == []  # nothing half-built


@pytest.mark.skipif(not os.path.isfile(CELL), reason="the work cell's plugin is not built")
def test_cell_plugin_refuses_the_loops_options():
    # In a process of its own: the cell's classes (Robot, Conveyor, Part, ...) stay in the Registry once the
    # library is loaded, and other tests define Python classes of those names.
    script = """
import sys, vsd
env = vsd.Environment()
for args in (["--png", "x.png"], ["--frobnicate"]):
    try:
        vsd.load_plugin(sys.argv[1], env, args)
    except vsd.Error as e:
        print(e)
print(len(env.main_state.database.children))
"""
    r = subprocess.run([sys.executable, "-c", script, CELL], capture_output=True, text=True, timeout=60)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert lines[0].endswith(": --csv, --png and --time-limit belong to vsd_two_robot_cell's loop; from Python, "
                             "step the environment and record what you need")
    assert lines[1].endswith(": unknown option '--frobnicate'")
    assert lines[2] == "0"  # refused before anything was built
