"""``wgcad.records.record`` behaves as ``dataclasses.dataclass`` on every feature wgcad's classes use.

Each case defines one class twice, once with the standard decorator and
once with ``record``, from the same random field layout (required fields,
defaults, default factories, ``init=False`` fields with and without a
default, ``repr=False``, ``compare=False``, ``__post_init__``, a subclass
adding fields), frozen or not, and holds every observable to the
standard's: the arguments taken and refused, the fields set, ``repr``,
equality against equal and different instances and other classes, the
hash, frozen-instance errors, ``fields``, ``replace``, ``asdict``, copying
(pickle's path) and ``__match_args__``; a real record crosses pickle. Then every record class of wgcad is held to the
decorator it replaced.
"""

from __future__ import annotations

import copy
import dataclasses
import importlib
import inspect
import pkgutil
import re
from dataclasses import MISSING, FrozenInstanceError, field
from pathlib import Path

import numpy as np
import pytest

import wgcad
from wgcad.records import record

KINDS = ["required", "default", "factory", "noinit_default", "noinit_factory", "noinit_post", "norepr", "nocompare"]


def _layout(rng, n):
    kinds = list(rng.choice(KINDS, n))
    # required fields first (a required one after a default is a TypeError for both decorators)
    return sorted(kinds, key=lambda k: k != "required")


def _namespace(kinds, prefix, value):
    ann, ns = {}, {}
    for i, k in enumerate(kinds):
        name = f"{prefix}{i}"
        ann[name] = "object"
        if k == "default":
            ns[name] = value(i)
        elif k == "factory":
            ns[name] = field(default_factory=lambda i=i: (value(i), "made"))
        elif k == "noinit_default":
            ns[name] = field(default=value(i), init=False)
        elif k == "noinit_factory":
            ns[name] = field(default_factory=lambda i=i: [value(i)], init=False)
        elif k == "noinit_post":
            ns[name] = field(init=False, repr=False, compare=False)
        elif k == "norepr":
            ns[name] = field(default=value(i), repr=False)
        elif k == "nocompare":
            ns[name] = field(default=value(i), compare=False)
    ns["__annotations__"] = ann
    return ns


def _post_init(self):
    for f in dataclasses.fields(self):
        if not f.init and f.default is MISSING and f.default_factory is MISSING:
            object.__setattr__(self, f.name, ("post", type(self).__name__))


def _pair(kinds, sub_kinds, frozen, with_post):
    """The same classes (a base and a subclass) under both decorators."""
    out = []
    for deco in (dataclasses.dataclass(frozen=frozen), record(frozen=frozen)):
        ns = _namespace(kinds, "a", lambda i: i * 10)
        ns["__doc__"] = "a record"
        if with_post:
            ns["__post_init__"] = _post_init
        base = deco(type("Base", (), ns))
        sub_ns = _namespace(sub_kinds, "b", lambda i: -i)
        sub_ns["__doc__"] = "its subclass"
        sub = deco(type("Sub", (base,), sub_ns))
        out.append((base, sub))
    return out


def _args(cls, rng):
    """Positional and keyword arguments for every init field without a default, and some with one."""
    args, kw = [], {}
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        value = (f.name, int(rng.integers(3)))
        if f.default is MISSING and f.default_factory is MISSING:
            if kw or rng.random() < 0.3:
                kw[f.name] = value
            else:
                args.append(value)
        elif rng.random() < 0.5:
            kw[f.name] = value
    return args, kw


def _state(obj):
    return {k: v for k, v in vars(obj).items()}


def _outcome(fn):
    try:
        return ("ok", fn())
    except Exception as exc:  # noqa: BLE001 (the kind of failure is what is compared)
        return ("raises", type(exc))


