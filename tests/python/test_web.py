"""vsd.web from Python: the inspector of a simulation stepped by Python answers the page between steps,
refuses writes without the token and applies them with it, through the setters."""
import json
import threading
import urllib.error
import urllib.request

import pytest

import vsd

if not hasattr(vsd, "web"):
    pytest.skip("vsd::web is not built", allow_module_level=True)
web = vsd.web


def request(url, body=None, token=None):
    """(status, JSON answer) of one request; runs on a thread of its own while the test steps."""
    headers = {"Content-Type": "application/json"}
    if token is not None:
        headers["X-VSD-Token"] = token
    data = None if body is None else json.dumps(body).encode()
    req = urllib.request.Request(url, data=data, headers=headers, method="GET" if body is None else "POST")
    try:
        with urllib.request.urlopen(req, timeout=10) as r:
            return r.status, json.loads(r.read())
    except urllib.error.HTTPError as e:
        return e.code, json.loads(e.read() or b"{}")


def while_stepping(env, server, fn):
    """Runs fn on a thread and steps env (the server's jobs run at the step boundaries) until it returns."""
    out = {}
    t = threading.Thread(target=lambda: out.setdefault("r", fn()))
    t.start()
    steps = 0
    while t.is_alive():
        env.step()
        steps += 1
        server.serve_for(0.005)
        assert steps < 5000, "the request was not answered"
    t.join()
    return out["r"]


def test_the_inspector_of_a_python_simulation(env):
    s = env.main_state
    n = s.create("Node", name="belt")
    s.database.add_child(n)
    with web.Server(env, port=0, timeline_bytes=0) as server:
        server.start()
        assert server.listening and server.port > 0 and server.url.startswith("http://127.0.0.1:")
        assert len(server.token) == 32
        status, info = while_stepping(env, server, lambda: request(server.url + "api/info"))
        assert status == 200 and info["instances"] >= 2 and info["writable"] is False
        set_name = {"id": n.vsd_id, "property": "name", "value": "conveyor"}
        # Without the token the page is read-only; nothing changes.
        status, answer = while_stepping(env, server, lambda: request(server.url + "api/set", set_name))
        assert status == 403 and "token" in json.dumps(answer).lower()
        assert n.name == "belt"
        # With it, the edit goes through the setter at a step boundary.
        status, answer = while_stepping(env, server, lambda: request(server.url + "api/set", set_name, server.token))
        assert status == 200 and answer["ok"] is True
        assert n.name == "conveyor"
        # A wrong type is refused with a message naming the property, and changes nothing.
        bad = {"id": n.vsd_id, "property": "name", "value": 12}
        status, answer = while_stepping(env, server, lambda: request(server.url + "api/set", bad, server.token))
        assert status == 400 and "name" in answer.get("error", "")
        assert n.name == "conveyor"
        assert server.stats()["requests"] >= 4
    assert not server.listening
    with pytest.raises(ValueError, match="closed"):
        server.start()


def test_bad_arguments(env):
    with pytest.raises(ValueError, match="port"):
        web.Server(env, port=70000)
    with pytest.raises(ValueError, match="push_rate"):
        web.Server(env, push_rate=0)
    other = vsd.Environment()
    with pytest.raises(ValueError, match="another environment"):
        web.Server(env, other.main_state)
    with pytest.raises(TypeError):
        web.Server("not an environment")
    # Another state of the same environment is fine; a removed one is not.
    extra = env.create_state("extra")
    web.Server(env, extra, port=0).close()
    env.remove_state(extra)
    with pytest.raises(ValueError, match="removed"):
        web.Server(env, extra, port=0)
