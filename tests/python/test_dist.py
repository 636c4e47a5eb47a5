"""vsd.dist from Python: two environments of this process (sites 1 and 2) share a state over Cyclone DDS on
the loopback interface; changes made in one reach the other at the steps, ownership refuses foreign
writes, and bad arguments raise."""
import os
import time

import pytest

import vsd

if not hasattr(vsd, "dist"):
    pytest.skip("vsd::dist is not built", allow_module_level=True)
dist = vsd.dist


def domain():
    # A domain of its own per run, as the C++ tests pick theirs (runs of ctest -j must not hear each other).
    return 1 + (os.getpid() * 7 + 101) % 220


def step_until(envs, done, seconds=10.0):
    end = time.monotonic() + seconds
    while not done():
        assert time.monotonic() < end, "timed out"
        for e in envs:
            e.step()
        time.sleep(0.002)


def test_two_environments_share_a_state():
    robot_env, ui_env = vsd.Environment(site=1), vsd.Environment(site=2)
    d = domain()
    robot = dist.join(robot_env, name="robot", domain=d, seed=True, config=dist.loopback_config,
                      request_interval=0.05)
    ui = dist.join(ui_env, name="ui", domain=d, config=dist.loopback_config, request_interval=0.05)
    assert robot.synced and robot.name == "robot"
    assert not ui.synced
    # The robot answers the ui's snapshot request when it polls: at its environment's steps.
    step_until([robot_env, ui_env], lambda: ui.synced)
    assert ui.wait_peers(1, 10.0) and ui.peers == 1
    assert ui.wait_synced(0.0)

    s = robot_env.main_state
    arm = s.create("Node", name="arm")
    s.database.add_child(arm)
    step_until([robot_env, ui_env], lambda: [n.name for n in ui_env.main_state.database.children] == ["arm"])
    (copy,) = ui_env.main_state.database.children
    assert copy.vsd_id == arm.vsd_id  # ids are unique across sites

    # The robot owns its arm: the ui's write is refused and undone, and both are told.
    robot.claim(arm)
    step_until([robot_env, ui_env], lambda: ui.owner(copy) == robot.id)
    copy.name = "taken"
    step_until([robot_env, ui_env], lambda: copy.name == "arm")
    kinds = [c["kind"] for c in ui.conflicts()]
    assert "owned" in kinds
    assert ui.conflicts() == []  # taken
    assert robot.stats()["bundles_sent"] >= 1 and ui.stats()["bundles_applied"] >= 1
    assert robot.participant_name(ui.id) == "ui"


def test_bad_arguments():
    env = vsd.Environment(site=3)
    with pytest.raises(ValueError, match="domain"):
        dist.join(env, domain=231)
    with pytest.raises(ValueError, match="request_interval"):
        dist.join(env, request_interval=-1)
    other = vsd.Environment(site=4)
    with pytest.raises(ValueError, match="another environment"):
        dist.join(env, other.main_state)
    # The first participant of a domain in a process configures it: a broken configuration is refused.
    with pytest.raises(vsd.Error):
        dist.join(env, domain=(domain() + 110) % 220 + 1, config="<CycloneDDS><not-xml", name="broken")
    p = dist.join(env, domain=domain(), topic="vsd_bad_args", seed=True, config=dist.loopback_config)
    n = other.main_state.create("Node")
    with pytest.raises(ValueError, match="another state"):
        p.claim(n)
    with pytest.raises(TypeError):
        p.claim("arm")
