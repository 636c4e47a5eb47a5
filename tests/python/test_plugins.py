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
    node, gauge = s.database.children
    assert node.name == "counter" and gauge.name == "gauge"
    assert isinstance(gauge, vsd.Node) and type(gauge).__name__ == "PluginGauge"  # the plugin's own class
    env.step()
    env.step()
    assert node.name == "steps 2"  # the plugin's task, through the object the environment keeps
    # A second load into another environment: the library is loaded once, each build is its own.
    other = vsd.Environment()
    vsd.load_plugin(PLUGIN, other, ["second"])
    other.step()
    assert [n.name for n in other.main_state.database.children] == ["steps 1", "gauge"]
    assert node.name == "steps 2"


@needs_plugins
def test_a_read_only_property_refuses_assignment_and_keeps_its_value(env):
    vsd.load_plugin(PLUGIN, env, ["counter"])
    s = env.main_state
    (gauge,) = s.index("PluginGauge")
    s.start_recording()
    changes = []
    with s.on_property_changed(lambda inst, prop: changes.append(prop)):
        with pytest.raises(AttributeError, match="property 'PluginGauge.serial' is read-only"):
            gauge.serial = 8
        with pytest.raises(AttributeError, match="property 'PluginGauge.serial' is read-only"):
            setattr(gauge, "serial", 9)
        with pytest.raises(AttributeError, match="property 'PluginGauge.serial' is read-only"):
            s.set_column("PluginGauge", "serial", [10])
        gauge.reading = 1.5  # its writable neighbour is writable
    assert gauge.serial == 7 and list(s.column("PluginGauge", "serial")) == [7]
    assert changes == ["reading"]  # no change of serial signalled ...
    assert len(s.stop_recording()) == 1  # ... nor recorded


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
