# Shared fixtures of the Python tests (run by ctest as vsd_python_tests, label `python`).
import os

import pytest

import vsd

GRIPPER = """
enum Mode { Idle, Moving, Done, }
class Gripper : Node {
  double width = 0.08;
  int32 cycles = 0;
  uint8 flags = 3;
  float grip = 1.5;
  bool closed = false;
  string label = "gripper";
  Vector3d offset;
  Isometry3d frame;
  Quaterniond turn;
  vector<double> joints;
  vector<string> tags;
  Mode mode = Mode::Idle;
  ref<Node> tool;
  shared<Node> target;
  list<Node> parts;
  shared_list<Gripper> peers;
  Gripper(double w) { width = w; }
  void open() { width = 0.08; closed = false; }
  double span(double extra) { return width + extra; }
  bool ready() { return !closed && mode == Mode::Idle; }
}
object left : Gripper(0.05) { double force = 20.0; }
object right : Gripper(0.06);
"""

DATA = os.environ.get("VSD_TEST_DATA", os.path.join(os.path.dirname(__file__), "..", "scene", "data"))


@pytest.fixture
def env():
    return vsd.Environment()


@pytest.fixture
def grippers(env):
    """A state with the SOML++ Gripper objects left and right (every kind of property)."""
    s = env.main_state
    vsd.soml.load(env, s, "gripper.soml", GRIPPER)
    left, right = sorted(s.index("Gripper"), key=lambda g: g.name)
    return s, left, right