@pytest.mark.parametrize("seed", range(60))
def test_record_behaves_as_the_standard_dataclass(seed):
    rng = np.random.default_rng(seed)
    frozen = bool(seed % 2)
    kinds, sub_kinds = _layout(rng, int(rng.integers(0, 6))), _layout(rng, int(rng.integers(0, 4)))
    if "required" in sub_kinds and any(k != "required" for k in kinds if not k.startswith("noinit")):
        sub_kinds = [k for k in sub_kinds if k != "required"]  # a required field after a default: refused by both
    with_post = "noinit_post" in kinds + sub_kinds or rng.random() < 0.5
    (std_base, std_sub), (rec_base, rec_sub) = _pair(kinds, sub_kinds, frozen, with_post)
    for std, rec in ((std_base, rec_base), (std_sub, rec_sub)):
        assert dataclasses.is_dataclass(rec)
        assert [(f.name, f.init, f.repr, f.compare) for f in dataclasses.fields(std)] == [
            (f.name, f.init, f.repr, f.compare) for f in dataclasses.fields(rec)
        ]
        assert std.__match_args__ == rec.__match_args__
        assert str(inspect.signature(std)) == str(inspect.signature(rec))
        for trial in range(6):
            args, kw = _args(std, np.random.default_rng([seed, trial]))
            a, b = std(*args, **kw), rec(*args, **kw)
            assert _state(a) == _state(b)
            assert repr(a).replace("Base", "X").replace("Sub", "X") == repr(b).replace("Base", "X").replace("Sub", "X")
            assert dataclasses.asdict(a) == dataclasses.asdict(b)
            a2, b2 = std(*args, **kw), rec(*args, **kw)
            assert (a == a2) == (b == b2) and (a != a2) == (b != b2)
            assert (b == a) is False and b.__eq__(a) is NotImplemented  # another class: not equal
            assert _outcome(lambda: hash(a) == hash(a2)) == _outcome(lambda: hash(b) == hash(b2))
            changes = {f.name: ("changed",) for f in dataclasses.fields(std) if f.init and rng.random() < 0.5}
            ra, rb = (
                _outcome(lambda: _state(dataclasses.replace(a, **changes))),
                _outcome(lambda: _state(dataclasses.replace(b, **changes))),
            )
            assert ra == rb
            if changes:
                assert (a == dataclasses.replace(a, **changes)) == (b == dataclasses.replace(b, **changes))
            # (copy takes the path pickle takes: __reduce_ex__, then the state into __dict__, no __setattr__)
            assert _state(copy.deepcopy(b)) == _state(b) and _outcome(lambda: copy.deepcopy(a) == a) == _outcome(
                lambda: copy.deepcopy(b) == b
            )
            for name in [f.name for f in dataclasses.fields(std)] + ["not_a_field"]:
                sa = _outcome(lambda: setattr(a, name, 1))
                sb = _outcome(lambda: setattr(b, name, 1))
                assert sa == sb, name
                assert _outcome(lambda: delattr(a, name)) == _outcome(lambda: delattr(b, name)), name
            # arguments refused alike: one too many, an unknown keyword, a value given twice, one missing
            n_init = len([f for f in dataclasses.fields(std) if f.init])
            bad = [
                (list(range(n_init + 1)), {}),
                (args, {**kw, "unknown": 1}),
            ]
            if args:
                first = next(f.name for f in dataclasses.fields(std) if f.init)
                bad.append((args, {**kw, first: 2}))
                bad.append((args[:-1], {}))
            for bargs, bkw in bad:
                assert _outcome(lambda: std(*bargs, **bkw)) == _outcome(lambda: rec(*bargs, **bkw))


def test_a_record_of_wgcad_crosses_pickle_whole():
    """A sweep's workers receive designs and drives pickled: a frozen record comes back equal, fields and all."""
    import pickle

    from conftest import TEMPLATES

    from wgcad.design import load_design

    design = load_design(TEMPLATES / "d1_involute.toml")
    back = pickle.loads(pickle.dumps(design))
    assert back == design and back is not design and repr(back) == repr(design)


def test_a_required_field_after_a_default_is_refused_by_both():
    for deco in (dataclasses.dataclass, record):

        class Base:
            """b"""

            x: int = 1

        with pytest.raises(TypeError, match="non-default argument 'y' follows default argument"):
            deco(type("Sub", (deco(Base),), {"__annotations__": {"y": "int"}, "__doc__": "s"}))


def test_a_frozen_records_subclass_takes_attributes_that_are_no_fields():
    """As with the standard decorator: a plain subclass of a frozen record may set its own attributes, not fields."""
    for deco in (dataclasses.dataclass(frozen=True), record(frozen=True)):

        @deco
        class Point:
            """p"""

            x: float

        class Labelled(Point):
            def label(self, text):
                self.text = text
                return self

        class Own(Point):
            def __init__(self, x, note):
                super().__init__(x)

        assert list(inspect.signature(Own).parameters) == ["x", "note"]
        p = Labelled(1.0).label("a")
        assert p.text == "a"
        with pytest.raises(FrozenInstanceError):
            p.x = 2.0


def _modules():
    root = Path(wgcad.__file__).parent
    for info in pkgutil.walk_packages([str(root)], "wgcad."):
        if info.name.endswith("__main__"):
            continue
        yield info.name, root


def test_every_record_class_of_wgcad_is_one_and_none_uses_the_standard_decorator():
    """No module decorates with ``dataclasses.dataclass`` (its methods are compiled per class, the cost ``record``
    removes); every class ``record`` made is a dataclass with its fields, and its frozen classes refuse a field."""
    root = Path(wgcad.__file__).parent
    pattern = re.compile(r"^\s*@(dataclasses\.)?dataclass\b", re.M)
    users = [str(p.relative_to(root)) for p in root.rglob("*.py") if pattern.search(p.read_text())]
    assert users == []
    found = 0
    for name, _ in _modules():
        mod = importlib.import_module(name)
        for obj in vars(mod).values():
            if isinstance(obj, type) and obj.__module__ == name and dataclasses.is_dataclass(obj):
                assert obj.__init__.__module__ == "wgcad.records", obj
                found += 1
    assert found >= 100
