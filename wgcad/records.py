"""``record``: :func:`dataclasses.dataclass` with its methods shared instead of compiled per class.

The standard decorator writes ``__init__``, ``__repr__``, ``__eq__`` (and,
frozen, ``__setattr__``, ``__delattr__``, ``__hash__``) as source text and
compiles each with ``exec``: ~0.5 ms a class on Python 3.11, 16 ms of the
33 classes an audit loads, the largest single cost of a command's start
after numpy itself. ``record`` lets ``dataclasses`` collect the fields
(``fields``, ``replace``, ``asdict``, ``is_dataclass`` work as ever;
``help`` and ``inspect.signature`` show the arguments) and
gives the class methods written once here that read those fields: the
same arguments, defaults and default factories, ``__post_init__``, the
same ``repr``, equality, hash and frozen-instance errors
(tests/test_records.py holds them to the standard decorator's on random
layouts of every kind of field wgcad uses). Building an instance costs
~1 us more (1.4 against 0.8 us for eight fields by position, 2.1 against
1.1 us by keyword); no class is built in numbers where that shows.
"""

from __future__ import annotations

import dataclasses
from dataclasses import MISSING, FrozenInstanceError
from typing import dataclass_transform

__all__ = ["record"]


def _spec(cls) -> tuple:
    """``(init fields as (name, default, factory), other fields with a default factory as (name, factory), repr
    names, compare names)`` of a record class, kept on the class."""
    spec = cls.__dict__.get("__record_spec__")
    if spec is None:
        fs = dataclasses.fields(cls)
        init = tuple((f.name, f.default, f.default_factory) for f in fs if f.init)
        # (another field with a plain default reads it from the class, as the standard decorator's do)
        rest = tuple((f.name, f.default_factory) for f in fs if not f.init and f.default_factory is not MISSING)
        spec = (init, rest, tuple(f.name for f in fs if f.repr), tuple(f.name for f in fs if f.compare))
        type.__setattr__(cls, "__record_spec__", spec)
    return spec


def _init(self, *args, **kwargs):
    cls = type(self)
    init, rest, _, _ = _spec(cls)
    if len(args) > len(init):
        raise TypeError(f"{cls.__qualname__}() takes {len(init)} positional arguments but {len(args)} were given")
    put = object.__setattr__
    for i, (name, default, factory) in enumerate(init):
        if i < len(args):
            if name in kwargs:
                raise TypeError(f"{cls.__qualname__}() got multiple values for argument '{name}'")
            value = args[i]
        elif name in kwargs:
            value = kwargs.pop(name)
        elif default is not MISSING:
            value = default
        elif factory is not MISSING:
            value = factory()
        else:
            raise TypeError(f"{cls.__qualname__}() missing required argument: '{name}'")
        put(self, name, value)
    if kwargs:
        raise TypeError(f"{cls.__qualname__}() got an unexpected keyword argument '{next(iter(kwargs))}'")
    for name, factory in rest:
        put(self, name, factory())
    post = getattr(cls, "__post_init__", None)
    if post is not None:
        post(self)


def _repr(self) -> str:
    names = _spec(type(self))[2]
    return f"{type(self).__qualname__}({', '.join(f'{n}={getattr(self, n)!r}' for n in names)})"


def _eq(self, other):
    if other.__class__ is not self.__class__:
        return NotImplemented
    names = _spec(type(self))[3]
    return tuple(getattr(self, n) for n in names) == tuple(getattr(other, n) for n in names)


def _hash(self) -> int:
    return hash(tuple(getattr(self, n) for n in _spec(type(self))[3]))


def _frozen(self, name: str) -> bool:
    # as the standard decorator: a frozen record's own instances take no attribute, a subclass's no field
    cls = type(self)
    return "__record_frozen__" in cls.__dict__ or name in cls.__dataclass_fields__


def _frozen_setattr(self, name, value):
    if _frozen(self, name):
        raise FrozenInstanceError(f"cannot assign to field {name!r}")
    object.__setattr__(self, name, value)


def _frozen_delattr(self, name):
    if _frozen(self, name):
        raise FrozenInstanceError(f"cannot delete field {name!r}")
    object.__delattr__(self, name)


class _Signature:
    """A record class's ``__signature__``, built on first look (``help``, ``inspect.signature``) from its fields: the
    arguments its ``__init__`` takes, as the standard decorator's ``__init__`` shows them."""

    def __get__(self, obj, owner):
        if obj is not None or owner.__init__ is not _init:  # an instance, or a subclass with an __init__ of its own
            raise AttributeError("__signature__")
        sig = owner.__dict__.get("__record_signature__")
        if sig is None:
            import inspect

            params = [inspect.Parameter("self", inspect.Parameter.POSITIONAL_OR_KEYWORD)]
            for f in dataclasses.fields(owner):
                if f.init:
                    default = f.default if f.default is not MISSING else inspect.Parameter.empty
                    if f.default_factory is not MISSING:
                        default = dataclasses._HAS_DEFAULT_FACTORY  # shown as <factory>, as the standard's
                    params.append(
                        inspect.Parameter(
                            f.name, inspect.Parameter.POSITIONAL_OR_KEYWORD, default=default, annotation=f.type
                        )
                    )
            sig = inspect.Signature(params[1:], return_annotation=None)
            type.__setattr__(owner, "__record_signature__", sig)
        return sig


_SIGNATURE = _Signature()


def _check_order(cls) -> None:
    """The standard decorator's check, which it makes only when it writes ``__init__``: no required argument after
    one with a default."""
    seen_default = None
    for f in dataclasses.fields(cls):
        if not f.init:
            continue
        if f.default is MISSING and f.default_factory is MISSING:
            if seen_default is not None:
                raise TypeError(f"non-default argument {f.name!r} follows default argument")
        else:
            seen_default = f.name


@dataclass_transform(field_specifiers=(dataclasses.field, dataclasses.Field))
def record(cls=None, /, *, frozen: bool = False):
    """Use as ``@record`` or ``@record(frozen=True)`` where ``@dataclass`` would stand (module note); type checkers
    and editors read the fields as a dataclass's (``typing.dataclass_transform``)."""

    def wrap(c):
        own = dict(c.__dict__)
        c = dataclasses.dataclass(c, init=False, repr=False, eq=False)
        _check_order(c)
        for name, fn in (("__init__", _init), ("__repr__", _repr), ("__eq__", _eq)):
            if name not in own:
                setattr(c, name, fn)
        if "__init__" not in own:
            c.__signature__ = _SIGNATURE
        if frozen:
            c.__record_frozen__ = True
            c.__setattr__, c.__delattr__ = _frozen_setattr, _frozen_delattr
            if "__hash__" not in own:
                c.__hash__ = _hash
        elif "__hash__" not in own:
            c.__hash__ = None  # as the standard decorator: equal by value and mutable, so unhashable
        return c

    return wrap if cls is None else wrap(cls)
