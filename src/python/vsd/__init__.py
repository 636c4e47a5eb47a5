"""vsd from Python: every class, property and method of the simulation database, through its
meta-information (no per-class binding code).

    import vsd
    env = vsd.Environment()
    s = env.main_state
    n = s.create("Node", name="a")
    s.database.add_child(n)
    isinstance(n, vsd.Node)          # True: vsd classes become Python classes on first use

See docs/python.md.
"""
import enum as _enum

from . import _core
from ._core import (  # noqa: F401  (the package's API)
    Connection,
    DeadInstanceError,
    Environment,
    Error,
    SimState,
    Transaction,
    class_info,
    class_names,
    define_class,
    load_plugin,
    type_names,
)

# The modules' entry points (vsd.io, vsd.soml, vsd.scene, vsd.robotics, vsd.physics, vsd.collision, vsd.web, vsd.dist, vsd.analysis): only
# those of the modules built.
for _name in ("io", "soml", "scene", "robotics", "physics", "collision", "web", "dist", "analysis"):
    if hasattr(_core, _name):
        globals()[_name] = getattr(_core, _name)

Instance = None  # replaced below by the Python class of vsd's root class

_classes = {}  # full vsd class name -> (class index, Python class): an undefined class's name may come back
_enums = {}


def _short(name):
    return name.rsplit("::", 1)[-1]


def _make_enum(name, values, is_flags):
    """The Python enum (IntEnum, or IntFlag for flags) of a vsd enum or flags type."""
    key = (name, tuple(values))
    cls = _enums.get(key)
    if cls is None:
        base = _enum.IntFlag if is_flags else _enum.IntEnum
        cls = base(_short(name), [(n, v) for n, v in values], module=__name__)
        _enums[key] = cls
    return cls


# Extra Python methods of some classes, written against their C++ API (not meta-methods).
def _add_child(self, child):
    """Appends child (moving it from its former parent); returns self."""
    _core._node_add_child(self, child)
    return self


def _remove_child(self, child):
    """Removes child; it is deleted when nothing else holds it."""
    _core._node_remove_child(self, child)


def _add_extension(self, ext):
    """Attaches the extension ext (moving it from a former owner); returns self."""
    _core._add_extension(self, ext)
    return self


def _remove_extension(self, ext):
    """Detaches ext; it is deleted when nothing else holds it."""
    _core._remove_extension(self, ext)


_extras = {
    "NamedModelInstance": {
        "add_extension": _add_extension,
        "remove_extension": _remove_extension,
    },
    "Node": {
        "add_child": _add_child,
        "remove_child": _remove_child,
        "parent": property(lambda self: _core._node_parent(self), doc="The parent node, or None"),
        "path": property(lambda self: _core._node_path(self), doc="Names from the root down: '/robot/arm'"),
    },
}


def _class_for(name):
    """The Python class of the vsd class `name` (made on first use, with its bases)."""
    info = class_info(name)
    full = info["name"]
    known = _classes.get(full)
    if known is not None and known[0] == info["index"]:
        return known[1]
    base = _class_for(info["base"]) if info["base"] is not None else _core._Handle
    ns = {
        "__slots__": (),
        "__module__": __name__,
        "__qualname__": _short(full),
        "__doc__": f"vsd class {full}" + (" (abstract)" if info["abstract"] else ""),
        "_vsd_class": full,
        "_vsd_generated": True,
    }
    for pname, prop, _type, _hint, _ro in info["properties"]:
        ns[pname] = prop
    for mname, meth, _sig, _args, _res in info["methods"]:
        ns.setdefault(mname, meth)
    for k, v in _extras.get(full, {}).items():
        ns.setdefault(k, v)
    cls = type(_short(full), (base,), ns)
    _classes[full] = (info["index"], cls)
    return cls


_core._set_class_factory(_class_for)
Instance = _class_for("Instance")

_python_types = {float: "double", int: "int64", bool: "bool", str: "string"}


def _type_name(annotation, owner, pname):
    if isinstance(annotation, str):
        return annotation  # a vsd type name ("int32", "vector<double>", "shared<Node>")
    if annotation in _python_types:
        return _python_types[annotation]
    if isinstance(annotation, type) and hasattr(annotation, "_vsd_class"):
        return f"shared<{annotation._vsd_class}>"
    raise TypeError(f"{owner}.{pname}: annotation {annotation!r} has no vsd type "
                    "(use float, int, bool, str, a vsd class, or a vsd type name as a string)")


def _define_from_python(cls):
    """Makes a Python subclass of a vsd class a run-time vsd class (its annotated attributes become
    properties) and makes it the Python class of that vsd class."""
    base = next(b for b in cls.__mro__[1:] if "_vsd_class" in b.__dict__)
    name = cls.__dict__.get("vsd_name", cls.__name__)
    own = cls.__dict__.get("__annotations__", {})
    props = []
    for pname, ann in own.items():
        default = cls.__dict__.get(pname)
        props.append((pname, _type_name(ann, name, pname), default))
    if name in class_names():  # defined before (a module imported twice, a test run again): reuse when equal
        info = class_info(name)
        have = [p[0] for p in info["properties"]]
        if info["base"] != base._vsd_class or have != [p[0] for p in props]:
            raise Error(f"class '{name}' is defined already with other properties or another base")
    else:
        define_class(name, base._vsd_class, props)
    info = class_info(name)
    for pname, prop, _type, _hint, _ro in info["properties"]:
        setattr(cls, pname, prop)  # the descriptor replaces the default value
    for mname, meth, _sig, _args, _res in info["methods"]:
        if mname not in cls.__dict__:
            setattr(cls, mname, meth)
    cls._vsd_class = info["name"]
    _classes[info["name"]] = (info["index"], cls)
    _core._register_class(info["name"], cls)


def _init_subclass(cls, **kwargs):
    if cls.__dict__.get("_vsd_generated"):
        return
    _define_from_python(cls)


Instance.__init_subclass__ = classmethod(_init_subclass)


def _no_direct_construction(cls, *args, **kwargs):
    raise TypeError(f"vsd instances live in a SimState: use state.create({cls.__name__}, ...), "
                    f"not {cls.__name__}()")


Instance.__new__ = _no_direct_construction


class _Recording:
    """`with state.record() as r: ...` records the changes made inside into r.transaction."""

    def __init__(self, state):
        self.state = state
        self.transaction = None

    def __enter__(self):
        self.state.start_recording()
        return self

    def __exit__(self, *exc):
        self.transaction = self.state.stop_recording()
        return False


SimState.record = lambda self: _Recording(self)


def __getattr__(name):
    """vsd.Node, vsd.Database, vsd.scene.Node3D's short name "Node3D", ...: the Python class of a vsd class."""
    if name.startswith("__"):
        raise AttributeError(name)
    try:
        cls = _class_for(name)
    except KeyError:
        raise AttributeError(f"module 'vsd' has no attribute '{name}' (and no vsd class has that name)") from None
    return cls


def class_of(name):
    """The Python class of the vsd class `name` (full or short name); KeyError when there is none."""
    return _class_for(name)
